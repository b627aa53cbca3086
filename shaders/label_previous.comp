#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/forces.h"

// Eq. 3.1's previous position (eta): where the forces drew each label last frame, or, for labels
// held as offsets from their anchors, that offset from the anchor's new position.
layout(local_size_x = FORCES_GROUP) in;
layout(binding = FORCES_BINDING_LABELS, std430) buffer Labels { LabelGpu labels[]; };
layout(binding = FORCES_BINDING_STATE, std430) readonly buffer States { LabelStateGpu states[]; };
layout(push_constant) uniform Push { ForcesParams params; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.label_count || (states[i].flags & LABEL_STATE_PLACED) == 0u) return;
  // Anchored labels: where the label is now if it kept last frame's offset from its anchor.
  labels[i].previous =
      params.anchor_relative != 0u ? labels[i].anchor + states[i].position : states[i].drawn;
}
