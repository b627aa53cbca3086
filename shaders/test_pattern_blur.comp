#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/test_pattern.h"

layout(local_size_x = TEST_PATTERN_GROUP, local_size_y = TEST_PATTERN_GROUP) in;
layout(binding = TEST_PATTERN_BINDING_COLOR, rgba8) readonly uniform image2D color;
layout(binding = TEST_PATTERN_BINDING_TABLE, std430) readonly buffer Table { float table[]; };
layout(binding = TEST_PATTERN_BINDING_OUTPUT, rgba8) writeonly uniform image2D result;
layout(push_constant) uniform Push { TestPatternParams p; };

float table_at(int x, int y) {
  return (x < 0 || y < 0) ? 0.0 : table[uint(y) * p.width + uint(x)];
}

// Left half: the test pattern. Right half: its luminance box-filtered in O(1) per pixel from the
// summed-area table, tinted, so the demo image shows the table at work.
void main() {
  const ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  if (px.x >= int(p.width) || px.y >= int(p.height)) return;
  vec4 c = imageLoad(color, px);
  if (uint(px.x) >= p.width / 2) {
    const int r = int(p.blur_radius);
    const ivec2 lo = max(px - r, ivec2(0)) - 1;
    const ivec2 hi = min(px + r, ivec2(p.width, p.height) - 1);
    const float sum = table_at(hi.x, hi.y) - table_at(lo.x, hi.y) - table_at(hi.x, lo.y) +
                      table_at(lo.x, lo.y);
    const float mean = sum / float((hi.x - lo.x) * (hi.y - lo.y));
    c = vec4(mean * vec3(1.0, 0.9, 0.7), 1.0);
  }
  imageStore(result, px, c);
}
