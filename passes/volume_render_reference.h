// The CPU reference of the renderer: the same resolve (shaders/shared/resolve_walk.h, compiled as
// C++ here), fed by ray-triangle and ray-box intersections instead of rasterisation and by
// software trilinear sampling of the same atlas and transfer table. Small images only: tests.
#pragma once

#include <vector>

#include "passes/volume_renderer.h"

namespace strata {

struct ReferenceImage {
  graph::Extent size;
  uint32_t layer_count = 0;
  std::vector<glm::vec4> layers;  // [layer][pixel], premultiplied
  std::vector<glm::vec4> final;   // layers over the background
  std::vector<float> depth;
  uint64_t samples = 0;
  uint64_t shaded = 0;
};

ReferenceImage render_reference(const RenderInputs& inputs, const Camera& camera,
                                const RenderSettings& settings, graph::Extent size);

}  // namespace strata
