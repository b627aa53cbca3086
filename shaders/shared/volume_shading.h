// Shading and compositing, written once in the common subset of GLSL and GLM: the GPU passes and
// the CPU reference renderer (passes/volume_render_reference.cpp) run the same arithmetic.
#ifndef STRATA_SHARED_VOLUME_SHADING_H
#define STRATA_SHARED_VOLUME_SHADING_H

#include "volume_render.h"

#ifdef __cplusplus
#include <glm/gtc/packing.hpp>
#endif

STRATA_BEGIN

// Two-sided Blinn-Phong with a headlight (light and eye in the same direction, so the half vector
// is the light): straight RGBA in, premultiplied RGBA out.
// `unit_normal` has length 1; the specular power 32 is five squarings (no pow on the GPU's
// special-function units, which bound the resolve's shading).
STRATA_INLINE vec4 shade_unit_normal(vec4 color, vec3 unit_normal, vec3 to_eye) {
  float diffuse = abs(dot(unit_normal, to_eye));
  float specular = diffuse * diffuse;
  specular *= specular;
  specular *= specular;
  specular *= specular;
  specular *= specular;
  vec3 rgb = vec3(color) * (0.3f + 0.7f * diffuse) + vec3(0.2f * specular);
  rgb = min(rgb, vec3(1.0f));
  return vec4(rgb * color.a, color.a);
}

STRATA_INLINE vec4 shade_blinn_phong(vec4 color, vec3 normal, vec3 to_eye) {
  return shade_unit_normal(color, normalize(normal), to_eye);
}

// Eq. 3.9, front to back: `back` (premultiplied) seen through what `front` has accumulated.
STRATA_INLINE vec4 over(vec4 front, vec4 back) {
  return front + (1.0f - front.a) * back;
}

// Transfer-function alpha is defined per `reference` distance; a step of `step` absorbs more or
// less (the usual opacity correction). Applied to the transfer table's entries once per frame
// (corrected_transfer in passes/volume_renderer.h), not per sample.
STRATA_INLINE float corrected_alpha(float alpha, float step, float reference) {
  return 1.0f - pow(max(1.0f - alpha, 0.0f), step / reference);
}

STRATA_INLINE float split_depth(vec4 splits[2], uint i) {
  return splits[i / 4u][int(i % 4u)];
}

// Mesh colour as the HA-Buffer stores it: shaded, premultiplied, rgba8.
STRATA_INLINE uint mesh_payload_color(vec4 color, vec3 normal, vec3 to_eye) {
  return packUnorm4x8(shade_blinn_phong(color, normal, to_eye));
}
STRATA_END

#endif
