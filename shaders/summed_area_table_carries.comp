#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "shared/summed_area_table.h"

layout(local_size_x = SAT_CARRY_GROUP) in;

layout(binding = SAT_BINDING_CARRIES, std430) buffer Carries { float carries[]; };
layout(push_constant) uniform Push { SatParams p; };

// Loads are issued a chunk at a time (unrolled, so the chunk stays in registers): a thread
// waits for memory once per chunk rather than once per tile.
const uint kChunk = 8;

// An exclusive scan, in place, of `count` values `stride` floats apart from `first`.
void scan_line(uint first, uint stride, uint count) {
  float running = 0.0;
  for (uint base = 0; base < count; base += kChunk) {
    float v[kChunk];
    [[unroll]] for (uint j = 0; j < kChunk; ++j) {
      v[j] = base + j < count ? carries[first + (base + j) * stride] : 0.0;
    }
    [[unroll]] for (uint j = 0; j < kChunk; ++j) {
      if (base + j < count) carries[first + (base + j) * stride] = running;
      running += v[j];
    }
  }
}

// One thread per image row (over the tiles to its left), then one per image column (over the
// tiles above). Neighbouring threads scan neighbouring lines, so every access is coalesced.
void main() {
  const uint i = gl_GlobalInvocationID.x;
  const uint base = gl_GlobalInvocationID.y * (p.tiles_x * p.height + p.tiles_y * p.width);
  if (i < p.height) {
    scan_line(base + i, p.height, p.tiles_x);
  } else if (i < p.height + p.width) {
    scan_line(base + p.tiles_x * p.height + (i - p.height), p.width, p.tiles_y);
  }
}
