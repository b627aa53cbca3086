#include "passes/placement.h"

#include <cstring>

#include "engine/context.h"
#include "engine/error.h"

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
  return p;
}

Placement::Placement(Context& ctx, uint32_t label_count)
    : ctx_(ctx),
      label_count_(label_count),
      saliency_(ctx, "saliency.comp"),
      integral_costs_(ctx, "integral_costs.comp"),
      place_label_(ctx, "place_label.comp"),
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
  return placement_params(settings_, viewport, layer_count_, label_count_, step);
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
  readback_id_ = graph.import_resource("placement.readback",
                                       {false, false, VK_IMAGE_LAYOUT_UNDEFINED, Use::host_read});

  graph.add_pass({"placement.upload",
                  graph::PassKind::transfer,
                  {{r.labels, Use::transfer_dst},
                   {order, Use::transfer_dst},
                   {results, Use::transfer_dst},
                   {r.constraints, Use::transfer_dst}},
                  [this, r, order, results](graph::PassContext& pc) {
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
  for (uint32_t step = 0; step < label_count_; ++step) {
    graph.add_pass({"placement.label",
                    graph::PassKind::compute,
                    {{r.tables, Use::storage_read, PLACEMENT_BINDING_TABLES},
                     {r.labels, Use::storage_read, PLACEMENT_BINDING_LABELS},
                     {order, Use::storage_read, PLACEMENT_BINDING_ORDER},
                     {results, Use::storage_read_write, PLACEMENT_BINDING_RESULTS},
                     {r.constraints, Use::storage_read_write, PLACEMENT_BINDING_CONSTRAINTS}},
                    [this, step](graph::PassContext& pc) {
                      if (step >= order_.size()) return;  // fewer labels enabled this frame
                      pc.bind(place_label_);
                      place_label_.push_constants(pc.cmd, params(pc.viewport, step));
                      vkCmdDispatch(pc.cmd, group_count(pc.viewport.width, PLACEMENT_GROUP),
                                    group_count(pc.viewport.height, PLACEMENT_GROUP), 1);
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

std::span<const gpu::PlacementGpu> Placement::results() const {
  return {reinterpret_cast<const gpu::PlacementGpu*>(readback_.mapped()), label_count_};
}

}  // namespace strata
