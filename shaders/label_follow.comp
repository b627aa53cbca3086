#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/forces.h"

// The targets of the placement made beside the frames, moved with the anchors into this frame
// (follow_anchor).
layout(local_size_x = FORCES_GROUP) in;
layout(binding = FORCES_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = FORCES_BINDING_PLACED, std430) readonly buffer Placed { LabelGpu placed[]; };
layout(binding = FORCES_BINDING_TARGETS, std430) readonly buffer Targets { PlacementGpu targets[]; };
layout(binding = FORCES_BINDING_FOLLOWED, std430) writeonly buffer Followed {
  PlacementGpu followed[];
};
layout(push_constant) uniform Push { ForcesParams params; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.label_count) return;
  followed[i] = follow_anchor(targets[i], placed[i], labels[i], params);
}
