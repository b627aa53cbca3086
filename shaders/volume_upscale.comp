#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/upscale.h"

// The full images from the pixels cast at a lower resolution (shared/upscale.h).
layout(local_size_x = UPSCALE_GROUP, local_size_y = UPSCALE_GROUP) in;
layout(binding = UPSCALE_BINDING_LOW_LAYERS, rgba16f) readonly uniform image2DArray low_layers;
layout(binding = UPSCALE_BINDING_LOW_FINAL, rgba8) readonly uniform image2D low_final;
layout(binding = UPSCALE_BINDING_LOW_DEPTH, r32f) readonly uniform image2D low_depth;
layout(binding = UPSCALE_BINDING_LAYERS, rgba16f) writeonly uniform image2DArray layers;
layout(binding = UPSCALE_BINDING_FINAL, rgba8) writeonly uniform image2D final_image;
layout(binding = UPSCALE_BINDING_DEPTH, r32f) writeonly uniform image2D depth_image;
layout(push_constant) uniform Push { UpscaleParams params; };

vec4 bilinear_layer(UpscaleTap tap, int layer) {
  vec4 a = imageLoad(low_layers, ivec3(tap.p0.x, tap.p0.y, layer));
  vec4 b = imageLoad(low_layers, ivec3(tap.p1.x, tap.p0.y, layer));
  vec4 c = imageLoad(low_layers, ivec3(tap.p0.x, tap.p1.y, layer));
  vec4 d = imageLoad(low_layers, ivec3(tap.p1.x, tap.p1.y, layer));
  return mix(mix(a, b, tap.t.x), mix(c, d, tap.t.x), tap.t.y);
}

void main() {
  const uvec2 pixel = gl_GlobalInvocationID.xy;
  if (any(greaterThanEqual(pixel, params.size))) return;
  const UpscaleTap tap = upscale_tap(pixel, params);
  for (uint l = 0u; l < params.layer_count; ++l) {
    imageStore(layers, ivec3(pixel, l), bilinear_layer(tap, int(l)));
  }
  vec4 a = imageLoad(low_final, tap.p0), b = imageLoad(low_final, ivec2(tap.p1.x, tap.p0.y));
  vec4 c = imageLoad(low_final, ivec2(tap.p0.x, tap.p1.y)), d = imageLoad(low_final, tap.p1);
  imageStore(final_image, ivec2(pixel), mix(mix(a, b, tap.t.x), mix(c, d, tap.t.x), tap.t.y));
  imageStore(depth_image, ivec2(pixel), imageLoad(low_depth, upscale_nearest(pixel, params)));
}
