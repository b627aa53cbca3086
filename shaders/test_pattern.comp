#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/test_pattern.h"

layout(local_size_x = TEST_PATTERN_GROUP, local_size_y = TEST_PATTERN_GROUP) in;
layout(binding = TEST_PATTERN_BINDING_COLOR, rgba8) writeonly uniform image2D color;
layout(binding = TEST_PATTERN_BINDING_LUMINANCE, std430) writeonly buffer Luminance { float lum[]; };
layout(push_constant) uniform Push { TestPatternParams p; };

void main() {
  const uvec2 px = gl_GlobalInvocationID.xy;
  if (px.x >= p.width || px.y >= p.height) return;
  const vec3 c = test_pattern((vec2(px) + 0.5) / vec2(p.width, p.height));
  imageStore(color, ivec2(px), vec4(c, 1.0));
  lum[px.y * p.width + px.x] = luminance(c);
}
