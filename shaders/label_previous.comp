#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/forces.h"

// What each label of this frame takes from the last one (forces_previous): eq. 3.1's previous
// position, the held position and its hold, and hard mode's padding for a hidden label.
layout(local_size_x = FORCES_GROUP) in;
layout(binding = FORCES_BINDING_LABELS, std430) buffer Labels { LabelGpu labels[]; };
layout(binding = FORCES_BINDING_STATE, std430) readonly buffer States { LabelStateGpu states[]; };
layout(push_constant) uniform Push { ForcesParams params; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.label_count) return;
  labels[i] = forces_previous(labels[i], states[i], params);
}
