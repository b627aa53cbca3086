#include "passes/label_forces.h"

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"

namespace strata {

using graph::Use;

gpu::ForcesParams forces_params(const ForceSettings& settings, LabelUnits units,
                                uint32_t label_count, double seconds, bool hard,
                                uint32_t order_count) {
  if (!(settings.speed_widths > 0.0f) || !(settings.epsilon_widths > 0.0f) ||
      !(settings.snap >= 0.0f)) {
    throw Error("forces: speed and epsilon must be > 0 and snap >= 0");
  }
  if (!(settings.hold_share >= 0.0f) || !(settings.hold_cost >= 0.0f) ||
      !(settings.fade_seconds >= 0.0f) || !(settings.ease_in_seconds >= 0.0f) ||
      !(settings.appear_padding_em >= 0.0f) || !(settings.wait_seconds >= 0.0f) ||
      !(settings.appear_margin_em >= 0.0f) || !(settings.min_hidden_seconds >= 0.0f)) {
    throw Error("forces: hold, fade, ease-in, padding, wait, margin and hidden time must be >= 0");
  }
  if (!(units.width >= 1.0f) || !(units.em > 0.0f)) {
    throw Error("forces: an image " + std::to_string(units.width) + " px wide, text of " +
                std::to_string(units.em) + " px");
  }
  if (!(seconds >= 0.0 && seconds <= 60.0)) {
    throw Error("forces: a frame of " + std::to_string(seconds) + " s");
  }
  const double travel = seconds * double(settings.speed_widths) / double(settings.epsilon_widths);
  // (a frame of 1/30 s is 4 steps, not 5 for its rounding)
  const double short_steps = std::ceil(seconds / kForceStepSeconds - 1e-6);
  const auto steps = static_cast<uint32_t>(std::max({1.0, std::ceil(travel), short_steps}));
  gpu::ForcesParams p{};
  p.label_count = label_count;
  p.steps = steps;
  p.step_seconds = static_cast<float>(seconds / steps);
  p.speed = settings.speed_widths * units.width;
  p.epsilon = settings.epsilon_widths * units.width;
  p.snap = settings.snap;
  p.anchor_relative = settings.anchor_relative ? 1u : 0u;
  p.fade = seconds > 0.0 && settings.fade_seconds > 0.0f
               ? static_cast<float>(std::min(1.0, seconds / settings.fade_seconds))
               : 1.0f;
  p.hold_share = settings.hold_share;
  p.hold_cost = settings.hold_cost;
  p.appear_padding = hard ? settings.appear_padding_em * units.em : 0.0f;
  p.trial = 0u;
  p.acceleration = settings.ease_in_seconds > 0.0f ? p.speed / settings.ease_in_seconds : 0.0f;
  p.keep_apart = settings.keep_apart ? 1u : 0u;
  if (p.keep_apart != 0u && !(units.height >= 1.0f)) {
    throw Error("forces: keeping labels apart in an image " + std::to_string(units.height) +
                " px high");
  }
  p.order_count = std::min(order_count, label_count);
  p.image_width = units.width;
  p.image_height = units.height;
  p.wait = settings.wait_seconds;
  p.appear_margin = seconds > 0.0 ? settings.appear_margin_em * units.em : 0.0f;  // (a still: none)
  p.min_hidden = settings.min_hidden_seconds;
  p.clearance = seconds > 0.0 ? 0.01f : 0.0f;
  return p;
}

void set_keep_out(gpu::ForcesParams& params, std::span<const glm::uvec4> rects) {
  params.keep_out_count = 0;
  for (const glm::uvec4& r : rects) {
    if (r.x >= r.z || r.y >= r.w) continue;
    if (params.keep_out_count == PLACEMENT_KEEP_OUT_MAX) {
      throw Error("forces: more than " + std::to_string(PLACEMENT_KEEP_OUT_MAX) +
                  " keep-out rectangles");
    }
    const glm::uvec4 k = glm::min(r, glm::uvec4(0xFFFFu));
    params.keep_out[2 * params.keep_out_count] = k.x | k.y << 16u;
    params.keep_out[2 * params.keep_out_count + 1] = k.z | k.w << 16u;
    ++params.keep_out_count;
  }
}

LabelForces::LabelForces(Context& ctx, uint32_t label_count, LabelForces* from)
    : ctx_(ctx),
      label_count_(label_count),
      active_(label_count),
      params_(forces_params({}, {1024.0f, 14.0f, 1024.0f}, label_count, 0.0)),
      forces_(reuse_or_create(ctx, from ? &from->forces_ : nullptr, "label_forces.comp")),
      previous_(reuse_or_create(ctx, from ? &from->previous_ : nullptr, "label_previous.comp")),
      follow_(reuse_or_create(ctx, from ? &from->follow_ : nullptr, "label_follow.comp")),
      state_(ctx, std::max<VkDeviceSize>(1, label_count) * sizeof(gpu::LabelStateGpu),
             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                 VK_BUFFER_USAGE_TRANSFER_DST_BIT,
             MemoryKind::device_local),
      readback_(ctx, std::max<VkDeviceSize>(1, label_count) * sizeof(gpu::PlacementGpu)) {
  reset();
}

void LabelForces::reset() {
  const std::vector<gpu::LabelStateGpu> empty(std::max(1u, label_count_), gpu::LabelStateGpu{});
  upload(ctx_, state_, as_bytes(empty));
}

void LabelForces::set_frame(const ForceSettings& settings, LabelUnits units, double seconds,
                            bool hard, uint32_t order_count) {
  params_ = forces_params(settings, units, active_, seconds, hard, order_count);
  strata::set_keep_out(params_, keep_out_);
}

void LabelForces::set_keep_out(std::span<const glm::uvec4> rects) {
  strata::set_keep_out(params_, rects);
  keep_out_.assign(rects.begin(), rects.end());
}

std::vector<gpu::LabelStateGpu> LabelForces::state() const {
  std::vector<gpu::LabelStateGpu> out = download_as<gpu::LabelStateGpu>(ctx_, state_);
  out.resize(label_count_);
  return out;
}

std::span<const gpu::PlacementGpu> LabelForces::drawn() const {
  return {reinterpret_cast<const gpu::PlacementGpu*>(readback_.data().data()), label_count_};
}

graph::ResourceId LabelForces::import_state(graph::Graph& graph) const {
  return graph.import_buffer("forces.state", {.buffer = state_.handle(), .has_content = true});
}

void LabelForces::add_previous(graph::Graph& graph, graph::ResourceId labels,
                               graph::ResourceId state) const {
  graph.add_pass({"forces.previous",
                  graph::PassKind::compute,
                  {{labels, Use::storage_read_write, FORCES_BINDING_LABELS},
                   {state, Use::storage_read, FORCES_BINDING_STATE}},
                  [this](graph::PassContext& pc) {
                    pc.dispatch(previous_, params_, {active_, 1, 1});
                  },
                  "placement"});  // (timed with the placement it feeds)
}

LabelForces::Outputs LabelForces::add_to(graph::Graph& graph, const Inputs& in) {
  const uint32_t n = std::max(label_count_, 1u);
  Outputs out;
  out.drawn = graph.add_buffer(
      "forces.drawn", {[n](graph::Extent) { return VkDeviceSize{n} * sizeof(gpu::PlacementGpu); }});
  const graph::ResourceId scratch = graph.add_buffer(
      "forces.scratch",
      {[n](graph::Extent) { return VkDeviceSize{n} * sizeof(gpu::KeepApartGpu); }});
  graph.add_pass({"labels.forces",
                  graph::PassKind::compute,
                  {{in.labels, Use::storage_read, FORCES_BINDING_LABELS},
                   {in.targets, Use::storage_read, FORCES_BINDING_TARGETS},
                   {in.state, Use::storage_read_write, FORCES_BINDING_STATE},
                   {out.drawn, Use::storage_write, FORCES_BINDING_DRAWN},
                   {in.order, Use::storage_read, FORCES_BINDING_ORDER},
                   {scratch, Use::storage_write, FORCES_BINDING_SCRATCH}},
                  [this](graph::PassContext& pc) {
                    pc.dispatch(forces_, params_, {KEEP_APART_GROUP, 1, 1});  // (one workgroup)
                  },
                  "labels"});
  const graph::ResourceId readback = readback_.import(graph, "forces.readback");
  const graph::ResourceId drawn = out.drawn;
  graph.add_pass({"forces.readback",
                  graph::PassKind::transfer,
                  {{drawn, Use::transfer_src}, {readback, Use::transfer_dst}},
                  [this, drawn, readback](graph::PassContext& pc) {
                    const VkBufferCopy region{0, 0, readback_.size()};
                    vkCmdCopyBuffer(pc.cmd, pc.buffer(drawn), pc.buffer(readback), 1, &region);
                  }});
  return out;
}

graph::ResourceId LabelForces::add_follow(graph::Graph& graph, graph::ResourceId labels,
                                          graph::ResourceId placed,
                                          graph::ResourceId targets) const {
  const uint32_t n = std::max(label_count_, 1u);
  const graph::ResourceId followed = graph.add_buffer(
      "forces.followed",
      {[n](graph::Extent) { return VkDeviceSize{n} * sizeof(gpu::PlacementGpu); }});
  graph.add_pass({"labels.follow",
                  graph::PassKind::compute,
                  {{labels, Use::storage_read, FORCES_BINDING_LABELS},
                   {placed, Use::storage_read, FORCES_BINDING_PLACED},
                   {targets, Use::storage_read, FORCES_BINDING_TARGETS},
                   {followed, Use::storage_write, FORCES_BINDING_FOLLOWED}},
                  [this](graph::PassContext& pc) {
                    pc.dispatch(follow_, params_, {active_, 1, 1});
                  },
                  "labels"});
  return followed;
}

std::vector<gpu::PlacementGpu> follow_reference(std::vector<gpu::PlacementGpu> targets,
                                                const std::vector<gpu::LabelGpu>& placed,
                                                const std::vector<gpu::LabelGpu>& labels,
                                                const gpu::ForcesParams& params) {
  for (size_t i = 0; i < targets.size(); ++i) {
    targets[i] = gpu::follow_anchor(targets[i], placed.at(i), labels.at(i), params);
  }
  return targets;
}

std::vector<gpu::LabelGpu> previous_reference(std::vector<gpu::LabelGpu> labels,
                                              const std::vector<gpu::LabelStateGpu>& state,
                                              const gpu::ForcesParams& params) {
  for (size_t i = 0; i < labels.size(); ++i) {
    labels[i] = gpu::forces_previous(labels[i], state[i], params);
  }
  return labels;
}

namespace {

// Keeping apart on the CPU (label_forces.comp's turns, one after another): the labels taking part
// in their settling order, each one's boxes against every other's obstacle.
void keep_apart_reference(const std::vector<gpu::LabelGpu>& labels,
                          const std::vector<gpu::PlacementGpu>& targets,
                          std::vector<gpu::LabelStateGpu>& state, const gpu::ForcesParams& params,
                          const std::vector<uint32_t>& order) {
  const size_t n = labels.size();
  std::vector<uint32_t> keys(n);
  for (size_t i = 0; i < n; ++i) keys[i] = params.order_count + uint32_t(i);
  for (uint32_t k = 0; k < params.order_count; ++k) {
    if (order.at(k) < n) keys[order[k]] = k;
  }
  std::vector<glm::vec4> ways(n), stays(n);
  std::vector<gpu::LabelStateGpu> moved(n);
  std::vector<uint32_t> turns, alone;
  for (size_t i = 0; i < n; ++i) {
    const uint32_t c = gpu::keep_apart_class(labels[i], targets[i], state[i]);
    keys[i] += c * KEEP_APART_CLASS_STRIDE;
    moved[i] = gpu::forces_update(labels[i], targets[i], state[i], params);
    ways[i] = gpu::keep_apart_way(labels[i], targets[i], state[i], moved[i], params);
    stays[i] = gpu::keep_apart_stay(labels[i], state[i], params);
    (c != KEEP_APART_NONE ? turns : alone).push_back(uint32_t(i));
  }
  std::sort(turns.begin(), turns.end(), [&](uint32_t a, uint32_t b) { return keys[a] < keys[b]; });
  std::vector<glm::vec4> obstacles = stays;
  std::vector<bool> settled(n, false);
  const float clearance = params.clearance;
  for (const uint32_t i : turns) {
    uint32_t clashes = gpu::keep_apart_cut(ways[i], stays[i], params);
    size_t from = n;  // the first label settled before whose box clashes with where i is
    for (size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      if (gpu::boxes_clash(ways[i], obstacles[j], clearance)) clashes |= KEEP_APART_WAY;
      if (settled[j] && gpu::boxes_clash(stays[i], obstacles[j], clearance)) {
        clashes |= KEEP_APART_STAY;
        from = std::min(from, j);
      }
    }
    glm::vec4 pushed = gpu::keep_apart_none();
    if ((clashes & KEEP_APART_WAY) != 0u && from < n) {  // (where it is clashes with a box)
      pushed = gpu::keep_apart_push(stays[i], obstacles[from], params);
      bool free = gpu::box_inside(pushed, params);
      for (size_t j = 0; j < n && free; ++j) {
        free = j == i || !(gpu::boxes_clash(pushed, ways[j], clearance) ||
                           gpu::boxes_clash(pushed, stays[j], clearance));
      }
      if (!free) clashes |= KEEP_APART_PUSH;
    }
    state[i] =
        gpu::keep_apart_settle(labels[i], targets[i], state[i], moved[i], params, clashes, pushed);
    obstacles[i] = gpu::keep_apart_obstacle(labels[i], state[i]);
    settled[i] = true;
  }
  for (const uint32_t i : alone) {  // (taking no part: they move on their own)
    state[i] = gpu::keep_apart_settle(labels[i], targets[i], state[i], moved[i], params, 0u,
                                      gpu::keep_apart_none());
  }
}

}  // namespace

std::vector<gpu::PlacementGpu> forces_reference(const std::vector<gpu::LabelGpu>& labels,
                                                const std::vector<gpu::PlacementGpu>& targets,
                                                std::vector<gpu::LabelStateGpu>& state,
                                                const gpu::ForcesParams& params,
                                                const std::vector<uint32_t>& order) {
  if (params.trial == 0u && params.keep_apart != 0u) {
    keep_apart_reference(labels, targets, state, params, order);
  } else if (params.trial == 0u) {
    for (size_t i = 0; i < labels.size(); ++i) {
      state[i] = gpu::forces_update(labels[i], targets[i], state[i], params);
    }
  }
  std::vector<gpu::PlacementGpu> drawn(labels.size());
  for (size_t i = 0; i < labels.size(); ++i) {
    drawn[i] = params.trial == 0u && params.keep_apart != 0u
                   ? gpu::keep_apart_drawn(labels[i], targets[i], state[i], params)
                   : gpu::forces_drawn(targets[i], state[i]);
  }
  return drawn;
}

}  // namespace strata
