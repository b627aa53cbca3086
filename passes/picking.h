// Picking on the rendered frame (shaders/shared/pick.h): the world point under a pixel where the
// picture as drawn first became opaque enough, or nothing where the ray met only background: the
// resolve's depth, or in a ghosting lens (the labels' lenses, shared/ghost.h) the pixel's ray
// walked again as the resolve walks it (the same transfer functions, meshes and empty-space
// skipping) with each layer kept as far as ghosting keeps it there: a pick through a lens finds
// what the lens lets through.
#pragma once

#include <span>
#include <vector>

#include "engine/gpu/shader_library.h"
#include "engine/graph/render_graph.h"
#include "passes/label_drawing.h"
#include "passes/volume_render_reference.h"
#include "passes/volume_renderer.h"
#include "shared/pick.h"

namespace strata {

// A picked point: world space (LPS, millimetres); hit false where the ray met nothing.
struct PickHit {
  bool hit = false;
  glm::vec3 point{0.0f};
};

class Picking {
 public:
  // (with `pipeline_from`: that one's pipeline, moved out)
  explicit Picking(Context& ctx, Picking* pipeline_from = nullptr);

  struct Inputs {
    // The renderer's frame, HA-Buffer and scene resources, its depth and its layers (read before
    // labels.ghost changes them).
    VolumeRenderer::Outputs rendered;
    // labels.ghost's inputs: LabelGpu[] and the drawn PlacementGpu[] (0: no labels, no ghosting).
    graph::ResourceId labels = 0;
    graph::ResourceId placements = 0;
    // (the labels read at most: no further than either buffer's end, as labels.ghost)
    uint32_t label_count = LABEL_MAX;
  };
  // Adds picking.upload and picking.points (in the group "picking"); returns the points buffer,
  // a vec4 per pixel asked (read it with hits()).
  graph::ResourceId add_to(graph::Graph& graph, const Inputs& in);
  // The pixels the next frames pick (the viewport's pixel units, centres at +0.5); at most
  // PICK_MAX (Error past it).
  void set_pixels(std::vector<glm::vec2> pixels);
  const std::vector<glm::vec2>& pixels() const { return pixels_; }
  // Ghosting's settings as labels.ghost draws with them (LabelDrawing::set_ghost), read when the
  // graph is recorded; strength 0 (the default) or no labels: the picture without lenses.
  void set_ghost(const GhostSettings& ghost) { ghost_ = ghost; }
  // The hits in the points buffer's bytes, one per pixel set.
  std::vector<PickHit> hits(std::span<const std::byte> points) const;

 private:
  ComputePipeline pipeline_;
  std::vector<glm::vec2> pixels_;
  GhostSettings ghost_;
  bool labels_ = false;  // the graph gives labels (else picking.upload clears stand-ins)
};

// The first `count` hits in a points buffer's bytes (Picking::add_to's, or a copy of it).
std::vector<PickHit> pick_hits(std::span<const std::byte> points, size_t count);

// The labels a pick looks through, as labels.ghost draws them: the labels, their drawn
// placements and ghosting's settings (in pixels). Empty: no ghosting.
struct PickLabels {
  std::span<const gpu::LabelGpu> labels;
  std::span<const gpu::PlacementGpu> placements;
  GhostSettings ghost;
};

// The scene rendered at `size` from `camera` (VolumeRenderer with `settings`, the HA-Buffer grown
// until nothing overflows) with `pixels` picked in the same frame, `runs` times (for timing),
// through the lenses of `labels` where given: the hits, and per run the picking passes' GPU time.
struct ScenePick {
  std::vector<PickHit> hits;
  std::vector<double> gpu_ms;
};
ScenePick pick_scene(Context& ctx, const Scene& scene, const Camera& camera,
                     const RenderSettings& settings, graph::Extent size,
                     std::vector<glm::vec2> pixels, uint32_t runs = 1,
                     const PickLabels& labels = {});

// Picking on the CPU: the same walks with the reference renderer's (walk_reference_pixel), for
// the frame's data `frame` (frame_data; cast at `size` or smaller), the pixels in units of `size`.
std::vector<PickHit> pick_reference(const RenderInputs& inputs, const gpu::FrameGpu& frame,
                                    graph::Extent size, std::span<const glm::vec2> pixels,
                                    const PickLabels& labels = {});

}  // namespace strata
