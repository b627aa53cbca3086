#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/ghost.h"
#include "shared/volume_render.h"  // VR_MAX_LAYERS

// What hides each label's anchor (a layout's front_alpha): the composited alpha of the layers in
// front of the label's own at the pixel of its anchor, 0 outside the image. Read between the
// ghosting and the label drawing, so it measures the volume's layers as the lenses leave them.
layout(local_size_x = GHOST_FRONT_ALPHA_GROUP) in;
layout(binding = GHOST_BINDING_LAYERS, rgba16f) readonly uniform image2DArray layers;
layout(binding = GHOST_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = GHOST_BINDING_FRONT_ALPHA, std430) writeonly buffer Front { float front[]; };
layout(push_constant) uniform Push { GhostParams params; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= min(params.label_count, uint(min(labels.length(), front.length())))) return;
  const LabelGpu label = labels[i];
  const vec2 a = floor(label.anchor);
  if (a.x < 0.0 || a.y < 0.0 || a.x >= float(params.width) || a.y >= float(params.height)) {
    front[i] = 0.0;
    return;
  }
  float alpha = 0.0;
  for (uint k = 0u; k < min(label.layer, min(params.layer_count, uint(VR_MAX_LAYERS))); ++k) {
    alpha += (1.0 - alpha) * imageLoad(layers, ivec3(ivec2(a), k)).a;
  }
  front[i] = alpha;
}
