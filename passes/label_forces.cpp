#include "passes/label_forces.h"

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"

namespace strata {

using graph::Use;

gpu::ForcesParams forces_params(const ForceSettings& settings, LabelUnits units,
                                uint32_t label_count, double seconds, bool hard) {
  if (!(settings.speed_widths > 0.0f) || !(settings.epsilon_widths > 0.0f) ||
      !(settings.snap >= 0.0f)) {
    throw Error("forces: speed and epsilon must be > 0 and snap >= 0");
  }
  if (!(settings.hold_share >= 0.0f) || !(settings.hold_cost >= 0.0f) ||
      !(settings.fade_seconds >= 0.0f) || !(settings.ease_in_seconds >= 0.0f) ||
      !(settings.appear_padding_em >= 0.0f)) {
    throw Error("forces: hold, fade, ease-in and padding must be >= 0");
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
  return p;
}

LabelForces::LabelForces(Context& ctx, uint32_t label_count)
    : ctx_(ctx),
      label_count_(label_count),
      params_(forces_params({}, {1024.0f, 14.0f}, label_count, 0.0)),
      forces_(ctx, "label_forces.comp"),
      previous_(ctx, "label_previous.comp"),
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
                            bool hard) {
  params_ = forces_params(settings, units, label_count_, seconds, hard);
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
                    pc.dispatch(previous_, params_, {label_count_, 1, 1});
                  },
                  "placement"});  // (timed with the placement it feeds)
}

LabelForces::Outputs LabelForces::add_to(graph::Graph& graph, const Inputs& in) {
  const uint32_t n = std::max(label_count_, 1u);
  Outputs out;
  out.drawn = graph.add_buffer(
      "forces.drawn", {[n](graph::Extent) { return VkDeviceSize{n} * sizeof(gpu::PlacementGpu); }});
  graph.add_pass({"labels.forces",
                  graph::PassKind::compute,
                  {{in.labels, Use::storage_read, FORCES_BINDING_LABELS},
                   {in.targets, Use::storage_read, FORCES_BINDING_TARGETS},
                   {in.state, Use::storage_read_write, FORCES_BINDING_STATE},
                   {out.drawn, Use::storage_write, FORCES_BINDING_DRAWN}},
                  [this](graph::PassContext& pc) {
                    pc.dispatch(forces_, params_, {label_count_, 1, 1});
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

std::vector<gpu::LabelGpu> previous_reference(std::vector<gpu::LabelGpu> labels,
                                              const std::vector<gpu::LabelStateGpu>& state,
                                              const gpu::ForcesParams& params) {
  for (size_t i = 0; i < labels.size(); ++i) {
    labels[i] = gpu::forces_previous(labels[i], state[i], params);
  }
  return labels;
}

std::vector<gpu::PlacementGpu> forces_reference(const std::vector<gpu::LabelGpu>& labels,
                                                const std::vector<gpu::PlacementGpu>& targets,
                                                std::vector<gpu::LabelStateGpu>& state,
                                                const gpu::ForcesParams& params) {
  std::vector<gpu::PlacementGpu> drawn(labels.size());
  for (size_t i = 0; i < labels.size(); ++i) {
    if (params.trial == 0u) state[i] = gpu::forces_update(labels[i], targets[i], state[i], params);
    drawn[i] = gpu::forces_drawn(targets[i], state[i]);
  }
  return drawn;
}

}  // namespace strata
