#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/placement_snapshot.h"

// A placement's snapshot of the frame (shared/placement_snapshot.h): every texel as it is.
layout(local_size_x = SNAPSHOT_GROUP, local_size_y = SNAPSHOT_GROUP) in;
layout(binding = SNAPSHOT_BINDING_FINAL, rgba8) readonly uniform image2D final_image;
layout(binding = SNAPSHOT_BINDING_LAYERS, rgba16f) readonly uniform image2DArray layers;
layout(binding = SNAPSHOT_BINDING_FINAL_COPY, rgba8) writeonly uniform image2D final_copy;
layout(binding = SNAPSHOT_BINDING_LAYERS_COPY, rgba16f) writeonly uniform image2DArray layers_copy;
layout(push_constant) uniform Push { SnapshotParams params; };

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(uvec2(p), params.size))) return;
  imageStore(final_copy, p, imageLoad(final_image, p));
  for (uint l = 0u; l < params.layer_count; ++l) {
    imageStore(layers_copy, ivec3(p, l), imageLoad(layers, ivec3(p, l)));
  }
}
