// The CPU reference of the renderer: the same resolve (shaders/shared/resolve_walk.h, compiled as
// C++ here), fed by ray-triangle and ray-box intersections instead of rasterisation and by
// software trilinear sampling of the same atlas and transfer table. Small images only: tests.
#pragma once

#include <span>
#include <vector>

#include "passes/volume_renderer.h"
#include "shared/pick.h"

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

// One pixel's walk (the frame's pixel units, centres at +0.5), keeping keep[l] of each layer l
// (ghosting: shared/ghost.h; layers past keep's end are kept whole): the layers as walked, whole,
// and the eye depth where the picture drawn with those keeps first reaches depth_alpha (0:
// nowhere). Every layer whole: the depth of render_reference. With `pick` the walk is a pick's: it
// starts at pick->layer (pick_start) and ends at the depth, so the layers are not whole.
struct ReferencePixel {
  std::vector<glm::vec4> layers;  // frame.layer_count, premultiplied
  float depth = 0.0f;
};
ReferencePixel walk_reference_pixel(const RenderInputs& inputs, const gpu::FrameGpu& frame,
                                    glm::vec2 pixel, std::span<const float> keep = {},
                                    const gpu::PickStart* pick = nullptr);

}  // namespace strata
