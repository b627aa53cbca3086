#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/ghost.h"
#include "shared/saliency.h"

// Saliency (eq. 3.5), every layer's integral costs (eq. 3.3/3.4) of a pixel and whether the layers
// in front of each layer hide it (composited alpha at least HIDING_ALPHA, after the ghosting
// lenses of the rear labels open them: ghost_placement_opening), in one pass: the workgroup
// converts its tile and a one-pixel border of the label-free final image to CIELAB once (each
// conversion is six powers), the Sobel filter reads them from shared memory.
layout(local_size_x = PLACEMENT_GROUP, local_size_y = PLACEMENT_GROUP) in;
layout(binding = PLACEMENT_BINDING_FINAL, rgba8) readonly uniform image2D final_image;
layout(binding = PLACEMENT_BINDING_SALIENCY, std430) writeonly buffer Saliency { float saliency[]; };
layout(binding = PLACEMENT_BINDING_LAYERS, rgba16f) readonly uniform image2DArray layers;
layout(binding = PLACEMENT_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = PLACEMENT_BINDING_COSTS, std430) writeonly buffer Costs { float costs[]; };
layout(push_constant) uniform Push { IntegralCostsParams params; };

const uint SPAN = PLACEMENT_GROUP + 2u;  // the tile and its border
shared vec3 lab[SPAN * SPAN];
shared uint tile_lenses[LABEL_MAX / 32u];  // bit i: label i's lens reaches the tile

// (clamp to edge, as the reference)
vec3 lab_of(ivec2 p) {
  p = clamp(p, ivec2(0), ivec2(params.width, params.height) - 1);
  return rgb_to_lab(imageLoad(final_image, p).rgb);
}

vec3 lab_at(ivec2 local) { return lab[uint(local.y) * SPAN + uint(local.x)]; }

void main() {
  const uint lane = gl_LocalInvocationIndex;
  const uint lanes = PLACEMENT_GROUP * PLACEMENT_GROUP;
  const bool ghost = params.ghost_strength > 0.0f && params.ghost_radius > 0.0f;
  const uint count = ghost ? min(min(params.label_count, LABEL_MAX), uint(labels.length())) : 0u;
  const uint words = (count + 31u) / 32u;
  for (uint w = lane; w < words; w += lanes) tile_lenses[w] = 0u;
  const ivec2 origin = ivec2(gl_WorkGroupID.xy * PLACEMENT_GROUP) - 1;
  for (uint i = lane; i < SPAN * SPAN; i += lanes) {
    lab[i] = lab_of(origin + ivec2(i % SPAN, i / SPAN));
  }
  barrier();
  const vec2 tile_lo = vec2(gl_WorkGroupID.xy * PLACEMENT_GROUP) + 0.5;
  const vec2 tile_hi = tile_lo + float(PLACEMENT_GROUP - 1u);
  for (uint i = lane; i < count; i += lanes) {
    const LabelGpu label = labels[i];
    if (label.layer > 0u && label.layer < params.layer_count &&
        ghost_placement_opening(label, label.anchor, params.ghost_radius) > 0.0f &&
        !ghost_anchor_far_from_tile(tile_lo, tile_hi, label.anchor, params.ghost_radius)) {
      atomicOr(tile_lenses[i / 32u], 1u << (i % 32u));
    }
  }
  barrier();
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(params.width) || p.y >= int(params.height)) return;
  const ivec2 c = ivec2(gl_LocalInvocationID.xy) + 1;
  const uint pixel = uint(p.y) * params.width + uint(p.x);
  const float s =
      sobel_saliency(lab_at(c + ivec2(-1, -1)), lab_at(c + ivec2(0, -1)), lab_at(c + ivec2(1, -1)),
                     lab_at(c + ivec2(-1, 0)), lab_at(c + ivec2(1, 0)), lab_at(c + ivec2(-1, 1)),
                     lab_at(c + ivec2(0, 1)), lab_at(c + ivec2(1, 1)));
  saliency[pixel] = s;
  // Occlusion of a layer is its alpha (thesis 3.2.2).
  float occlusion[VR_MAX_LAYERS_FOR_PLACEMENT];
  float open_on[VR_MAX_LAYERS_FOR_PLACEMENT];  // the largest lens opening of each layer's labels
  float all = 0.0;
  for (uint l = 0u; l < params.layer_count; ++l) {
    occlusion[l] = imageLoad(layers, ivec3(p, l)).a;
    open_on[l] = 0.0;
    all += occlusion[l];
  }
  for (uint w = 0u; w < words; ++w) {
    uint bits = tile_lenses[w];
    while (bits != 0u) {
      const uint i = w * 32u + uint(findLSB(bits));
      bits &= bits - 1u;
      const LabelGpu label = labels[i];
      open_on[label.layer] = max(open_on[label.layer],
                                 ghost_placement_opening(label, vec2(p) + 0.5, params.ghost_radius));
    }
  }
  // What each layer keeps of its alpha after the lenses behind it (back to front, as labels.ghost)
  float kept[VR_MAX_LAYERS_FOR_PLACEMENT];
  float behind = 0.0;
  float behind_alpha = 0.0;
  for (int k = int(params.layer_count) - 1; k >= 0; --k) {
    kept[k] = occlusion[k] * ghost_keep(behind, params.ghost_strength);
    behind_alpha = ghost_behind_alpha(occlusion[k], behind_alpha);
    if (k > 0) behind = max(behind, open_on[k] * ghost_behind_weight(behind_alpha));
  }
  float in_front = 0.0;
  float composite = 0.0;  // of the layers in front of layer l, as the lenses leave them
  const uint layer_size = params.width * params.height;
  for (uint l = 0u; l < params.layer_count; ++l) {
    costs[(params.layer_count + l) * layer_size + pixel] = composite >= HIDING_ALPHA ? 1.0 : 0.0;
    composite += (1.0 - composite) * kept[l];
    in_front += occlusion[l];
    costs[l * layer_size + pixel] =
        integral_cost(in_front, all - in_front, all, s, params.layer_count, params.saliency_weight,
                      params.occlusion_weight, params.single_saliency_weight);
  }
}
