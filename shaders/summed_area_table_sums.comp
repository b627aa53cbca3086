#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/summed_area_table.h"
#include "summed_area_table_tile.glsl"

layout(binding = SAT_BINDING_CARRIES, std430) writeonly buffer Carries { float carries[]; };

const uint kRuns = SAT_TILE / SAT_RUN;  // runs per tile line; kRuns * SAT_TILE == threads
shared float row_parts[SAT_TILE][kRuns];
shared float column_parts[SAT_TILE][kRuns];

void main() {
  load_tile();
  barrier();
  // Every thread sums one run of a row and one run of a column; then 64 threads add the runs.
  const uint t = gl_LocalInvocationIndex;
  const uint line = t / kRuns, run = t % kRuns;
  float row = 0.0, column = 0.0;
  for (uint j = 0; j < SAT_RUN; ++j) {
    row += tile[line][run * SAT_RUN + j];
    column += tile[run * SAT_RUN + j][line];
  }
  row_parts[line][run] = row;
  column_parts[line][run] = column;
  barrier();
  const uvec2 origin = tile_origin();
  if (t < 2 * SAT_TILE) {
    const uint l = t % SAT_TILE;
    float sum = 0.0;
    for (uint r = 0; r < kRuns; ++r) sum += t < SAT_TILE ? row_parts[l][r] : column_parts[l][r];
    if (t < SAT_TILE && origin.y + l < p.height) {
      carries[row_carry_index(gl_WorkGroupID.x, origin.y + l)] = sum;
    } else if (t >= SAT_TILE && origin.x + l < p.width) {
      carries[column_carry_index(gl_WorkGroupID.y, origin.x + l)] = sum;
    }
  }
}
