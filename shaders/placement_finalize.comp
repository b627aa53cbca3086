#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#include "shared/placement.h"

// Unpacks every label's (cost, pixel) into its placement: box centre, cost, shown.
layout(local_size_x = 64) in;
layout(binding = PLACEMENT_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = PLACEMENT_BINDING_RESULTS, std430) readonly buffer Results { uint64_t results[]; };
layout(binding = PLACEMENT_BINDING_PLACEMENTS, std430) writeonly buffer Placements { PlacementGpu placements[]; };
layout(push_constant) uniform Push { PlacementParams params; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.label_count) return;
  const uint64_t r = results[i];
  const bool shown = r != PLACEMENT_NONE && (labels[i].flags & LABEL_ENABLED) != 0u;
  placements[i] = shown ? shown_placement(labels[i], uint(r & 0xFFFFFFFFul),
                                          uintBitsToFloat(uint(r >> 32)), params.width)
                        : hidden_placement(labels[i]);
}
