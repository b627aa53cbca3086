// What debug_view.h's per-pixel part (DEBUG_VIEW_PIXEL) reads from its includer, stated once: a
// concept in C++, declarations in GLSL (placement_free_cost_access.h says why). After
// debug_view.h's first part, whose DebugViewParams it names.
#ifndef STRATA_SHARED_DEBUG_VIEW_ACCESS_H
#define STRATA_SHARED_DEBUG_VIEW_ACCESS_H

#ifdef __cplusplus
#include <concepts>

STRATA_BEGIN
template <typename T>
concept DebugViewAccess = requires(const T& t, uint pixel, uint layer, uvec2 p, uint i) {
  // what to show (GLSL: a push-constant member; not declared here)
  { t.view } -> std::same_as<const DebugViewParams&>;
  { t.saliency_at(pixel) } -> std::same_as<float>;
  { t.cost_at(layer, pixel) } -> std::same_as<float>;
  { t.layer_at(p, layer) } -> std::same_as<vec4>;  // premultiplied
  { t.label_at(i) } -> std::same_as<LabelGpu>;
  { t.placement_at(i) } -> std::same_as<PlacementGpu>;
  { t.order_at(i) } -> std::same_as<uint>;
  // an HA-Buffer key: x the low word, y the high
  { t.key_at(i) } -> std::same_as<uvec2>;
  { t.table_size() } -> std::same_as<uint>;  // the HA-Buffer's slots
};
STRATA_END
#else
float saliency_at(uint pixel);
float cost_at(uint layer, uint pixel);
vec4 layer_at(uvec2 p, uint layer);
LabelGpu label_at(uint i);
PlacementGpu placement_at(uint i);
uint order_at(uint k);
uvec2 key_at(uint slot);
uint table_size();
#endif

#endif
