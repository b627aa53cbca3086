#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
#include "shared/placement.h"

// Before the label loop, for every label at once: a lower bound of eq. 3.1 over each 32x32 tile
// of candidates (phase BOUNDS: a workgroup per PLACEMENT_BOUNDS_TILES tiles of a label), how many tiles fall in each bucket above the label's lowest bound
// (COUNT), and the tiles sorted by bucket with the first label dispatch's size (SORT). None of it
// depends on where earlier labels went, so it is one dispatch per phase, not one per label.
layout(local_size_x = PLACEMENT_BOUNDS_GROUP) in;
layout(binding = PLACEMENT_BINDING_TABLES, std430) readonly buffer Tables { float tables[]; };
layout(binding = PLACEMENT_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = PLACEMENT_BINDING_ORDER, std430) readonly buffer Order { uint order[]; };
layout(binding = PLACEMENT_BINDING_BOUNDS, std430) buffer Bounds { float bounds[]; };
layout(binding = PLACEMENT_BINDING_BUCKETS, std430) buffer Buckets { PlacementBucketsGpu buckets[]; };
layout(binding = PLACEMENT_BINDING_TILES, std430) writeonly buffer Tiles { uvec2 tile_list[]; };
layout(binding = PLACEMENT_BINDING_LOWER, std430) buffer Lower { uint lower[]; };
layout(binding = PLACEMENT_BINDING_ARGS, std430) writeonly buffer Args { uint args[]; };
layout(push_constant) uniform Push { PlacementParams params; };

const float INFINITY = 1.0 / 0.0;

float table_at(uint layer, int x, int y) {
  if (x < 0 || y < 0) return 0.0;
  return tables[layer * params.width * params.height + uint(y) * params.width + uint(x)];
}

#include "shared/placement_bound.h"

uint tile_count() {
  const uvec2 tiles = placement_tiles(params.width, params.height);
  return tiles.x * tiles.y;
}

// A tile's bound: the lowest of its cells' (tile_cell_bound). A workgroup takes
// PLACEMENT_BOUNDS_TILES tiles of one label, an invocation a cell.
shared uint tile_lowest[PLACEMENT_BOUNDS_TILES];
void tile_bounds(uint group, uint s) {
  const uint cells = (PLACEMENT_TILE / PLACEMENT_CELL) * (PLACEMENT_TILE / PLACEMENT_CELL);
  const uint local_tile = gl_LocalInvocationIndex / cells, c = gl_LocalInvocationIndex % cells;
  const uint tile = group * PLACEMENT_BOUNDS_TILES + local_tile;
  if (c == 0u) tile_lowest[local_tile] = floatBitsToUint(INFINITY);
  barrier();
  const bool in_range = tile < tile_count();
  const LabelGpu me = labels[order[s]];
  const float bound = in_range ? tile_cell_bound(me, tile, c) : INFINITY;
  atomicMin(tile_lowest[local_tile], floatBitsToUint(bound));  // bounds >= 0: bits order too
  barrier();
  if (in_range && c == 0u) {
    bounds[s * tile_count() + tile] = uintBitsToFloat(tile_lowest[local_tile]);
    atomicMin(lower[s], tile_lowest[local_tile]);
  }
}

void main() {
  if (params.phase == PLACEMENT_PHASE_BOUNDS) {
    tile_bounds(gl_WorkGroupID.x, gl_WorkGroupID.y);
    return;
  }
  const uint tiles = tile_count();
  const uint tile = gl_GlobalInvocationID.x;
  const uint s = gl_WorkGroupID.y;  // position in the insertion order
  const bool in_range = tile < tiles;
  if (!in_range) return;
  if (params.phase == PLACEMENT_PHASE_SORT && tile == 0u && s == 0u) {
    // The first place_label dispatch, when indirect: the first label's speculative pass and
    // classification, and the region writer (see place_label.comp).
    uint listed = 0u;
    for (uint b = 0u; b < PLACEMENT_BUCKETS; ++b) listed += buckets[0].counts[b];
    const uint count0 = buckets[0].counts[0];
    const uvec3 size = placement_dispatch_size(placement_label_groups(0u, count0, listed, params.classify_tiles));
    args[0] = size.x;
    args[1] = size.y;
    args[2] = size.z;
  }
  if (params.phase == PLACEMENT_PHASE_SORT && tile == 0u) buckets[s].lowest = uintBitsToFloat(lower[s]);
  const float bound = bounds[s * tiles + tile];
  if (isinf(bound)) return;  // no candidate here may hold the label
  // Everything in bucket 0 when the constraint image is kept: every candidate is evaluated.
  const uint bucket = params.write_constraints != 0u
                          ? 0u
                          : placement_bucket(bound - uintBitsToFloat(lower[s]), params.bucket_width);
  if (params.phase == PLACEMENT_PHASE_COUNT) {
    atomicAdd(buckets[s].counts[bucket], 1u);
    return;
  }
  // In bucket order: the speculative pass takes the first counts[0], the main pass a prefix.
  uint index = atomicAdd(buckets[s].cursors[bucket], 1u);
  for (uint b = 0u; b < bucket; ++b) index += buckets[s].counts[b];
  tile_list[s * tiles + index] =
      uvec2(tile | (bucket == 0u ? PLACEMENT_BUCKET0_TILE : 0u), floatBitsToUint(bound));
}
