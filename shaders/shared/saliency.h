// Saliency (thesis eq. 3.5): CIELAB of the label-free final image, a Sobel filter per channel,
// the length of the two 3-vectors of derivatives; shared by the GPU and the CPU reference.
#ifndef STRATA_SHARED_SALIENCY_H
#define STRATA_SHARED_SALIENCY_H

#include "placement.h"

STRATA_BEGIN

STRATA_INLINE float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : pow((c + 0.055f) / 1.055f, 2.4f);
}

STRATA_INLINE float lab_f(float t) {
  return t > 0.008856452f ? pow(t, 1.0f / 3.0f) : t / 0.12841855f + 0.13793103f;
}

// sRGB-encoded colour (the image as shown) to CIELAB, D65 white.
STRATA_INLINE vec3 rgb_to_lab(vec3 srgb) {
  vec3 c = vec3(srgb_to_linear(srgb.x), srgb_to_linear(srgb.y), srgb_to_linear(srgb.z));
  float x = (0.4124564f * c.x + 0.3575761f * c.y + 0.1804375f * c.z) / 0.95047f;
  float y = 0.2126729f * c.x + 0.7151522f * c.y + 0.0721750f * c.z;
  float z = (0.0193339f * c.x + 0.1191920f * c.y + 0.9503041f * c.z) / 1.08883f;
  float fx = lab_f(x), fy = lab_f(y), fz = lab_f(z);
  return vec3(116.0f * fy - 16.0f, 500.0f * (fx - fy), 200.0f * (fy - fz));
}

// Eq. 3.5 from the CIELAB values of a 3x3 neighbourhood (row-major, centre at index 4), scaled
// so that a gradient of SALIENCY_SCALE counts 1.
STRATA_INLINE float sobel_saliency(vec3 n0, vec3 n1, vec3 n2, vec3 n3, vec3 n5, vec3 n6, vec3 n7,
                                   vec3 n8) {
  vec3 gx = (n2 + 2.0f * n5 + n8) - (n0 + 2.0f * n3 + n6);
  vec3 gy = (n6 + 2.0f * n7 + n8) - (n0 + 2.0f * n1 + n2);
  return sqrt(dot(gx, gx) + dot(gy, gy)) / SALIENCY_SCALE;
}

// Eq. 3.3 (several layers) and eq. 3.4 (one layer): the integral cost of a pixel for `layer`,
// from the alpha of each layer (occlusion) and the saliency. o[] has layer_count entries.
STRATA_INLINE float integral_cost(float occlusion_in_front, float occlusion_behind,
                                  float occlusion_all, float saliency, uint layer_count,
                                  float saliency_weight, float occlusion_weight,
                                  float single_saliency_weight) {
  if (layer_count == 1u)
    return occlusion_weight * occlusion_all + single_saliency_weight * saliency;
  return occlusion_in_front +
         (saliency_weight * saliency + (1.0f - saliency_weight)) * occlusion_behind;
}
STRATA_END

#endif
