#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/label_drawing.h"
#include "shared/volume_render.h"  // VR_MAX_LAYERS

// The depth layers, labels drawn, composited front to back (layer 0 is nearest) over the
// background: the final image (straight alpha; opaque unless the background is none). Then, on
// top, the connectors and anchors' marks of rear labels where the layers in front of theirs hide
// them (label_behind): every leader can be followed to its anchor.
layout(local_size_x = LABEL_DRAW_GROUP, local_size_y = LABEL_DRAW_GROUP) in;
layout(binding = LABEL_DRAW_BINDING_LAYERS, rgba16f) readonly uniform image2DArray layers;
layout(binding = LABEL_DRAW_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = LABEL_DRAW_BINDING_PLACEMENTS, std430) readonly buffer Placements {
  PlacementGpu placements[];
};
layout(binding = LABEL_DRAW_BINDING_COVERS, std430) readonly buffer Covers {
  AnchorCoverGpu covers[];
};
layout(binding = LABEL_DRAW_BINDING_FINAL, rgba8) writeonly uniform image2D final_image;
layout(push_constant) uniform Push { LabelDrawParams params; };

// The rear labels that can reach this workgroup's tile (bit i: label i), as label_draw.comp.
shared uint tile_labels[LABEL_MAX / 32u];

void main() {
  const uint lane = gl_LocalInvocationIndex;
  const uint lanes = LABEL_DRAW_GROUP * LABEL_DRAW_GROUP;
  const uint count =
      min(min(params.label_count, LABEL_MAX),
          uint(min(min(labels.length(), placements.length()), covers.length())));
  const uint words = (count + 31u) / 32u;  // (the bit set's words in use: only those are cleared)
  for (uint w = lane; w < words; w += lanes) tile_labels[w] = 0u;
  barrier();
  const vec2 tile_lo = vec2(gl_WorkGroupID.xy * LABEL_DRAW_GROUP) + 0.5f;
  const vec2 tile_hi = tile_lo + float(LABEL_DRAW_GROUP - 1u);
  const uint layer_count = min(params.layer_count, uint(VR_MAX_LAYERS));
  for (uint i = lane; i < count; i += lanes) {
    const LabelGpu label = labels[i];
    if ((label.flags & LABEL_ENABLED) == 0u || (label.flags & LABEL_INTERNAL) != 0u ||
        label.layer == 0u || label.layer >= layer_count) {
      continue;
    }
    const PlacementGpu placement = placements[i];
    if (placement.shown != PLACEMENT_SHOWN) continue;
    if (!label_far_from_tile(tile_lo, tile_hi, label.anchor, placement.position, label.size)) {
      atomicOr(tile_labels[i / 32u], 1u << (i % 32u));
    }
  }
  barrier();

  const uvec2 px = gl_GlobalInvocationID.xy;
  if (px.x >= params.width || px.y >= params.height) return;
  vec4 accumulated = vec4(0.0);
  float front[VR_MAX_LAYERS];  // the composite's alpha in front of each layer
  for (uint l = 0u; l < layer_count; ++l) {
    front[l] = accumulated.a;
    accumulated = label_over(accumulated, imageLoad(layers, ivec3(px, l)));
  }
  vec4 result = over_background(accumulated, params.background);
  const vec2 p = vec2(px) + 0.5;
  for (uint w = 0u; w < words; ++w) {
    uint bits = tile_labels[w];
    while (bits != 0u) {
      const uint i = w * 32u + uint(findLSB(bits));
      bits &= bits - 1u;
      const vec4 behind =
          label_behind(labels[i], placements[i], p, front[labels[i].layer], covers[i].hidden);
      result = label_over_composite(behind, result);
    }
  }
  imageStore(final_image, ivec2(px), straight_alpha(result));
}
