#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/forces.h"

// Eq. 3.1's previous position (eta): where the forces drew each label last frame.
layout(local_size_x = FORCES_GROUP) in;
layout(binding = FORCES_BINDING_LABELS, std430) buffer Labels { LabelGpu labels[]; };
layout(binding = FORCES_BINDING_STATE, std430) readonly buffer States { LabelStateGpu states[]; };
layout(push_constant) uniform Push { ForcesParams params; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.label_count || (states[i].flags & LABEL_STATE_PLACED) == 0u) return;
  labels[i].previous = states[i].drawn;
}
