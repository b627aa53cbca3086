#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/label_drawing.h"

// The depth layers, labels drawn, composited front to back (layer 0 is nearest) over the
// background: the final image.
layout(local_size_x = LABEL_DRAW_GROUP, local_size_y = LABEL_DRAW_GROUP) in;
layout(binding = LABEL_DRAW_BINDING_LAYERS, rgba16f) readonly uniform image2DArray layers;
layout(binding = LABEL_DRAW_BINDING_FINAL, rgba8) writeonly uniform image2D final_image;
layout(push_constant) uniform Push { LabelDrawParams params; };

void main() {
  const uvec2 px = gl_GlobalInvocationID.xy;
  if (px.x >= params.width || px.y >= params.height) return;
  vec4 accumulated = vec4(0.0);
  for (uint l = 0u; l < params.layer_count; ++l) {
    accumulated = label_over(accumulated, imageLoad(layers, ivec3(px, l)));
  }
  imageStore(final_image, ivec2(px), label_over_background(accumulated, params.background.rgb));
}
