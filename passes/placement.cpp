#include "passes/placement.h"

#include <cstring>

#include "engine/gpu/context.h"
#include "engine/core/error.h"

namespace strata {

using graph::ResourceId;
using graph::Use;

gpu::PlacementParams placement_params(const PlacementSettings& s, graph::Extent viewport,
                                      uint32_t layer_count, uint32_t label_count, uint32_t step) {
  gpu::PlacementParams p{};
  const CostWeights& w = s.weights;
  p.weights = {w.distance_to_anchor, w.connector_direction, w.label_shadow,      w.connector_shadow,
               w.anchor_constraint,  w.integral_costs,      w.previous_position, 0.0f};
  p.width = viewport.width;
  p.height = viewport.height;
  p.layer_count = layer_count;
  p.label_count = label_count;
  p.step = step;
  p.hard = s.hard ? 1u : 0u;
  p.write_constraints = s.write_constraints ? 1u : 0u;
  p.margin = s.margin;
  p.saliency_weight = s.saliency_weight;
  p.occlusion_weight = s.occlusion_weight;
  p.single_saliency_weight = s.single_saliency_weight;
  p.bucket_width = s.bucket_width;
  return p;
}

Placement::Placement(Context& ctx, uint32_t label_count, PlacementLayout layout)
    : ctx_(ctx),
      label_count_(label_count),
      indirect_(layout.dispatch == LabelDispatch::indirect ||
                (layout.dispatch == LabelDispatch::automatic &&
                 ctx.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU)),
      layout_(layout),
      saliency_(ctx, "saliency.comp"),
      integral_costs_(ctx, "integral_costs.comp"),
      bounds_(ctx, "placement_bounds.comp"),
      place_(ctx, "place_label.comp"),
      finalize_(ctx, "placement_finalize.comp"),
      tables_(ctx) {
  if (label_count > LABEL_MAX) {
    throw Error("placement: " + std::to_string(label_count) + " labels; strata places at most " +
                std::to_string(LABEL_MAX));
  }
  readback_ = Buffer(ctx, std::max<VkDeviceSize>(1, label_count) * sizeof(gpu::PlacementGpu),
                     VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryKind::host_readback);
  std::memset(readback_.mapped(), 0, readback_.size());
}

gpu::PlacementParams Placement::params(graph::Extent viewport, uint32_t step) const {
  gpu::PlacementParams p = placement_params(settings_, viewport, layer_count_, label_count_, step);
  p.order_count = static_cast<uint32_t>(order_.size());
  // place_label dispatch `step`: the main pass of position step - 1, the speculative one of step
  p.label = step > 0 && step <= order_.size() ? order_[step - 1] : 0;
  p.spec_label = step < order_.size() ? order_[step] : 0;
  p.finish_lanes = layout_.finish_lanes;
  return p;
}

void Placement::set_frame(std::vector<gpu::LabelGpu> labels, std::vector<uint32_t> order,
                          const PlacementSettings& settings) {
  if (labels.size() != label_count_ || order.size() > label_count_) {
    throw Error("placement: set_frame got " + std::to_string(labels.size()) + " labels and " +
                std::to_string(order.size()) + " in the order for " + std::to_string(label_count_));
  }
  labels_ = std::move(labels);
  order_ = std::move(order);
  settings_ = settings;
}

Placement::Resources Placement::add_to(graph::Graph& graph, ResourceId final_image,
                                       ResourceId layers, uint32_t layer_count) {
  layer_count_ = layer_count;
  const uint32_t n = std::max(label_count_, 1u);
  const auto fixed = [](VkDeviceSize bytes) {
    return graph::BufferInfo{[bytes](graph::Extent) { return bytes; }};
  };
  const auto per_pixel = [](VkDeviceSize bytes) {
    return graph::BufferInfo{
        [bytes](graph::Extent e) { return VkDeviceSize{e.width} * e.height * bytes; }};
  };
  Resources r;
  r.labels = graph.add_buffer("placement.labels", fixed(n * sizeof(gpu::LabelGpu)));
  const ResourceId order = graph.add_buffer("placement.order", fixed(n * sizeof(uint32_t)));
  const ResourceId results = graph.add_buffer("placement.results", fixed(n * sizeof(uint64_t)));
  r.results = results;
  r.placements = graph.add_buffer("placement.placements", fixed(n * sizeof(gpu::PlacementGpu)));
  r.saliency = graph.add_buffer("placement.saliency", per_pixel(sizeof(float)));
  r.costs = graph.add_buffer("placement.integral_costs", per_pixel(sizeof(float) * layer_count));
  r.tables = graph.add_buffer("placement.tables", per_pixel(sizeof(float) * layer_count));
  r.constraints = graph.add_buffer("placement.constraints", per_pixel(sizeof(uint32_t)));
  const auto per_label_tile = [n](VkDeviceSize bytes) {
    return graph::BufferInfo{[n, bytes](graph::Extent e) {
      const glm::uvec2 tiles = gpu::placement_tiles(e.width, e.height);
      return VkDeviceSize{n} * tiles.x * tiles.y * bytes;
    }};
  };
  const ResourceId bounds = graph.add_buffer("placement.bounds", per_label_tile(sizeof(float)));
  const ResourceId tiles =
      graph.add_buffer("placement.tiles", per_label_tile(2 * sizeof(uint32_t)));
  // (one more than labels: a place_label dispatch each, and the last one's main pass)
  const ResourceId buckets =
      graph.add_buffer("placement.buckets", fixed((n + 1) * sizeof(gpu::PlacementBucketsGpu)));
  r.buckets = buckets;
  const ResourceId lower = graph.add_buffer("placement.lower", fixed(n * sizeof(uint32_t)));
  const ResourceId args = graph.add_buffer("placement.args", fixed((n + 1) * 3 * sizeof(uint32_t)));
  const ResourceId speculative =
      graph.add_buffer("placement.speculative", graph::BufferInfo{[](graph::Extent e) {
                         const glm::uvec2 across = gpu::placement_tiles(e.width, e.height);
                         return VkDeviceSize{2} * across.x * across.y * sizeof(uint64_t);
                       }});
  const ResourceId samples =
      graph.add_buffer("placement.samples", graph::BufferInfo{[](graph::Extent e) {
                         const glm::uvec2 across = gpu::placement_tiles(e.width, e.height);
                         return VkDeviceSize{across.x} * across.y * sizeof(uint64_t);
                       }});
  const ResourceId regions =
      graph.add_buffer("placement.regions", fixed(VkDeviceSize{n} * n * sizeof(gpu::PairRegionsGpu)));
  readback_id_ = graph.import_resource("placement.readback",
                                       {false, false, VK_IMAGE_LAYOUT_UNDEFINED, Use::host_read});

  graph.add_pass({"placement.upload",
                  graph::PassKind::transfer,
                  {{r.labels, Use::transfer_dst},
                   {order, Use::transfer_dst},
                   {results, Use::transfer_dst},
                   {r.constraints, Use::transfer_dst},
                   {buckets, Use::transfer_dst},
                   {lower, Use::transfer_dst},
                   {speculative, Use::transfer_dst},
                   {samples, Use::transfer_dst},
                   {regions, Use::transfer_dst}},
                  [this, r, order, results, buckets, lower, speculative, samples,
                   regions](graph::PassContext& pc) {
                    if (!labels_.empty()) {
                      vkCmdUpdateBuffer(pc.cmd, pc.buffer(r.labels), 0,
                                        labels_.size() * sizeof(gpu::LabelGpu), labels_.data());
                    }
                    if (!order_.empty()) {
                      vkCmdUpdateBuffer(pc.cmd, pc.buffer(order), 0,
                                        order_.size() * sizeof(uint32_t), order_.data());
                    }
                    vkCmdFillBuffer(pc.cmd, pc.buffer(results), 0, VK_WHOLE_SIZE, 0xFFFFFFFFu);
                    vkCmdFillBuffer(pc.cmd, pc.buffer(r.constraints), 0, VK_WHOLE_SIZE, 0);
                    vkCmdFillBuffer(pc.cmd, pc.buffer(buckets), 0, VK_WHOLE_SIZE, 0);
                    vkCmdFillBuffer(pc.cmd, pc.buffer(lower), 0, VK_WHOLE_SIZE, 0xFFFFFFFFu);
                    // (each speculative workgroup writes its tile's entry before anything reads it)
                    vkCmdFillBuffer(pc.cmd, pc.buffer(speculative), 0, VK_WHOLE_SIZE, 0xFFFFFFFFu);
                    vkCmdFillBuffer(pc.cmd, pc.buffer(samples), 0, VK_WHOLE_SIZE, 0xFFFFFFFFu);
                    // No regions: a label that is never placed constrains nobody.
                    vkCmdFillBuffer(pc.cmd, pc.buffer(regions), 0, VK_WHOLE_SIZE, 0);
                  },
                  "placement"});
  const auto per_pixel_dispatch = [this](const ComputePipeline& pipeline, graph::PassContext& pc) {
    pc.bind(pipeline);
    pipeline.push_constants(pc.cmd, params(pc.viewport, 0));
    vkCmdDispatch(pc.cmd, group_count(pc.viewport.width, PLACEMENT_GROUP),
                  group_count(pc.viewport.height, PLACEMENT_GROUP), 1);
  };
  graph.add_pass(
      {"placement.saliency",
       graph::PassKind::compute,
       {{final_image, Use::storage_read, PLACEMENT_BINDING_FINAL},
        {r.saliency, Use::storage_write, PLACEMENT_BINDING_SALIENCY}},
       [this, per_pixel_dispatch](graph::PassContext& pc) { per_pixel_dispatch(saliency_, pc); },
       "placement"});
  graph.add_pass({"placement.integral_costs",
                  graph::PassKind::compute,
                  {{r.saliency, Use::storage_read, PLACEMENT_BINDING_SALIENCY},
                   {layers, Use::storage_read, PLACEMENT_BINDING_LAYERS},
                   {r.costs, Use::storage_write, PLACEMENT_BINDING_COSTS}},
                  [this, per_pixel_dispatch](graph::PassContext& pc) {
                    per_pixel_dispatch(integral_costs_, pc);
                  },
                  "placement"});
  tables_.add_to(graph, r.costs, r.tables, "placement.sat", layer_count);
  // Tile bounds, bucket counts, tiles sorted by bucket: for every label at once.
  for (const uint32_t phase :
       {PLACEMENT_PHASE_BOUNDS, PLACEMENT_PHASE_COUNT, PLACEMENT_PHASE_SORT}) {
    static constexpr const char* names[] = {"placement.bounds", "placement.buckets",
                                            "placement.tiles"};
    graph.add_pass(
        {names[phase],
         graph::PassKind::compute,
         {{r.tables, Use::storage_read, PLACEMENT_BINDING_TABLES},
          {r.labels, Use::storage_read, PLACEMENT_BINDING_LABELS},
          {order, Use::storage_read, PLACEMENT_BINDING_ORDER},
          // (one shader for the three phases: the bounds phase writes the bounds and
          // the later ones read them, but each binds them writable; the tile list and
          // the sizes are bound in each phase, only the last writes them)
          {bounds, phase == PLACEMENT_PHASE_BOUNDS ? Use::storage_write : Use::storage_read_write,
           PLACEMENT_BINDING_BOUNDS},
          {buckets, Use::storage_read_write, PLACEMENT_BINDING_BUCKETS},
          {tiles, Use::storage_write, PLACEMENT_BINDING_TILES},
          {lower, Use::storage_read_write, PLACEMENT_BINDING_LOWER},
          {args, Use::storage_write, PLACEMENT_BINDING_ARGS}},
         [this, phase](graph::PassContext& pc) {
           if (order_.empty()) return;
           pc.bind(bounds_);
           gpu::PlacementParams p = params(pc.viewport, 0);
           p.phase = phase;
           bounds_.push_constants(pc.cmd, p);
           const glm::uvec2 across = gpu::placement_tiles(pc.viewport.width, pc.viewport.height);
           const uint32_t tile_count = across.x * across.y;
           // Bounds: a workgroup of 64 per tile (its cells); then 64 tiles per group.
           vkCmdDispatch(pc.cmd,
                         phase == PLACEMENT_PHASE_BOUNDS ? tile_count : group_count(tile_count, 64),
                         static_cast<uint32_t>(order_.size()), 1);
         },
         "placement"});
  }
  // One dispatch per label and one more (dispatch j: the main pass of order position j - 1 and
  // the speculative pass of j); each sizes the next one's main pass, and the next dispatch.
  std::vector<graph::ResourceUse> label_uses{
      {r.tables, Use::storage_read, PLACEMENT_BINDING_TABLES},
      {r.labels, Use::storage_read, PLACEMENT_BINDING_LABELS},
      {order, Use::storage_read, PLACEMENT_BINDING_ORDER},
      {results, Use::storage_read_write, PLACEMENT_BINDING_RESULTS},
      {r.constraints, Use::storage_read_write, PLACEMENT_BINDING_CONSTRAINTS},
      {buckets, Use::storage_read_write, PLACEMENT_BINDING_BUCKETS},
      {tiles, Use::storage_read_write, PLACEMENT_BINDING_TILES},
      {args, Use::storage_read_write, PLACEMENT_BINDING_ARGS},
      {speculative, Use::storage_read_write, PLACEMENT_BINDING_SPECULATIVE},
      {regions, Use::storage_read_write, PLACEMENT_BINDING_REGIONS},
      {samples, Use::storage_read_write, PLACEMENT_BINDING_SAMPLES}};
  // (direct: the sizes are still written, but no barrier waits for them)
  if (indirect_) label_uses.push_back({args, Use::indirect});
  for (uint32_t step = 0; step <= label_count_; ++step) {
    graph.add_pass({"placement.label", graph::PassKind::compute, label_uses,
                    [this, step, args](graph::PassContext& pc) {
                      // (fewer labels enabled this frame, or none)
                      if (order_.empty() || step > order_.size()) return;
                      pc.bind(place_);
                      place_.push_constants(pc.cmd, params(pc.viewport, step));
                      if (indirect_) {
                        vkCmdDispatchIndirect(pc.cmd, pc.buffer(args),
                                              VkDeviceSize{step} * 3 * sizeof(uint32_t));
                        return;
                      }
                      // Room for any classification, the passes' tiles and the region
                      // writer.
                      const glm::uvec2 across =
                          gpu::placement_tiles(pc.viewport.width, pc.viewport.height);
                      const uint32_t tile_count = across.x * across.y;
                      const glm::uvec3 groups = gpu::placement_dispatch_size(
                          gpu::placement_classify_groups(tile_count) +
                          std::min(2 * tile_count, std::max(layout_.direct_groups, 1u)) + 1);
                      vkCmdDispatch(pc.cmd, groups.x, groups.y, groups.z);
                    },
                    "placement"});
  }
  graph.add_pass({"placement.finalize",
                  graph::PassKind::compute,
                  {{r.labels, Use::storage_read, PLACEMENT_BINDING_LABELS},
                   {results, Use::storage_read, PLACEMENT_BINDING_RESULTS},
                   {r.placements, Use::storage_write, PLACEMENT_BINDING_PLACEMENTS}},
                  [this](graph::PassContext& pc) {
                    pc.bind(finalize_);
                    finalize_.push_constants(pc.cmd, params(pc.viewport, 0));
                    vkCmdDispatch(pc.cmd, group_count(label_count_, 64), 1, 1);
                  },
                  "placement"});
  const ResourceId readback = readback_id_;
  const ResourceId placements = r.placements;
  graph.add_pass({"placement.readback",
                  graph::PassKind::transfer,
                  {{placements, Use::transfer_src}, {readback, Use::transfer_dst}},
                  [this, placements, readback](graph::PassContext& pc) {
                    const VkBufferCopy region{0, 0, readback_.size()};
                    vkCmdCopyBuffer(pc.cmd, pc.buffer(placements), pc.buffer(readback), 1, &region);
                  }});
  return r;
}

void Placement::bind(graph::GraphRunner& runner) {
  runner.bind_buffer(readback_id_, readback_.handle());
}

std::vector<PipelineReport> Placement::pipeline_statistics()
    const {
  std::vector<PipelineReport> out;
  for (const ComputePipeline* p : {&saliency_, &integral_costs_, &bounds_, &place_, &finalize_}) {
    out.push_back({p->name(), p->statistics()});
  }
  return out;
}

std::span<const gpu::PlacementGpu> Placement::results() const {
  return {reinterpret_cast<const gpu::PlacementGpu*>(readback_.mapped()), label_count_};
}

}  // namespace strata
