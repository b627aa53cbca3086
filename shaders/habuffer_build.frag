#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/volume_shading.h"
#include "habuffer.glsl"

// Thin: every fragment of every mesh goes into the hash table; nothing is drawn.
layout(early_fragment_tests) in;
layout(binding = VR_BINDING_FRAME) uniform Frame { FrameGpu frame; };
layout(binding = VR_BINDING_COUNTERS, std430) buffer Counters { uint counters[VR_COUNTER_COUNT]; };
layout(push_constant) uniform Push { DrawGpu draw; };

layout(location = 0) in vec3 view_position;
layout(location = 1) in vec3 view_normal;

void main() {
  const uvec2 px = uvec2(gl_FragCoord.xy);
  const uint pixel = px.y * frame.width + px.x;
  const vec3 to_eye = -normalize(view_position);
  const uvec2 data = uvec2(mesh_payload_color(draw.color, view_normal, to_eye),
                           draw.object | (VR_KIND_MESH << 8));
  const float depth = -view_position.z;
  for (uint age = 1u; age <= VR_MAX_AGE; ++age) {
    const uint slot = habuffer_slot(pixel, age, frame.table_size);
    if (atomicCompSwap(keys[slot], uint64_t(0), habuffer_key(depth, age, pixel)) == uint64_t(0)) {
      payload[slot] = data;
      return;
    }
  }
  atomicAdd(counters[VR_COUNTER_OVERFLOW], 1u);
}
