// What label_draw_pixel.h reads from its includer, stated once: a concept in C++, declarations in
// GLSL (placement_free_cost_access.h says why).
#ifndef STRATA_SHARED_LABEL_DRAW_PIXEL_ACCESS_H
#define STRATA_SHARED_LABEL_DRAW_PIXEL_ACCESS_H

#include "label_drawing.h"

#ifdef __cplusplus
#include <concepts>

STRATA_BEGIN
template <typename T>
concept LabelDrawPixelAccess = requires(const T& t, uint i, vec2 uv) {
  { t.label_count() } -> std::same_as<uint>;  // labels to consider
  { t.label_at(i) } -> std::same_as<LabelGpu>;
  { t.placement_at(i) } -> std::same_as<PlacementGpu>;
  { t.glyph_at(i) } -> std::same_as<GlyphGpu>;
  // the font atlas, bilinear, clamped to its edge
  { t.atlas_coverage(uv) } -> std::same_as<float>;
  // the image atlas (premultiplied), bilinear, clamped likewise
  { t.image_texel(uv) } -> std::same_as<vec4>;
  { t.layer_frames() } -> std::same_as<bool>;  // borders in their layer's colour
  { t.connector_halos() } -> std::same_as<bool>;  // solid connectors with a dark halo
  // how hidden label i's anchor is (AnchorCoverGpu::hidden)
  { t.anchor_hidden_at(i) } -> std::same_as<float>;
};
STRATA_END
#else
uint label_count();
LabelGpu label_at(uint i);
PlacementGpu placement_at(uint i);
GlyphGpu glyph_at(uint i);
float atlas_coverage(vec2 uv);
vec4 image_texel(vec2 uv);
bool layer_frames();
bool connector_halos();
float anchor_hidden_at(uint i);
#endif

#endif
