// Picking on the rendered frame (shaders/shared/pick.h): the world point under a pixel where the
// frame's own ray walk first made the picture opaque enough (the renderer's depth image: the
// same transfer functions, meshes and empty-space skipping as the picture), or nothing where the
// ray met only background.
#pragma once

#include <span>
#include <vector>

#include "engine/gpu/shader_library.h"
#include "engine/graph/render_graph.h"
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
    graph::ResourceId frame;  // the renderer's FrameGpu
    graph::ResourceId depth;  // its depth image (full size)
  };
  // Adds picking.upload and picking.points (in the group "picking"); returns the points buffer,
  // a vec4 per pixel asked (read it with hits()).
  graph::ResourceId add_to(graph::Graph& graph, const Inputs& in);
  // The pixels the next frames pick (pixel units, centres at +0.5); at most PICK_MAX (Error
  // past it).
  void set_pixels(std::vector<glm::vec2> pixels);
  const std::vector<glm::vec2>& pixels() const { return pixels_; }
  // The hits in the points buffer's bytes, one per pixel set.
  std::vector<PickHit> hits(std::span<const std::byte> points) const;

 private:
  ComputePipeline pipeline_;
  std::vector<glm::vec2> pixels_;
};

// The scene rendered at `size` from `camera` (VolumeRenderer with `settings`, the HA-Buffer grown
// until nothing overflows) with `pixels` picked in the same frame, `runs` times (for timing):
// the hits, and per run the picking passes' GPU time.
struct ScenePick {
  std::vector<PickHit> hits;
  std::vector<double> gpu_ms;
};
ScenePick pick_scene(Context& ctx, const Scene& scene, const Camera& camera,
                     const RenderSettings& settings, graph::Extent size,
                     std::vector<glm::vec2> pixels, uint32_t runs = 1);

// Picking on the CPU: the same points from the reference renderer's depth and the frame's data
// (frame_data for the same camera and size).
std::vector<PickHit> pick_reference(const ReferenceImage& image, const gpu::FrameGpu& frame,
                                    std::span<const glm::vec2> pixels);

}  // namespace strata
