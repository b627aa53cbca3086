#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/saliency.h"

layout(local_size_x = PLACEMENT_GROUP, local_size_y = PLACEMENT_GROUP) in;
layout(binding = PLACEMENT_BINDING_FINAL, rgba8) readonly uniform image2D final_image;
layout(binding = PLACEMENT_BINDING_SALIENCY, std430) writeonly buffer Saliency { float saliency[]; };
layout(push_constant) uniform Push { PlacementParams params; };

vec3 lab_at(ivec2 p) {
  p = clamp(p, ivec2(0), ivec2(params.width, params.height) - 1);
  return rgb_to_lab(imageLoad(final_image, p).rgb);
}

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(params.width) || p.y >= int(params.height)) return;
  saliency[p.y * params.width + p.x] =
      sobel_saliency(lab_at(p + ivec2(-1, -1)), lab_at(p + ivec2(0, -1)), lab_at(p + ivec2(1, -1)),
                     lab_at(p + ivec2(-1, 0)), lab_at(p + ivec2(1, 0)), lab_at(p + ivec2(-1, 1)),
                     lab_at(p + ivec2(0, 1)), lab_at(p + ivec2(1, 1)));
}
