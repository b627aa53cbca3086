#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/label_drawing.h"
#include "shared/volume_shading.h"  // FrameGpu, split_depth, VR_MAX_LAYERS

// What hides each label's anchor (a layout's front_alpha and anchor_hidden): the composited alpha
// of the layers in front of the label's own at the pixel of its anchor, and how hidden the anchor
// is (anchor_hidden); 0 outside the image. Read between the ghosting and the label drawing, so it
// measures the volume's layers as the lenses leave them.
layout(local_size_x = ANCHOR_COVER_GROUP) in;
layout(binding = ANCHOR_COVER_BINDING_LAYERS, rgba16f) readonly uniform image2DArray layers;
layout(binding = ANCHOR_COVER_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = ANCHOR_COVER_BINDING_DEPTH, r32f) readonly uniform image2D depth_image;
layout(binding = ANCHOR_COVER_BINDING_FRAME) uniform Frame { FrameGpu frame; };
layout(binding = ANCHOR_COVER_BINDING_COVERS, std430) writeonly buffer Covers {
  AnchorCoverGpu covers[];
};
layout(push_constant) uniform Push { LabelDrawParams params; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= min(params.label_count, uint(min(labels.length(), covers.length())))) return;
  const LabelGpu label = labels[i];
  const vec2 a = floor(label.anchor);
  if (a.x < 0.0 || a.y < 0.0 || a.x >= float(params.width) || a.y >= float(params.height)) {
    covers[i] = AnchorCoverGpu(0.0, 0.0);
    return;
  }
  const uint layer = min(label.layer, min(params.layer_count, uint(VR_MAX_LAYERS)));
  float alpha = 0.0;
  for (uint k = 0u; k < layer; ++k) {
    alpha += (1.0 - alpha) * imageLoad(layers, ivec3(ivec2(a), k)).a;
  }
  const float layer_near = layer > 0u ? split_depth(frame.splits, layer - 1u) : frame.near_depth;
  const float depth = imageLoad(depth_image, ivec2(a)).r;
  covers[i] = AnchorCoverGpu(alpha, anchor_hidden(alpha, depth, label.anchor_depth, layer_near,
                                                  frame.depth_alpha, frame.step));
}
