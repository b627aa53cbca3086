// What resolve_walk.h reads from its includer, stated once: a concept in C++, declarations in
// GLSL (placement_free_cost_access.h says why). Besides these, the pixel's mesh fragments sorted
// front to back (their eye depths and payloads) are resolve_pixel's arguments.
#ifndef STRATA_SHARED_RESOLVE_WALK_ACCESS_H
#define STRATA_SHARED_RESOLVE_WALK_ACCESS_H

#include "volume_render.h"

#ifdef __cplusplus
#include <concepts>

STRATA_BEGIN
template <typename T>
concept ResolveWalkAccess = requires(const T& t, uint v, vec3 tc, int i, uint l, vec4 colour) {
  // the frame (GLSL: a uniform block member; not declared here)
  { t.frame } -> std::same_as<const FrameGpu&>;
  { t.volume_info(v) } -> std::same_as<VolumeGpu>;
  // trilinear at tc in [0,1]^3: xyz the gradient (per voxel), w the normalised intensity
  { t.volume_sample(v, tc) } -> std::same_as<vec4>;
  // transfer table entry i of volume v, its alpha corrected for the frame's step
  // (corrected_transfer)
  { t.table_entry(v, i) } -> std::same_as<vec4>;
  // the transfer function is transparent in tc's brick
  { t.brick_empty(v, tc) } -> std::same_as<bool>;
  // volume v's cut-aways remove tc (VolumeGpu::cut)
  { t.volume_cut(v, tc) } -> std::same_as<bool>;
  // the pixel's layer l (premultiplied), called for every layer in order, once
  { t.emit_layer(l, colour) } -> std::same_as<void>;
};

// With VR_RESOLVE_LAYER_KEEP (resolve_walk.h says what the walk then does with them).
template <typename T>
concept ResolveWalkLayerKeepAccess = ResolveWalkAccess<T> && requires(const T& t, uint l) {
  // the share of layer l's colour and alpha the picture keeps (ghosting: ghost.h; 1 without)
  { t.layer_keep(l) } -> std::same_as<float>;
  // the first layer the walk samples (below layer_count): those in front are not walked nor
  // emitted
  { t.walk_start_layer() } -> std::same_as<uint>;
  // what the drawn layers in front of it let through
  { t.walk_start_clear() } -> std::same_as<float>;
  // the walk ends at the depth (a pick needs no more; the layers from there on are then not
  // whole)
  { t.walk_stops_at_depth() } -> std::same_as<bool>;
};
STRATA_END
#else
VolumeGpu volume_info(uint v);
vec4 volume_sample(uint v, vec3 tc);
vec4 table_entry(uint v, int i);
bool brick_empty(uint v, vec3 tc);
bool volume_cut(uint v, vec3 tc);
void emit_layer(uint l, vec4 colour);
#ifdef VR_RESOLVE_LAYER_KEEP
float layer_keep(uint l);
uint walk_start_layer();
float walk_start_clear();
bool walk_stops_at_depth();
#endif
#endif

#endif
