#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/summed_area_table.h"

layout(local_size_x = SAT_CARRY_GROUP) in;

layout(binding = SAT_BINDING_ROW_CARRY, std430) buffer RowCarry { float row_carry[]; };
layout(binding = SAT_BINDING_COLUMN_CARRY, std430) buffer ColumnCarry { float column_carry[]; };
layout(push_constant) uniform Push { SatParams p; };

// One thread per image row (then per image column): an exclusive scan over the tiles, in place.
// Neighbouring threads touch neighbouring floats, so every step is one coalesced access.
void main() {
  const uint i = gl_GlobalInvocationID.x;
  float running = 0.0;
  if (i < p.height) {
    for (uint tx = 0; tx < p.tiles_x; ++tx) {
      const uint k = tx * p.height + i;
      const float v = row_carry[k];
      row_carry[k] = running;
      running += v;
    }
  } else if (i < p.height + p.width) {
    const uint x = i - p.height;
    for (uint ty = 0; ty < p.tiles_y; ++ty) {
      const uint k = ty * p.width + x;
      const float v = column_carry[k];
      column_carry[k] = running;
      running += v;
    }
  }
}
