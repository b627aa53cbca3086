#include "passes/debug_view.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "engine/core/error.h"
#include "shared/debug_view_access.h"

namespace strata {

using graph::ResourceId;
using graph::Use;

namespace gpu {
namespace {

// The view's pixel on the CPU: the shared code is included inside this struct, so its functions
// see the buffer accessors below as members.
struct DebugViewReference {
  const DebugViewData& data;
  DebugViewParams view;

  size_t pixels() const { return size_t{view.width} * view.height; }
  float saliency_at(uint pixel) const { return data.saliency[pixel]; }
  float cost_at(uint layer, uint pixel) const { return data.costs[layer * pixels() + pixel]; }
  vec4 layer_at(uvec2 p, uint layer) const {
    return data.layers[layer * pixels() + size_t{p.y} * view.width + p.x];
  }
  LabelGpu label_at(uint i) const { return data.labels[i]; }
  PlacementGpu placement_at(uint i) const { return data.placements[i]; }
  uint order_at(uint k) const { return data.order[k]; }
  uvec2 key_at(uint slot) const {
    const uint64_t key = data.keys[slot];
    return uvec2(uint(key & 0xFFFFFFFFu), uint(key >> 32));
  }
  uint table_size() const { return uint(data.keys.size()); }

#define DEBUG_VIEW_PIXEL
#include "shared/debug_view.h"
#undef DEBUG_VIEW_PIXEL
};
static_assert(DebugViewAccess<DebugViewReference>);

}  // namespace
}  // namespace gpu

float default_scale(DebugBuffer buffer) {
  switch (buffer) {
    case DebugBuffer::costs:
      return 0.5f;
    case DebugBuffer::fragments:
      return 1.0f / 8.0f;
    default:
      return 1.0f;
  }
}

gpu::DebugViewParams debug_view_params(const DebugViewChoice& choice, graph::Extent size,
                                       uint32_t layer_count, uint32_t label_count,
                                       uint32_t order_count, float margin) {
  return {size.width,
          size.height,
          static_cast<uint32_t>(choice.buffer),
          choice.layer,
          choice.label,
          std::max(layer_count, 1u),
          label_count,
          std::min(order_count, label_count),
          choice.scale,
          margin};
}

DebugView::DebugView(Context& ctx) : pipeline_(ctx, "debug_view.comp") {}

ResourceId DebugView::add_to(graph::Graph& graph, const Inputs& in) {
  layer_count_ = in.layer_count;
  label_count_ = in.label_count;
  const ResourceId image = graph.add_image("debug.view", {VK_FORMAT_R8G8B8A8_UNORM});
  graph.add_pass({"debug.view",
                  graph::PassKind::compute,
                  {{image, Use::storage_write, DEBUG_VIEW_BINDING_OUTPUT},
                   {in.saliency, Use::storage_read, DEBUG_VIEW_BINDING_SALIENCY},
                   {in.costs, Use::storage_read, DEBUG_VIEW_BINDING_COSTS},
                   {in.labels, Use::storage_read, DEBUG_VIEW_BINDING_LABELS},
                   {in.placements, Use::storage_read, DEBUG_VIEW_BINDING_PLACEMENTS},
                   {in.order, Use::storage_read, DEBUG_VIEW_BINDING_ORDER},
                   {in.layers, Use::storage_read, DEBUG_VIEW_BINDING_LAYERS},
                   {in.frame, Use::uniform, DEBUG_VIEW_BINDING_FRAME},
                   {in.keys, Use::storage_read, DEBUG_VIEW_BINDING_KEYS}},
                  [this](graph::PassContext& pc) {
                    if (!enabled_) return;
                    const gpu::DebugViewParams p = debug_view_params(
                        choice_, pc.viewport, layer_count_, label_count_, order_count_, margin_);
                    pc.dispatch(pipeline_, p, {pc.viewport.width, pc.viewport.height, 1});
                  },
                  "debug"});
  return image;
}

namespace {

// The reference for one view, after checking that the spans it reads are large enough.
gpu::DebugViewReference reference_for(const DebugViewData& data, const DebugViewChoice& choice) {
  const size_t pixels = size_t{data.size.width} * data.size.height;
  const auto check = [](size_t have, size_t want, const char* what) {
    if (have < want) {
      throw Error("debug view: " + std::to_string(have) + " " + what + ", " + std::to_string(want) +
                  " expected");
    }
  };
  const size_t layers = pixels * std::max(data.layer_count, 1u);
  switch (choice.buffer) {
    case DebugBuffer::saliency:
      check(data.saliency.size(), pixels, "saliency values");
      break;
    case DebugBuffer::costs:
      check(data.costs.size(), layers, "costs");
      break;
    case DebugBuffer::layer:
      check(data.layers.size(), layers, "layer pixels");
      break;
    case DebugBuffer::constraints:
      check(data.placements.size(), data.labels.size(), "placements");
      for (const uint32_t label : data.order)
        check(data.labels.size(), label + size_t{1}, "labels");
      break;
    case DebugBuffer::fragments:
      break;
  }
  const auto label_count = static_cast<uint32_t>(data.labels.size());
  gpu::DebugViewReference reference{
      data, debug_view_params(choice, data.size, data.layer_count, label_count,
                              static_cast<uint32_t>(data.order.size()), data.margin)};
  reference.view_setup();
  return reference;
}

}  // namespace

std::vector<uint8_t> debug_view_reference(const DebugViewData& data,
                                          const DebugViewChoice& choice) {
  gpu::DebugViewReference reference = reference_for(data, choice);
  std::vector<uint8_t> out;
  out.reserve(size_t{4} * data.size.width * data.size.height);
  for (uint32_t y = 0; y < data.size.height; ++y) {
    for (uint32_t x = 0; x < data.size.width; ++x) {
      const glm::vec4 c = reference.debug_view_pixel(glm::uvec2(x, y));
      for (int ch = 0; ch < 4; ++ch) {
        out.push_back(static_cast<uint8_t>(std::lround(glm::clamp(c[ch], 0.0f, 1.0f) * 255.0f)));
      }
    }
  }
  return out;
}

std::vector<uint32_t> constraint_image_reference(const DebugViewData& data, uint32_t label) {
  gpu::DebugViewReference reference =
      reference_for(data, {.buffer = DebugBuffer::constraints, .label = label});
  std::vector<uint32_t> out;
  out.reserve(size_t{data.size.width} * data.size.height);
  for (uint32_t y = 0; y < data.size.height; ++y) {
    for (uint32_t x = 0; x < data.size.width; ++x) {
      out.push_back(reference.view_constraint_bits(glm::uvec2(x, y)));
    }
  }
  return out;
}

std::vector<uint32_t> habuffer_fragment_counts(const DebugViewData& data) {
  gpu::DebugViewReference reference = reference_for(data, {.buffer = DebugBuffer::fragments});
  std::vector<uint32_t> out;
  out.reserve(size_t{data.size.width} * data.size.height);
  for (uint32_t pixel = 0; pixel < data.size.width * data.size.height; ++pixel) {
    out.push_back(reference.habuffer_fragments(pixel));
  }
  return out;
}

}  // namespace strata
