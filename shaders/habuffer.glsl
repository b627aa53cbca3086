// The HA-Buffer in storage buffers, shared by its build, its resolve and the pick (the counters
// are the build's and the resolve's own).
// A key is 64 bits: eye depth (float bits, positive so they order like the floats) in the high
// word, then the age (probe number, 8 bits) and the pixel index (24 bits). Slot of (pixel, age):
// pixel + age * golden ratio, modulo the table: age 1 keeps neighbouring pixels in neighbouring
// slots (coherent, as in Lefebvre et al.'s HA-Buffer), later ages scatter. Nothing is ever
// removed, so a fragment probed past age a only if slot (pixel, a) was taken: the resolve stops
// at the first empty slot of a pixel's sequence, and needs no per-pixel count.
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require

layout(binding = VR_BINDING_KEYS, std430) buffer Keys { uint64_t keys[]; };
layout(binding = VR_BINDING_PAYLOAD, std430) buffer Payload { uvec2 payload[]; };

uint habuffer_slot(uint pixel, uint age, uint table_size) {
  return (pixel + age * 0x9E3779B1u) % table_size;
}

uint64_t habuffer_key(float depth, uint age, uint pixel) {
  return (uint64_t(floatBitsToUint(depth)) << 32) | (uint64_t(age) << 24) | uint64_t(pixel);
}
