#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/saliency.h"

// Saliency (eq. 3.5), every layer's integral costs (eq. 3.3/3.4) of a pixel and whether the layers
// in front of each layer hide it (composited alpha at least HIDING_ALPHA), in one pass: the
// workgroup converts its tile and a one-pixel border of the label-free final image to CIELAB
// once (each conversion is six powers), the Sobel filter reads them from shared memory.
layout(local_size_x = PLACEMENT_GROUP, local_size_y = PLACEMENT_GROUP) in;
layout(binding = PLACEMENT_BINDING_FINAL, rgba8) readonly uniform image2D final_image;
layout(binding = PLACEMENT_BINDING_SALIENCY, std430) writeonly buffer Saliency { float saliency[]; };
layout(binding = PLACEMENT_BINDING_LAYERS, rgba16f) readonly uniform image2DArray layers;
layout(binding = PLACEMENT_BINDING_COSTS, std430) writeonly buffer Costs { float costs[]; };
layout(push_constant) uniform Push { PlacementParams params; };

const uint SPAN = PLACEMENT_GROUP + 2u;  // the tile and its border
shared vec3 lab[SPAN * SPAN];

// (clamp to edge, as the reference)
vec3 lab_of(ivec2 p) {
  p = clamp(p, ivec2(0), ivec2(params.width, params.height) - 1);
  return rgb_to_lab(imageLoad(final_image, p).rgb);
}

vec3 lab_at(ivec2 local) { return lab[uint(local.y) * SPAN + uint(local.x)]; }

void main() {
  const ivec2 origin = ivec2(gl_WorkGroupID.xy * PLACEMENT_GROUP) - 1;
  for (uint i = gl_LocalInvocationIndex; i < SPAN * SPAN; i += PLACEMENT_GROUP * PLACEMENT_GROUP) {
    lab[i] = lab_of(origin + ivec2(i % SPAN, i / SPAN));
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
  float all = 0.0;
  for (uint l = 0u; l < params.layer_count; ++l) {
    occlusion[l] = imageLoad(layers, ivec3(p, l)).a;
    all += occlusion[l];
  }
  float in_front = 0.0;
  float composite = 0.0;  // of the layers in front of layer l
  const uint layer_size = params.width * params.height;
  for (uint l = 0u; l < params.layer_count; ++l) {
    costs[(params.layer_count + l) * layer_size + pixel] = composite >= HIDING_ALPHA ? 1.0 : 0.0;
    composite += (1.0 - composite) * occlusion[l];
    in_front += occlusion[l];
    costs[l * layer_size + pixel] =
        integral_cost(in_front, all - in_front, all, s, params.layer_count, params.saliency_weight,
                      params.occlusion_weight, params.single_saliency_weight);
  }
}
