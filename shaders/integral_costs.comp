#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/saliency.h"

layout(local_size_x = PLACEMENT_GROUP, local_size_y = PLACEMENT_GROUP) in;
layout(binding = PLACEMENT_BINDING_SALIENCY, std430) readonly buffer Saliency { float saliency[]; };
layout(binding = PLACEMENT_BINDING_LAYERS, rgba16f) readonly uniform image2DArray layers;
layout(binding = PLACEMENT_BINDING_COSTS, std430) writeonly buffer Costs { float costs[]; };
layout(push_constant) uniform Push { PlacementParams params; };

// Occlusion of a layer is its alpha (thesis 3.2.2); every layer's integral costs at once.
void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(params.width) || p.y >= int(params.height)) return;
  const uint pixel = uint(p.y) * params.width + uint(p.x);
  float occlusion[VR_MAX_LAYERS_FOR_PLACEMENT];
  float all = 0.0;
  for (uint l = 0u; l < params.layer_count; ++l) {
    occlusion[l] = imageLoad(layers, ivec3(p, l)).a;
    all += occlusion[l];
  }
  float in_front = 0.0;
  for (uint l = 0u; l < params.layer_count; ++l) {
    in_front += occlusion[l];
    costs[l * params.width * params.height + pixel] =
        integral_cost(in_front, all - in_front, all, saliency[pixel], params.layer_count,
                      params.saliency_weight, params.occlusion_weight, params.single_saliency_weight);
  }
}
