// The viewer's debug views (the thesis program's --show-buffers): one compute pass that shows one
// of the frame's internal buffers as a viewport-sized rgba8 image. Which one is read when the
// frame is recorded (set()) and reaches the shader as push constants, so switching needs no new
// graph; the pass therefore binds every input whatever it shows.
//   saliency     the placement's saliency (eq. 3.5) times scale, grey
//   costs        layer L's integral costs (eq. 3.3/3.4) times scale, black-body ramp
//   constraints  label i's constraint image (thesis 4.1.1), recomputed from the labels placed
//                before it in the order (see shaders/shared/debug_view.h)
//   layer        depth layer L (premultiplied) over a grey checkerboard
//   fragments    the HA-Buffer's mesh fragments per pixel times scale, black-body ramp
// The per-pixel code is shared with the CPU reference below.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "engine/gpu/shader_library.h"
#include "engine/graph/graph_runner.h"
#include "engine/graph/render_graph.h"
#include "shared/debug_view.h"

namespace strata {

enum class DebugBuffer : uint32_t {
  saliency = DEBUG_MODE_SALIENCY,
  costs = DEBUG_MODE_COSTS,
  constraints = DEBUG_MODE_CONSTRAINTS,
  layer = DEBUG_MODE_LAYER,
  fragments = DEBUG_MODE_FRAGMENTS,
};

struct DebugViewChoice {
  DebugBuffer buffer = DebugBuffer::saliency;
  uint32_t layer = 0;  // costs, layer: the depth layer (the last one if past it)
  uint32_t label = 0;  // constraints: an index into the labels buffer
  // saliency, costs, fragments: the value times this, clamped to [0, 1], is what is shown
  float scale = 1.0f;
};

// A scale that shows the buffer's usual range: saliency 1, costs 1/2 (one layer's cost of an
// opaque pixel is about 1 to 2), fragments 1/8.
float default_scale(DebugBuffer buffer);

class DebugView {
 public:
  explicit DebugView(Context& ctx);

  struct Inputs {
    graph::ResourceId saliency;    // Placement::Outputs::saliency: float per pixel
    graph::ResourceId costs;       // Placement::Outputs::costs: float per layer per pixel
    graph::ResourceId labels;      // Placement::Outputs::labels: LabelGpu[]
    graph::ResourceId placements;  // Placement::Outputs::placements: PlacementGpu[]
    graph::ResourceId order;       // the placement's insertion order: uint[]
    graph::ResourceId layers;      // VolumeRenderer::Outputs::layers: rgba16f array
    graph::ResourceId frame;       // the renderer's FrameGpu uniform (its table_size)
    graph::ResourceId keys;        // the renderer's HA-Buffer keys: uint64_t per slot
    uint32_t layer_count = 1;
    uint32_t label_count = 0;  // entries of the labels and placements buffers
  };
  // Adds the pass `debug.view`; returns the viewport-sized rgba8 image it writes.
  graph::ResourceId add_to(graph::Graph& graph, const Inputs& in);

  // What to show (read when the frame is recorded).
  void set(const DebugViewChoice& choice) { choice_ = choice; }
  // Whether the pass runs at all (a viewer showing no debug view leaves its image as it was).
  void set_enabled(bool enabled) { enabled_ = enabled; }
  // This frame's placement (read when the frame is recorded): how many labels its order holds
  // and its margin (PlacementSettings::margin); the constraint image needs both.
  void set_placement(uint32_t order_count, float margin) {
    order_count_ = order_count;
    margin_ = margin;
  }

 private:
  ComputePipeline pipeline_;
  DebugViewChoice choice_;
  bool enabled_ = true;
  uint32_t layer_count_ = 1;
  uint32_t label_count_ = 0;
  uint32_t order_count_ = 0;
  float margin_ = 6.0f;
};

// What the CPU reference reads: the buffers' contents as they download.
struct DebugViewData {
  graph::Extent size;
  uint32_t layer_count = 1;
  std::span<const float> saliency;                // per pixel
  std::span<const float> costs;                   // per layer, per pixel
  std::span<const glm::vec4> layers;              // per layer, per pixel, premultiplied
  std::span<const gpu::LabelGpu> labels;          // label_count of them
  std::span<const gpu::PlacementGpu> placements;  // one per label
  std::span<const uint32_t> order;                // this frame's order (order_count entries)
  float margin = 6.0f;
  std::span<const uint64_t> keys;  // the HA-Buffer, all of its slots
};

// The push constants of a view of `size` (the pass's and the reference's).
gpu::DebugViewParams debug_view_params(const DebugViewChoice& choice, graph::Extent size,
                                       uint32_t layer_count, uint32_t label_count,
                                       uint32_t order_count, float margin);

// The pass on the CPU: rgba8, rows top to bottom.
std::vector<uint8_t> debug_view_reference(const DebugViewData& data, const DebugViewChoice& choice);

// Label `label`'s constraint bits per candidate pixel (DEBUG_NOT_CANDIDATE where its box cannot
// be), as the constraints view computes them.
std::vector<uint32_t> constraint_image_reference(const DebugViewData& data, uint32_t label);

// The fragments of each pixel in the HA-Buffer `keys` (row-major), as the fragments view and the
// resolve count them.
std::vector<uint32_t> habuffer_fragment_counts(const DebugViewData& data);

}  // namespace strata
