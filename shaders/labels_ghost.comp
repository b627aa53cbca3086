#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/ghost.h"

// Ghosting (shared/ghost.h): each layer in front of a shown rear label made more transparent
// around the label's anchor (and connector), in place, before the labels are drawn.
layout(local_size_x = GHOST_GROUP, local_size_y = GHOST_GROUP) in;
layout(binding = GHOST_BINDING_LAYERS, rgba16f) uniform image2DArray layers;
layout(binding = GHOST_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = GHOST_BINDING_PLACEMENTS, std430) readonly buffer Placements {
  PlacementGpu placements[];
};
layout(push_constant) uniform Push { GhostParams params; };

// The rear labels whose lenses reach this workgroup's tile (bit i: label i).
shared uint tile_labels[LABEL_MAX / 32u];

void main() {
  const uint lane = gl_LocalInvocationIndex;
  const uint lanes = GHOST_GROUP * GHOST_GROUP;
  const uint count = min(min(params.label_count, LABEL_MAX),
                         uint(min(labels.length(), placements.length())));
  const uint words = (count + 31u) / 32u;
  const uint layer_count = min(params.layer_count, uint(VR_MAX_LAYERS));
  for (uint w = lane; w < words; w += lanes) tile_labels[w] = 0u;
  barrier();
  const vec2 tile_lo = vec2(gl_WorkGroupID.xy * GHOST_GROUP) + 0.5f;
  const vec2 tile_hi = tile_lo + float(GHOST_GROUP - 1u);
  for (uint i = lane; i < count; i += lanes) {
    const LabelGpu label = labels[i];
    if ((label.flags & LABEL_ENABLED) == 0u || (label.flags & LABEL_INTERNAL) != 0u ||
        label.layer == 0u || label.layer >= layer_count) {
      continue;
    }
    const PlacementGpu drawn = placements[i];
    if (drawn.shown != PLACEMENT_SHOWN || drawn.opacity <= 0.0f) continue;
    if (!ghost_far_from_tile(tile_lo, tile_hi, label, drawn, params)) {
      atomicOr(tile_labels[i / 32u], 1u << (i % 32u));
    }
  }
  barrier();

  const uvec2 px = gl_GlobalInvocationID.xy;
  if (px.x >= params.width || px.y >= params.height) return;
  const vec2 p = vec2(px) + 0.5;
  GhostOpenings open = ghost_no_openings();
  bool any = false;
  for (uint w = 0u; w < words; ++w) {
    uint bits = tile_labels[w];
    while (bits != 0u) {
      const uint i = w * 32u + uint(findLSB(bits));
      bits &= bits - 1u;
      const LabelGpu label = labels[i];
      const vec2 opening = ghost_opening(label, placements[i], p, params);
      open = ghost_with(open, label.layer, opening);
      any = any || max(opening.x, opening.y) > 0.0f;
    }
  }
  if (!any) return;
  vec4 colour[VR_MAX_LAYERS];
  float alpha[VR_MAX_LAYERS];
  for (uint k = 0u; k < VR_MAX_LAYERS; ++k) {
    colour[k] = k < layer_count ? imageLoad(layers, ivec3(px, k)) : vec4(0.0);
    alpha[k] = colour[k].a;
  }
  const GhostKeeps keeps = ghost_keeps(open, alpha, layer_count, params.strength);
  for (uint k = 0u; k < layer_count; ++k) {
    if (keeps.layer[k] < 1.0 && colour[k] != vec4(0.0)) {  // (an empty layer stays empty)
      imageStore(layers, ivec3(px, k), colour[k] * keeps.layer[k]);
    }
  }
}
