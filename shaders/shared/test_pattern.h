// The demo's test image: a shaded sphere over a checker floor and a sky gradient. The function is
// written once in the common subset of GLSL and GLM, so the GPU shader and the CPU reference that
// tests it run the very same arithmetic.
#ifndef STRATA_SHARED_TEST_PATTERN_H
#define STRATA_SHARED_TEST_PATTERN_H

#include "common.h"

#define TEST_PATTERN_GROUP 16
#define TEST_PATTERN_BINDING_COLOR 0      // rgba8 storage image
#define TEST_PATTERN_BINDING_LUMINANCE 1  // float per pixel, for the summed-area table
#define TEST_PATTERN_BINDING_TABLE 2      // summed-area table of the luminance
#define TEST_PATTERN_BINDING_OUTPUT 3     // rgba8 storage image

STRATA_BEGIN
struct TestPatternParams {
  uint width;
  uint height;
  uint blur_radius;  // box-filter half size, in pixels, for the right half of the image
  uint pad;
};

// uv in [0, 1]^2, y down. Returns linear RGB in [0, 1]. Every edge is a narrow smooth ramp, not
// a step: CPU and GPU round divisions differently, and a step at a pixel centre would flip.
STRATA_INLINE vec3 test_pattern(vec2 uv) {
  vec3 sky = mix(vec3(0.55f, 0.70f, 0.95f), vec3(0.10f, 0.20f, 0.45f), uv.y);
  float checker = clamp(0.5f + 6.0f * sin(uv.x * 37.699f) * sin(uv.y * 75.398f), 0.0f, 1.0f);
  vec3 floor_color = mix(vec3(0.25f, 0.22f, 0.20f), vec3(0.85f, 0.82f, 0.78f), checker);
  vec3 color = mix(sky, floor_color, smoothstep(0.64f, 0.66f, uv.y));
  vec2 d = (uv - vec2(0.5f, 0.45f)) / 0.3f;
  float r2 = dot(d, d);
  if (r2 < 1.0f) {
    vec3 n = vec3(d.x, -d.y, sqrt(1.0f - r2));
    vec3 light = normalize(vec3(-0.5f, 0.7f, 0.6f));
    vec3 half_vector = normalize(light + vec3(0.0f, 0.0f, 1.0f));
    float diffuse = max(dot(n, light), 0.0f);
    float specular = pow(max(dot(n, half_vector), 0.0f), 40.0f);
    vec3 sphere = vec3(0.80f, 0.25f, 0.20f) * (0.15f + 0.85f * diffuse) + vec3(specular);
    color = mix(color, sphere, smoothstep(1.0f, 0.96f, r2));
  }
  return clamp(color, vec3(0.0f), vec3(1.0f));
}

STRATA_INLINE float luminance(vec3 c) {
  return dot(c, vec3(0.2126f, 0.7152f, 0.0722f));
}
STRATA_END

#endif
