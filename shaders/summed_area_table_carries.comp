#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/summed_area_table.h"

layout(local_size_x = SAT_CARRY_GROUP) in;

layout(binding = SAT_BINDING_ROW_CARRY, std430) buffer RowCarry { float row_carry[]; };
layout(binding = SAT_BINDING_COLUMN_CARRY, std430) buffer ColumnCarry { float column_carry[]; };
layout(push_constant) uniform Push { SatParams p; };

// Loads are issued a chunk at a time, so a thread waits for memory once per chunk rather than
// once per tile.
const uint kChunk = 16;

// One thread per image row (then per image column): an exclusive scan over the tiles, in place.
// Neighbouring threads touch neighbouring floats, so every step is one coalesced access.
void main() {
  const uint i = gl_GlobalInvocationID.x;
  const bool is_row = i < p.height;
  if (i >= p.height + p.width) return;
  const uint line = is_row ? i : i - p.height;
  const uint stride = is_row ? p.height : p.width;
  const uint count = is_row ? p.tiles_x : p.tiles_y;
  float running = 0.0;
  float v[kChunk];
  for (uint base = 0; base < count; base += kChunk) {
    const uint n = min(kChunk, count - base);
    for (uint j = 0; j < n; ++j) {
      const uint k = (base + j) * stride + line;
      v[j] = is_row ? row_carry[k] : column_carry[k];
    }
    for (uint j = 0; j < n; ++j) {
      const uint k = (base + j) * stride + line;
      if (is_row) row_carry[k] = running;
      else column_carry[k] = running;
      running += v[j];
    }
  }
}
