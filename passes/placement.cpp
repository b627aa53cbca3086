#include "passes/placement.h"

#include <array>
#include <cstddef>
#include <cstring>
#include <string_view>
#include <utility>

#include "engine/core/error.h"
#include "engine/gpu/context.h"
#include "engine/gpu/resources.h"
#include "shared/tidy_gpu.h"

static_assert(sizeof(strata::gpu::TidyGpu) == 112, "TidyGpu: the layout GLSL's std430 gives it");
static_assert(PLACEMENT_BOUNDS_TILES * (PLACEMENT_TILE / PLACEMENT_CELL) *
                      (PLACEMENT_TILE / PLACEMENT_CELL) ==
                  PLACEMENT_BOUNDS_GROUP,
              "placement_bounds.comp: a cell per invocation");

namespace strata {

using graph::ResourceId;
using graph::Use;

// The tidy-up's rounds for `labels` labels: as asked up to TIDY_SHARED_MAX (256); past that a
// round's work grows with the square of the count or faster (each conflicted label's moves and
// each crossing pair weighed against every label; 4096 labels' 64 rounds ran past the GPU
// timeout: docs/performance.md), so at most 64 (256 / labels)^2 rounds, at least one:
// 500 labels take 16, 1000 take 4, from 2048 on one.
namespace {
uint32_t tidy_rounds_for(uint32_t asked, uint32_t labels) {
  const uint32_t rounds = std::min(asked, TIDY_ROUNDS_MAX);
  if (labels <= TIDY_SHARED_MAX) return rounds;
  const double share = double(TIDY_SHARED_MAX) / double(labels);
  const auto cap = std::max(1u, uint32_t(64.0 * share * share));
  return std::min(rounds, cap);
}
}  // namespace

std::vector<uint32_t> rounds_ranks(uint32_t label_count, std::span<const uint32_t> order,
                                   std::span<const uint32_t> group_first) {
  std::vector<uint32_t> ranks(label_count, ROUNDS_NO_RANK);
  for (uint32_t s = 0; s < order.size(); ++s) {
    const uint32_t first = s < group_first.size() ? std::min(group_first[s], s) : 0u;
    ranks[order[s]] = s | first << 16u;
  }
  return ranks;
}

std::vector<glm::uvec4> keep_out_rectangles(const PlacementSettings& s) {
  std::vector<glm::uvec4> rects;
  for (const glm::uvec4& k : s.keep_out) {
    if (k.x < k.z && k.y < k.w) rects.push_back(k);
  }
  if (rects.size() > PLACEMENT_KEEP_OUT_MAX) {
    throw Error("placement: " + std::to_string(rects.size()) + " keep-out rectangles; at most " +
                std::to_string(PLACEMENT_KEEP_OUT_MAX));
  }
  return rects;
}

gpu::PlacementParams placement_params(const PlacementSettings& s, graph::Extent viewport,
                                      uint32_t layer_count, uint32_t label_count, uint32_t step) {
  gpu::PlacementParams p{};
  const CostWeights& w = s.weights;
  p.weights = {w.distance_to_anchor, w.connector_direction, w.label_shadow,
               w.connector_shadow,   w.anchor_constraint,   w.integral_costs,
               w.previous_position,  w.leader_crossing,     w.illegible};
  p.width = viewport.width;
  p.height = viewport.height;
  p.layer_count = layer_count;
  p.label_count = label_count;
  p.step = step;
  p.hard = s.hard ? 1u : 0u;
  p.write_constraints = s.write_constraints ? 1u : 0u;
  p.margin = margin_pixels(s);
  p.edge = s.edge_em * s.text_pixels;
  p.keep_out_count = uint32_t(keep_out_rectangles(s).size());
  p.saliency_weight = s.saliency_weight;
  p.occlusion_weight = s.occlusion_weight;
  p.single_saliency_weight = s.single_saliency_weight;
  p.bucket_width = s.bucket_width;
  p.tidy_rounds = s.hard ? 0u : tidy_rounds_for(s.tidy_rounds, label_count);
  return p;
}

gpu::IntegralCostsParams integral_costs_params(const PlacementSettings& s, graph::Extent viewport,
                                               uint32_t layer_count, uint32_t label_count) {
  return {viewport.width,
          viewport.height,
          layer_count,
          label_count,
          s.saliency_weight,
          s.occlusion_weight,
          s.single_saliency_weight,
          s.ghost_strength,
          s.ghost_radius};
}

PlacementPlan PlacementPlan::choose(const Context& ctx, uint32_t label_count,
                                    const PlacementLayout& layout) {
  PlacementPlan plan;
  plan.indirect = layout.dispatch == LabelDispatch::indirect ||
                  (layout.dispatch == LabelDispatch::automatic &&
                   ctx.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU);
  plan.skip_idle_blocks = !plan.indirect && layout.skip_idle_blocks && ctx.conditional_rendering();
  plan.large = tidy_states_in_buffer(label_count);
  return plan;
}

std::vector<ComputePipeline> Placement::create_pipelines(Context& ctx, uint32_t label_count) {
  const bool large = tidy_states_in_buffer(label_count);
  const std::array<std::string_view, 5> shaders{
      "integral_costs.comp", "placement_bounds.comp", "place_label.comp",
      large ? "placement_tidy_large.comp" : "placement_tidy.comp",
      large ? "placement_tidy_search_large.comp" : "placement_tidy_search.comp"};
  return create_compute_pipelines(ctx, shaders);
}

Placement::Placement(Context& ctx, uint32_t label_count, PlacementLayout layout)
    : Placement(ctx, label_count, layout, create_pipelines(ctx, label_count)) {}

std::vector<ComputePipeline> Placement::take_pipelines(uint32_t label_count) {
  if (tidy_states_in_buffer(label_count) != tidy_states_in_buffer(label_count_))
    return create_pipelines(ctx_, label_count);
  std::vector<ComputePipeline> out;
  for (ComputePipeline* p : {&integral_costs_, &bounds_, &place_, &tidy_, &search_})
    out.push_back(std::move(*p));
  return out;
}

Placement::Placement(Context& ctx, uint32_t label_count, PlacementLayout layout,
                     std::vector<ComputePipeline> pipelines)
    : ctx_(ctx),
      label_count_(label_count),
      layout_(layout),
      plan_(PlacementPlan::choose(ctx, label_count, layout)),
      integral_costs_(std::move(pipelines[0])),
      bounds_(std::move(pipelines[1])),
      place_(std::move(pipelines[2])),
      tidy_(std::move(pipelines[3])),
      search_(std::move(pipelines[4])),
      tables_(ctx),
      readback_(ctx, std::max<VkDeviceSize>(1, label_count) * sizeof(gpu::PlacementGpu)) {
  static_assert(LABEL_MAX == kMaxLabels, "the scene side's label limit is the placement's");
  if (label_count > LABEL_MAX) {
    throw Error("placement: " + std::to_string(label_count) + " labels; strata places at most " +
                std::to_string(LABEL_MAX));
  }
  const uint32_t c = layout.classify_tiles;
  if (c != 0 && c != 4 && c != 8 && c != 16) {
    throw Error("placement: classify_tiles " + std::to_string(c) + " is not 0, 4, 8 or 16");
  }
}

gpu::PlacementParams Placement::params(graph::Extent viewport, uint32_t step) const {
  gpu::PlacementParams p = placement_params(settings_, viewport, layer_count_, frame_count(), step);
  p.order_count = static_cast<uint32_t>(order_.size());
  // place_label dispatch `step`: the main pass of position step - 1, the speculative one of step
  p.label = step > 0 && step <= order_.size() ? order_[step - 1] : 0;
  p.spec_label = step < order_.size() ? order_[step] : 0;
  p.finish_lanes = layout_.finish_lanes;
  p.classify_tiles = classify_tiles(viewport);
  p.indirect = plan_.indirect ? 1u : 0u;
  return p;
}

uint32_t Placement::classify_tiles(graph::Extent viewport) const {
  const glm::uvec2 across = gpu::placement_tiles(viewport.width, viewport.height);
  return layout_.classify_tiles != 0 ? layout_.classify_tiles
                                     : gpu::placement_classify_tiles(across.x * across.y);
}

void Placement::set_frame(std::vector<gpu::LabelGpu> labels, std::vector<uint32_t> order,
                          const PlacementSettings& settings, std::optional<uint32_t> active,
                          std::span<const uint32_t> group_first) {
  if (labels.size() != label_count_ || order.size() > label_count_) {
    throw Error("placement: set_frame got " + std::to_string(labels.size()) + " labels and " +
                std::to_string(order.size()) + " in the order for " + std::to_string(label_count_));
  }
  active_ = std::min(active.value_or(label_count_), label_count_);
  labels_ = std::move(labels);
  order_ = std::move(order);
  ranks_ = rounds_ranks(label_count_, order_, group_first);
  keep_out_rectangles(settings);  // (checked here, not while recording)
  settings_ = settings;
}

namespace {

graph::BufferInfo fixed(VkDeviceSize bytes) {
  return {[bytes](graph::Extent) { return bytes; }};
}

graph::BufferInfo per_pixel(VkDeviceSize bytes) {
  return {[bytes](graph::Extent e) { return VkDeviceSize{e.width} * e.height * bytes; }};
}

// `bytes` per 32x32 tile of candidates, `copies` times.
graph::BufferInfo per_tile(VkDeviceSize bytes, VkDeviceSize copies = 1) {
  return {[bytes, copies](graph::Extent e) {
    const glm::uvec2 tiles = gpu::placement_tiles(e.width, e.height);
    return copies * tiles.x * tiles.y * bytes;
  }};
}

}  // namespace

Placement::Outputs Placement::add_to(graph::Graph& graph, const Inputs& in) {
  layer_count_ = in.layer_count;
  const Buffers b = add_buffers(graph);
  add_upload(graph, b);
  if (in.adjust_labels) in.adjust_labels(graph, b.labels);
  add_costs(graph, b, in);
  add_bounds(graph, b);
  // (both ways are in the graph, whichever the frame's settings choose: a frame records one)
  const graph::PassId loop = add_label_loop(graph, b);
  const auto loop_end = static_cast<graph::PassId>(graph.passes().size());
  const graph::PassId rounds = add_rounds(graph, b);
  add_tidy(graph, b);
  return {b.labels,  b.placements, b.saliency,    b.costs,        b.tables,
          b.constraints, b.results, b.buckets,    b.tidy_rounds,  b.round_counts,
          b.round_of, b.order,     loop,          loop_end,       rounds};
}

Placement::Buffers Placement::add_buffers(graph::Graph& graph) {
  const uint32_t n = std::max(label_count_, 1u);
  const uint32_t layers = layer_count_;
  Buffers b;
  b.labels = graph.add_buffer("placement.labels", fixed(n * sizeof(gpu::LabelGpu)));
  b.order = graph.add_buffer("placement.order", fixed(n * sizeof(uint32_t)));
  b.results = graph.add_buffer("placement.results", fixed(n * sizeof(uint64_t)));
  b.placements = graph.add_buffer("placement.placements", fixed(n * sizeof(gpu::PlacementGpu)));
  b.saliency = graph.add_buffer("placement.saliency", per_pixel(sizeof(float)));
  // (integral costs, then hidden pixels: two stacks of `layers`)
  b.costs = graph.add_buffer("placement.integral_costs", per_pixel(sizeof(float) * 2 * layers));
  b.tables = graph.add_buffer("placement.tables", per_pixel(sizeof(float) * 2 * layers));
  b.constraints = graph.add_buffer("placement.constraints", per_pixel(sizeof(uint32_t)));
  b.bounds = graph.add_buffer("placement.bounds", per_tile(sizeof(float), n));
  b.tiles = graph.add_buffer("placement.tiles", per_tile(2 * sizeof(uint32_t), n));
  // (one more than labels: a place_label dispatch each, and the last one's main pass)
  b.buckets =
      graph.add_buffer("placement.buckets", fixed((n + 1) * sizeof(gpu::PlacementBucketsGpu)));
  b.lower = graph.add_buffer("placement.lower", fixed(n * sizeof(uint32_t)));
  b.args = graph.add_buffer("placement.args", fixed((n + 1) * 3 * sizeof(uint32_t)));
  b.speculative = graph.add_buffer("placement.speculative", per_tile(sizeof(uint64_t), 2));
  b.samples = graph.add_buffer("placement.samples", per_tile(sizeof(uint64_t)));
  b.tidy = graph.add_buffer("placement.tidy", fixed(n * sizeof(gpu::TidyGpu)));
  b.tidy_rounds =
      graph.add_buffer("placement.tidy_rounds", fixed((TIDY_ROUNDS_MAX + 1) * sizeof(uint32_t)));
  b.tidy_args = graph.add_buffer("placement.tidy_args",
                                 fixed(TIDY_ROUNDS_MAX * TIDY_ROUND_STEPS * 3 * sizeof(uint32_t)));
  b.regions = graph.add_buffer(
      "placement.regions",
      fixed(VkDeviceSize{gpu::placement_pair_count(n)} * sizeof(gpu::PairRegionsGpu)));
  b.ranks = graph.add_buffer("placement.ranks", fixed(n * sizeof(uint32_t)));
  b.round_of = graph.add_buffer("placement.round_of", fixed(n * sizeof(uint32_t)));
  b.round_list = graph.add_buffer("placement.round_list", fixed(n * sizeof(uint32_t)));
  b.round_args =
      graph.add_buffer("placement.round_args", fixed(ROUNDS_MAX * 3 * sizeof(uint32_t)));
  b.round_counts =
      graph.add_buffer("placement.round_counts", fixed((ROUNDS_MAX + 1) * sizeof(uint32_t)));
  b.round_bits = graph.add_buffer(
      "placement.round_bits", fixed(VkDeviceSize{n} * gpu::rounds_row_words(n) * sizeof(uint32_t)));
  b.round_done = graph.add_buffer("placement.round_done", fixed(ROUNDS_MAX * sizeof(uint32_t)));
  b.round_wide = graph.add_buffer("placement.round_wide", fixed(n * sizeof(uint32_t)));
  b.keep_out =
      graph.add_buffer("placement.keep_out", fixed(PLACEMENT_KEEP_OUT_MAX * sizeof(glm::uvec4)));
  b.readback = readback_.import(graph, "placement.readback");
  return b;
}

// The frame's labels and order; everything the loop accumulates starts empty.
void Placement::add_upload(graph::Graph& graph, const Buffers& b) {
  graph.add_pass({"placement.upload",
                  graph::PassKind::transfer,
                  {{b.labels, Use::transfer_dst},
                   {b.order, Use::transfer_dst},
                   {b.keep_out, Use::transfer_dst},
                   {b.results, Use::transfer_dst},
                   {b.constraints, Use::transfer_dst},
                   {b.buckets, Use::transfer_dst},
                   {b.lower, Use::transfer_dst},
                   {b.speculative, Use::transfer_dst},
                   {b.samples, Use::transfer_dst},
                   {b.tidy_args, Use::transfer_dst},
                   {b.ranks, Use::transfer_dst},
                   {b.round_of, Use::transfer_dst},
                   {b.round_args, Use::transfer_dst},
                   {b.round_counts, Use::transfer_dst},
                   {b.round_done, Use::transfer_dst}},
                  [this, b](graph::PassContext& pc) {
                    record_update(pc.cmd, pc.buffer(b.labels), 0, as_bytes(labels_));
                    record_update(pc.cmd, pc.buffer(b.order), 0, as_bytes(order_));
                    // (the whole buffer: a shader's binding is read only up to keep_out_count)
                    std::vector<glm::uvec4> keep_out = keep_out_rectangles(settings_);
                    keep_out.resize(PLACEMENT_KEEP_OUT_MAX, glm::uvec4(0u));
                    record_update(pc.cmd, pc.buffer(b.keep_out), 0, as_bytes(keep_out));
                    const auto fill = [&pc](ResourceId id, uint32_t value) {
                      vkCmdFillBuffer(pc.cmd, pc.buffer(id), 0, VK_WHOLE_SIZE, value);
                    };
                    fill(b.results, 0xFFFFFFFFu);  // "not placed"
                    fill(b.constraints, 0);
                    fill(b.buckets, 0);
                    fill(b.lower, 0xFFFFFFFFu);
                    // (each speculative workgroup writes its tile's entry before anything reads it)
                    fill(b.speculative, 0xFFFFFFFFu);
                    fill(b.samples, 0xFFFFFFFFu);
                    // (indirect: no round runs until the one before sizes it)
                    fill(b.tidy_args, 0);
                    // The rounds, where the frame places in them: every label undecided; each
                    // recorded round's search sized by its list.
                    if (settings_.method == PlacementMethod::rounds) {
                      record_update(pc.cmd, pc.buffer(b.ranks), 0, as_bytes(ranks_));
                      fill(b.round_of, ROUND_UNDECIDED);
                      fill(b.round_done, 0);
                      const uint32_t rounds = round_count();
                      std::vector<uint32_t> args(rounds * 3, 1u);
                      for (uint32_t r = 0; r < rounds; ++r) {
                        args[3 * r] = round_groups(pc.viewport);
                        args[3 * r + 1] = 0;
                      }
                      record_update(pc.cmd, pc.buffer(b.round_args), 0, as_bytes(args));
                      std::vector<uint32_t> counts(rounds + 1, 0u);
                      counts[0] = uint32_t(order_.size());
                      record_update(pc.cmd, pc.buffer(b.round_counts), 0, as_bytes(counts));
                    }
                    // (placement.regions needs none: the loop writes each pair, from the placed
                    // label's result, before a later label reads it; a label never placed
                    // writes regions that constrain nobody)
                  },
                  "placement"});
}

// Saliency (eq. 3.5), integral costs per layer (eq. 3.3/3.4) and hidden pixels per layer in one
// pass, then their summed-area tables.
void Placement::add_costs(graph::Graph& graph, const Buffers& b, const Inputs& in) {
  graph.add_pass({"placement.integral_costs",
                  graph::PassKind::compute,
                  {{in.final_image, Use::storage_read, PLACEMENT_BINDING_FINAL},
                   {b.saliency, Use::storage_write, PLACEMENT_BINDING_SALIENCY},
                   {in.layers, Use::storage_read, PLACEMENT_BINDING_LAYERS},
                   {b.labels, Use::storage_read, PLACEMENT_BINDING_LABELS},
                   {b.costs, Use::storage_write, PLACEMENT_BINDING_COSTS}},
                  [this](graph::PassContext& pc) {
                    pc.dispatch(
                        integral_costs_,
                        integral_costs_params(settings_, pc.viewport, layer_count_, frame_count()),
                        {pc.viewport.width, pc.viewport.height, 1});
                  },
                  "placement"});
  tables_.add_to(graph, b.costs, b.tables, "placement.sat", 2 * in.layer_count);
}

// Tile bounds, bucket counts, tiles sorted by bucket: for every label at once, since none of it
// depends on where earlier labels go.
void Placement::add_bounds(graph::Graph& graph, const Buffers& b) {
  static constexpr const char* names[] = {"placement.bounds", "placement.buckets",
                                          "placement.tiles"};
  for (const uint32_t phase :
       {PLACEMENT_PHASE_BOUNDS, PLACEMENT_PHASE_COUNT, PLACEMENT_PHASE_SORT}) {
    graph.add_pass(
        {names[phase],
         graph::PassKind::compute,
         {{b.tables, Use::storage_read, PLACEMENT_BINDING_TABLES},
          {b.labels, Use::storage_read, PLACEMENT_BINDING_LABELS},
          {b.order, Use::storage_read, PLACEMENT_BINDING_ORDER},
          // (one shader for the three phases: the bounds phase writes the bounds and the later
          // ones read them, but each binds them writable; the tile list and the sizes are bound
          // in each phase, only the last writes them)
          {b.bounds, phase == PLACEMENT_PHASE_BOUNDS ? Use::storage_write : Use::storage_read_write,
           PLACEMENT_BINDING_BOUNDS},
          {b.buckets, Use::storage_read_write, PLACEMENT_BINDING_BUCKETS},
          {b.tiles, Use::storage_write, PLACEMENT_BINDING_TILES},
          {b.lower, Use::storage_read_write, PLACEMENT_BINDING_LOWER},
          {b.args, Use::storage_write, PLACEMENT_BINDING_ARGS}},
         [this, phase](graph::PassContext& pc) {
           if (order_.empty()) return;
           gpu::PlacementParams p = params(pc.viewport, 0);
           p.phase = phase;
           const glm::uvec2 across = gpu::placement_tiles(pc.viewport.width, pc.viewport.height);
           const uint32_t tile_count = across.x * across.y;
           // Bounds: PLACEMENT_BOUNDS_TILES tiles per workgroup, a cell per invocation; then a
           // tile per invocation.
           const uint32_t groups = phase == PLACEMENT_PHASE_BOUNDS
                                       ? group_count(tile_count, PLACEMENT_BOUNDS_TILES)
                                       : group_count(tile_count, PLACEMENT_BOUNDS_GROUP);
           pc.dispatch_groups(bounds_, p, {groups, uint32_t(order_.size()), 1});
         },
         "placement"});
  }
}

// The greedy loop as one graph pass: a place_label dispatch per label and one more (dispatch j:
// the main pass of order position j - 1 and the speculative pass of j), each reading what the one
// before wrote, so the graph's barrier helper separates them. Each dispatch sizes the next one's
// main pass, and the next dispatch. With pass_per_label, a pass per dispatch, with the same uses:
// the graph derives the barrier between them.
graph::PassId Placement::add_label_loop(graph::Graph& graph, const Buffers& b) {
  std::vector<graph::ResourceUse> uses{
      {b.tables, Use::storage_read, PLACEMENT_BINDING_TABLES},
      {b.labels, Use::storage_read, PLACEMENT_BINDING_LABELS},
      {b.keep_out, Use::storage_read, PLACEMENT_BINDING_KEEP_OUT},
      {b.order, Use::storage_read, PLACEMENT_BINDING_ORDER},
      {b.results, Use::storage_read_write, PLACEMENT_BINDING_RESULTS},
      {b.constraints, Use::storage_read_write, PLACEMENT_BINDING_CONSTRAINTS},
      {b.buckets, Use::storage_read_write, PLACEMENT_BINDING_BUCKETS},
      {b.tiles, Use::storage_read_write, PLACEMENT_BINDING_TILES},
      {b.args, Use::storage_read_write, PLACEMENT_BINDING_ARGS},
      {b.speculative, Use::storage_read_write, PLACEMENT_BINDING_SPECULATIVE},
      // (written: the loop writes every pair before it reads it)
      {b.regions, Use::storage_write, PLACEMENT_BINDING_REGIONS},
      {b.samples, Use::storage_read_write, PLACEMENT_BINDING_SAMPLES}};
  declare_sizes(uses, b.args);
  // Steps [first, end) of the loop, those the frame's order has.
  const auto steps = [this, args = b.args](uint32_t first, uint32_t end) {
    return [this, args, first, end](graph::PassContext& pc) {
      if (settings_.method != PlacementMethod::sequential) return;
      const glm::uvec3 groups = direct_groups(pc.viewport);
      for (uint32_t step = first; step < end && step <= order_.size() && !order_.empty(); ++step) {
        if (step > first) pc.barrier();
        dispatch(pc, place_, params(pc.viewport, step), args,
                 VkDeviceSize{step} * 3 * sizeof(uint32_t), groups);
      }
    };
  };
  if (!layout_.pass_per_label) {
    return graph.add_pass({"placement.labels", graph::PassKind::compute, std::move(uses),
                           steps(0, label_count_ + 1), "placement"});
  }
  const auto first = static_cast<graph::PassId>(graph.passes().size());
  for (uint32_t step = 0; step <= label_count_; ++step) {
    graph.add_pass({"placement.labels." + std::to_string(step), graph::PassKind::compute, uses,
                    steps(step, step + 1), "placement"});
  }
  return first;
}

uint32_t Placement::round_count() const {
  return std::min({settings_.rounds, ROUNDS_MAX, std::max(uint32_t(order_.size()), 1u)});
}

uint32_t Placement::round_groups(graph::Extent viewport) const {
  const glm::uvec2 across = gpu::placement_tiles(viewport.width, viewport.height);
  return std::min(ROUNDS_GROUPS, across.x * across.y);
}

// The greedy placement in rounds (place_rounds.comp): mark, search, commit, each over every label
// at once. Where the device has conditional rendering, a block of kTidyBlockRounds rounds past the
// first runs only while some label is undecided before it.
graph::PassId Placement::add_rounds(graph::Graph& graph, const Buffers& b) {
  std::vector<graph::ResourceUse> uses{
      {b.tables, Use::storage_read, PLACEMENT_BINDING_TABLES},
      {b.labels, Use::storage_read, PLACEMENT_BINDING_LABELS},
      {b.keep_out, Use::storage_read, PLACEMENT_BINDING_KEEP_OUT},
      {b.results, Use::storage_read_write, PLACEMENT_BINDING_RESULTS},
      {b.constraints, Use::storage_write, PLACEMENT_BINDING_CONSTRAINTS},
      {b.buckets, Use::storage_read, PLACEMENT_BINDING_BUCKETS},
      {b.tiles, Use::storage_read, PLACEMENT_BINDING_TILES},
      {b.ranks, Use::storage_read, PLACEMENT_BINDING_RANKS},
      {b.round_of, Use::storage_read_write, PLACEMENT_BINDING_ROUND_OF},
      // (written: each round marks its list before it searches it)
      {b.round_list, Use::storage_write, PLACEMENT_BINDING_ROUND_LIST},
      {b.round_args, Use::storage_read_write, PLACEMENT_BINDING_ROUND_ARGS},
      {b.round_counts, Use::storage_read_write, PLACEMENT_BINDING_ROUND_COUNTS},
      // (written: each label clears its row before it sets bits)
      {b.round_bits, Use::storage_write, PLACEMENT_BINDING_ROUND_BITS},
      {b.round_done, Use::storage_read_write, PLACEMENT_BINDING_ROUND_DONE},
      // (written: MARK resets a label's before EVALUATE counts on it)
      {b.round_wide, Use::storage_write, PLACEMENT_BINDING_ROUND_WIDE},
      {b.round_args, Use::indirect}};
  const bool skip_idle = ctx_.conditional_rendering() && layout_.skip_idle_blocks;
  if (skip_idle) uses.push_back({b.round_counts, Use::conditional});
  return graph.add_pass(
      {"placement.rounds", graph::PassKind::compute, std::move(uses),
       [this, b, skip_idle](graph::PassContext& pc) {
         if (order_.empty() || settings_.method != PlacementMethod::rounds) return;
         // (made when a frame first asks for the rounds: it costs a CPU device's startup)
         if (!rounds_) rounds_.emplace(ctx_, "place_rounds.comp");
         const ComputePipeline& pipeline = *rounds_;
         gpu::PlacementParams p = params(pc.viewport, 0);
         const uint32_t rounds = round_count();
         p.label = rounds;
         p.spec_label = std::max(settings_.round_tiles, 1u);
         const uint32_t n = frame_count();
         for (uint32_t round = 0; round < rounds; ++round) {
           p.step = round;
           const uint32_t block_start = round - round % kTidyBlockRounds;
           const bool conditional = skip_idle && block_start > 0;
           if (conditional && round == block_start) {
             pc.barrier_for_predicates();
             pc.begin_conditional(b.round_counts, block_start * sizeof(uint32_t));
           } else if (round > 0) {
             pc.barrier();
           }
           p.phase = ROUNDS_PHASE_MARK;
           pc.dispatch_groups(pipeline, p, {n, 1, 1});
           pc.barrier();
           p.phase = ROUNDS_PHASE_EVALUATE;
           pc.dispatch_indirect(pipeline, p, b.round_args, VkDeviceSize{round} * 3 * sizeof(uint32_t));
           pc.barrier();
           if (settings_.wide_search) {
             p.phase = ROUNDS_PHASE_WIDE;
             pc.dispatch_indirect(pipeline, p, b.round_args,
                                  VkDeviceSize{round} * 3 * sizeof(uint32_t));
             pc.barrier();
           }
           p.phase = ROUNDS_PHASE_COMMIT;
           pc.dispatch_groups(pipeline, p, {n, 1, 1});
           const bool block_ends = (round + 1) % kTidyBlockRounds == 0 || round + 1 == rounds;
           if (conditional && block_ends) pc.end_conditional();
         }
       },
       "placement"});
}

void Placement::declare_sizes(std::vector<graph::ResourceUse>& uses, ResourceId args) const {
  // (a direct plan declares none: an indirect use makes every barrier of the pass wait for
  // indirect reads too, which costs a GPU's hundreds of barriers dearly)
  if (plan_.indirect) uses.push_back({args, Use::indirect});
}

void Placement::dispatch(graph::PassContext& pc, const ComputePipeline& pipeline,
                         const gpu::PlacementParams& p, ResourceId args, VkDeviceSize offset,
                         glm::uvec3 groups) const {
  if (plan_.indirect) {
    pc.dispatch_indirect(pipeline, p, args, offset);
  } else {
    pc.dispatch_groups(pipeline, p, groups);
  }
}

// A direct place_label dispatch: room for any classification, the passes' tiles and the region
// writer (workgroups past the sizes the GPU wrote leave at once).
glm::uvec3 Placement::direct_groups(graph::Extent viewport) const {
  const glm::uvec2 across = gpu::placement_tiles(viewport.width, viewport.height);
  const uint32_t tile_count = across.x * across.y;
  const uint32_t tiles = std::min(2 * tile_count, std::max(layout_.direct_groups, 1u));
  return gpu::placement_dispatch_size(
      gpu::placement_classify_groups(tile_count, classify_tiles(viewport)) + tiles + 1);
}

// The tidy-up: its start, its rounds (four dispatches each; a round after one that changed nothing
// has nothing to do), and each label's position and whether it is shown, copied to the host after
// the frame.
void Placement::add_tidy(graph::Graph& graph, const Buffers& b) {
  std::vector<graph::ResourceUse> uses = {
      {b.tables, Use::storage_read, PLACEMENT_BINDING_TABLES},
      {b.labels, Use::storage_read, PLACEMENT_BINDING_LABELS},
      {b.keep_out, Use::storage_read, PLACEMENT_BINDING_KEEP_OUT},
      {b.order, Use::storage_read, PLACEMENT_BINDING_ORDER},
      {b.results, Use::storage_read, PLACEMENT_BINDING_RESULTS},
      {b.tidy, Use::storage_write, PLACEMENT_BINDING_TIDY},
      {b.tidy_rounds, Use::storage_write, PLACEMENT_BINDING_TIDY_ROUNDS},
      {b.tidy_args, Use::storage_read_write, PLACEMENT_BINDING_TIDY_ARGS},
      {b.placements, Use::storage_write, PLACEMENT_BINDING_PLACEMENTS}};
  declare_sizes(uses, b.tidy_args);
  if (plan_.skip_idle_blocks) uses.push_back({b.tidy_rounds, Use::conditional});
  graph.add_pass({"placement.tidy", graph::PassKind::compute, std::move(uses),
                  [this, b](graph::PassContext& pc) {
                    gpu::PlacementParams p = params(pc.viewport, 0);
                    p.phase = TIDY_PHASE_START;
                    pc.dispatch(tidy_, p, {std::max(frame_count(), p.tidy_rounds + 1), 1, 1});
                    record_tidy_rounds(pc, p, b);
                    pc.barrier();
                    p.phase = TIDY_PHASE_OUTPUT;
                    pc.dispatch(tidy_, p, {frame_count(), 1, 1});
                  },
                  "placement"});
  graph.add_pass({"placement.readback",
                  graph::PassKind::transfer,
                  {{b.placements, Use::transfer_src}, {b.readback, Use::transfer_dst}},
                  [this, b](graph::PassContext& pc) {
                    const VkBufferCopy region{0, 0, readback_.size()};
                    vkCmdCopyBuffer(pc.cmd, pc.buffer(b.placements), pc.buffer(b.readback), 1,
                                    &region);
                  }});
}

// The tidy-up's rounds. Where the plan skips idle blocks, a block of kTidyBlockRounds past the
// first runs only when the round before it applied a change: its first round's count in the rounds
// buffer, which a round of the block before wrote. (One conditional block per block of rounds:
// one around each dispatch cost a GPU more than the idle dispatches it skipped.)
void Placement::record_tidy_rounds(graph::PassContext& pc, gpu::PlacementParams p,
                                   const Buffers& b) const {
  for (uint32_t round = 0; round < p.tidy_rounds; ++round) {
    p.step = round;
    const uint32_t block_start = round - round % kTidyBlockRounds;
    const bool conditional = plan_.skip_idle_blocks && block_start > 0;
    if (conditional && round == block_start) {
      pc.barrier_for_predicates();
      pc.begin_conditional(b.tidy_rounds, block_start * sizeof(uint32_t));
    } else {
      pc.barrier();
    }
    for (uint32_t k = 0; k < TIDY_ROUND_STEPS; ++k) {
      if (k > 0) pc.barrier();
      p.phase = TIDY_PHASE_CONFLICTS + k;
      // (the search's workgroups pass 65535 from about 900 labels: rows of them)
      const ComputePipeline& pipeline = p.phase == TIDY_PHASE_SEARCH ? search_ : tidy_;
      const VkDeviceSize offset =
          (VkDeviceSize{round} * TIDY_ROUND_STEPS + k) * 3 * sizeof(uint32_t);
      dispatch(pc, pipeline, p, b.tidy_args, offset,
               gpu::tidy_phase_groups(p.phase, frame_count()));
    }
    const bool block_ends = (round + 1) % kTidyBlockRounds == 0 || round + 1 == p.tidy_rounds;
    if (conditional && block_ends) pc.end_conditional();
  }
}

std::vector<PipelineReport> Placement::pipeline_statistics() const {
  std::vector<PipelineReport> out;
  for (const ComputePipeline* p : {&integral_costs_, &bounds_, &place_, &tidy_, &search_}) {
    out.push_back({p->name(), p->statistics()});
  }
  if (rounds_) out.push_back({rounds_->name(), rounds_->statistics()});
  return out;
}

std::span<const gpu::PlacementGpu> Placement::results() const {
  return {reinterpret_cast<const gpu::PlacementGpu*>(readback_.data().data()), label_count_};
}

}  // namespace strata
