#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/pick.h"

// Picking (shared/pick.h): each asked pixel's world point, from the frame's depth image.
layout(local_size_x = PICK_GROUP) in;
layout(binding = PICK_BINDING_FRAME) uniform Frame { FrameGpu frame; };
layout(binding = PICK_BINDING_DEPTH, r32f) readonly uniform image2D depth_image;
layout(binding = PICK_BINDING_PIXELS, std430) readonly buffer Pixels { vec2 pixels[]; };
layout(binding = PICK_BINDING_POINTS, std430) writeonly buffer Points { vec4 points[]; };
layout(push_constant) uniform Push { PickParams params; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= min(params.count, uint(min(pixels.length(), points.length())))) return;
  const ivec2 t = pick_texel(pixels[i], params.width, params.height);
  points[i] = pick_point(frame, t, imageLoad(depth_image, t).r, params.width, params.height);
}
