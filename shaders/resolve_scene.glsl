// What a walk of shared/resolve_walk.h reads on the GPU, for the resolve (habuffer_resolve.comp)
// and the pick (pick.comp): the frame, the volumes, the atlas, the transfer table and the
// occupancy as bindings, the sampling functions the walk asks for, and the gather of a pixel's
// mesh fragments from the HA-Buffer. The includer includes shared/volume_shading.h first.
#include "habuffer.glsl"

layout(binding = VR_BINDING_FRAME) uniform Frame { FrameGpu frame; };
// (a uniform block: GPUs read its fields as constants instead of holding them in registers)
layout(binding = VR_BINDING_VOLUMES) uniform Volumes { VolumeGpu volumes[VR_MAX_VOLUMES]; };
layout(binding = VR_BINDING_ATLAS) uniform sampler3D atlas;
layout(binding = VR_BINDING_TRANSFER, std430) readonly buffer Transfer { vec4 transfer_table[]; };
layout(binding = VR_BINDING_OCCUPANCY, std430) readonly buffer Occupancy { uint occupancy[]; };

VolumeGpu volume_info(uint v) { return volumes[v]; }
vec4 volume_sample(uint v, vec3 tc) {
  return texture(atlas, volumes[v].atlas_offset.xyz + tc * volumes[v].atlas_scale.xyz);
}
vec4 table_entry(uint v, int i) { return transfer_table[v * VR_TF_SIZE + uint(i)]; }
bool volume_cut(uint v, vec3 tc) {
  for (uint i = 0u; i < volumes[v].cut_count.x; ++i)
    if (dot(volumes[v].cut[i].xyz, tc) + volumes[v].cut[i].w < 0.0f) return true;
  return false;
}
bool brick_empty(uint v, vec3 tc) {
  const uvec3 b = min(uvec3(tc / (volumes[v].texel.xyz * float(VR_BRICK))), volumes[v].bricks.xyz - 1u);
  const uvec4 g = volumes[v].bricks;
  return occupancy[g.w + (b.z * g.y + b.y) * g.x + b.x] == 0u;
}

// The mesh fragments of the frame's pixel px along its probe sequence up to the first empty slot,
// sorted by depth: how many (at most VR_MAX_MESH_FRAGMENTS; `dropped` counts those past that).
uint gather_fragments(uvec2 px, out float depths[VR_MAX_FRAGMENTS],
                      out uvec2 payloads[VR_MAX_FRAGMENTS], out uint dropped) {
  uint count = 0u;
  dropped = 0u;
  const uint pixel = px.y * frame.width + px.x;
  for (uint age = 1u; age <= VR_MAX_AGE; ++age) {
    const uint slot = habuffer_slot(pixel, age, frame.table_size);
    const uint64_t key = keys[slot];
    if (key == uint64_t(0)) break;
    if (uint(key & 0xFFFFFFul) != pixel || uint((key >> 24) & 0xFFul) != age) continue;
    if (count == VR_MAX_MESH_FRAGMENTS) {
      ++dropped;
      continue;
    }
    const float d = uintBitsToFloat(uint(key >> 32));
    const uvec2 p = payload[slot];
    uint j = count++;
    for (; j > 0u && depths[j - 1u] > d; --j) {
      depths[j] = depths[j - 1u];
      payloads[j] = payloads[j - 1u];
    }
    depths[j] = d;
    payloads[j] = p;
  }
  return count;
}
