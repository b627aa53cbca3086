#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/forces.h"

// One invocation per label: its drawn position moves toward its placement (eq. 3.6-3.8).
layout(local_size_x = FORCES_GROUP) in;
layout(binding = FORCES_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = FORCES_BINDING_TARGETS, std430) readonly buffer Targets { PlacementGpu targets[]; };
layout(binding = FORCES_BINDING_STATE, std430) buffer States { LabelStateGpu states[]; };
layout(binding = FORCES_BINDING_DRAWN, std430) writeonly buffer Drawn { PlacementGpu drawn[]; };
layout(push_constant) uniform Push { ForcesParams params; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.label_count) return;
  LabelStateGpu state = states[i];
  if (params.trial == 0u) {
    state = forces_update(labels[i], targets[i], state, params);
    states[i] = state;
  }
  drawn[i] = forces_drawn(targets[i], state);
}
