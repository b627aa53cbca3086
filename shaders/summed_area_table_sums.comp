#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/summed_area_table.h"
#include "summed_area_table_tile.glsl"

layout(binding = SAT_BINDING_ROW_CARRY, std430) writeonly buffer RowCarry { float row_carry[]; };
layout(binding = SAT_BINDING_COLUMN_CARRY, std430) writeonly buffer ColumnCarry { float column_carry[]; };

void main() {
  load_tile();
  barrier();
  const uvec2 origin = tile_origin();
  const uint t = gl_LocalInvocationIndex;
  if (t < SAT_TILE) {
    float sum = 0.0;
    for (uint c = 0; c < SAT_TILE; ++c) sum += tile[t][c];
    if (origin.y + t < p.height) row_carry[gl_WorkGroupID.x * p.height + origin.y + t] = sum;
  } else if (t < 2 * SAT_TILE) {
    const uint c = t - SAT_TILE;
    float sum = 0.0;
    for (uint r = 0; r < SAT_TILE; ++r) sum += tile[r][c];
    if (origin.x + c < p.width) column_carry[gl_WorkGroupID.y * p.width + origin.x + c] = sum;
  }
}
