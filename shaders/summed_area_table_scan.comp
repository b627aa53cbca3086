#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
#include "shared/summed_area_table.h"
#include "summed_area_table_tile.glsl"

layout(binding = SAT_BINDING_OUTPUT, std430) writeonly buffer Output { float values[]; } dst;
layout(binding = SAT_BINDING_CARRIES, std430) readonly buffer Carries { float carries[]; };

const uint kRuns = SAT_TILE / SAT_RUN;  // runs per tile line; kRuns * SAT_TILE == threads

shared float left[SAT_TILE];   // sum of each tile row's image row left of the tile
shared float above[SAT_TILE];  // sum of each tile column's image column above the tile
shared float run_totals[SAT_TILE][kRuns];
shared float corner_parts[SAT_TILE * SAT_GROUP_ROWS];

// Inclusive scan of the line `line` of the tile (a row when along_rows, else a column): each
// thread scans SAT_RUN elements, then adds the totals of the runs before its own.
void scan_lines(bool along_rows, float seed_first, bool seed_row) {
  const uint t = gl_LocalInvocationIndex;
  const uint line = t / kRuns, run = t % kRuns, first = run * SAT_RUN;
  float v[SAT_RUN];
  for (uint j = 0; j < SAT_RUN; ++j) {
    v[j] = along_rows ? tile[line][first + j] : tile[first + j][line];
    if (seed_row && line == 0) v[j] += above[first + j];
  }
  if (run == 0) v[0] += seed_first;
  for (uint j = 1; j < SAT_RUN; ++j) v[j] += v[j - 1];
  run_totals[line][run] = v[SAT_RUN - 1];
  barrier();
  float offset = 0.0;
  for (uint r = 0; r < run; ++r) offset += run_totals[line][r];
  for (uint j = 0; j < SAT_RUN; ++j) {
    if (along_rows) tile[line][first + j] = v[j] + offset;
    else tile[first + j][line] = v[j] + offset;
  }
  barrier();
}

void main() {
  load_tile();
  const uvec2 origin = tile_origin();
  const uint t = gl_LocalInvocationIndex;
  if (t < SAT_TILE) {
    left[t] = origin.y + t < p.height ? carries[row_carry_index(gl_WorkGroupID.x, origin.y + t)] : 0.0;
  } else if (t < 2 * SAT_TILE) {
    const uint c = t - SAT_TILE;
    above[c] = origin.x + c < p.width ? carries[column_carry_index(gl_WorkGroupID.y, origin.x + c)] : 0.0;
  }
  // Everything above and to the left of the tile: the column carries of the columns to its left.
  float part = 0.0;
  for (uint x = t; x < origin.x; x += SAT_TILE * SAT_GROUP_ROWS) {
    part += carries[column_carry_index(gl_WorkGroupID.y, x)];
  }
  part = subgroupAdd(part);
  if (subgroupElect()) corner_parts[gl_SubgroupID] = part;
  barrier();
  float corner = 0.0;
  for (uint s = 0; s < gl_NumSubgroups; ++s) corner += corner_parts[s];

  const uint line = t / kRuns;
  scan_lines(true, left[line] + (line == 0 ? corner : 0.0), true);
  scan_lines(false, 0.0, false);

  const uint x = origin.x + gl_LocalInvocationID.x;
  for (uint r = gl_LocalInvocationID.y; r < SAT_TILE; r += SAT_GROUP_ROWS) {
    const uint y = origin.y + r;
    if (x < p.width && y < p.height) dst.values[image_offset() + y * p.width + x] = tile[r][gl_LocalInvocationID.x];
  }
}
