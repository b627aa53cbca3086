#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "shared/placement.h"

// The greedy placement in parallel rounds (shared/placement_rounds.h), three dispatches a round
// (params.step: the round, params.phase: ROUNDS_PHASE_*):
//  - MARK, a workgroup per label: an undecided label whose choice a label decided in the round
//    before constrains (every label in round 0) forgets its choice and joins the round's list,
//    which sizes the search (an indirect dispatch);
//  - EVALUATE, a workgroup per listed label and tile it searches (those past the workgroups take
//    turns): the tile's cheapest candidate against the labels decided before the round, into the
//    label's result by a 64-bit atomicMin (place_label_evaluate.glsl, as the sequential loop);
//  - COMMIT, a workgroup per label: an undecided label is decided in this round unless its choice
//    conflicts with an undecided label's before it in the order, or a label of a higher priority
//    is undecided (the last round decides all).
layout(local_size_x = PLACE_GROUP_X, local_size_y = PLACE_GROUP_Y) in;
layout(binding = PLACEMENT_BINDING_TABLES, std430) readonly buffer Tables { float tables[]; };
layout(binding = PLACEMENT_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
// coherent: a tile's read of its label's best so far sees other workgroups' atomicMin results (a
// stale value is only a weaker bound: results only decrease within a round).
layout(binding = PLACEMENT_BINDING_RESULTS, std430) coherent buffer Results { uint64_t results[]; };
layout(binding = PLACEMENT_BINDING_CONSTRAINTS, std430) writeonly buffer Constraints { uint constraints[]; };
layout(binding = PLACEMENT_BINDING_BUCKETS, std430) readonly buffer Buckets { PlacementBucketsGpu buckets[]; };
layout(binding = PLACEMENT_BINDING_TILES, std430) readonly buffer Tiles { uvec2 tile_list[]; };
layout(binding = PLACEMENT_BINDING_RANKS, std430) readonly buffer Ranks { uint ranks[]; };
layout(binding = PLACEMENT_BINDING_ROUND_OF, std430) buffer RoundOf { uint round_of[]; };
layout(binding = PLACEMENT_BINDING_ROUND_LIST, std430) buffer RoundList { uint round_list[]; };
layout(binding = PLACEMENT_BINDING_ROUND_ARGS, std430) buffer RoundArgs { uint round_args[]; };
layout(binding = PLACEMENT_BINDING_ROUND_COUNTS, std430) buffer RoundCounts { uint round_counts[]; };
layout(push_constant) uniform Push { PlacementParams params; };

// (PlacementParams has no room left: the rounds recorded ride in `label`, the tiles a label
// searches at most in `spec_label`.)
uint rounds_recorded() { return params.label; }
uint tiles_budget() { return params.spec_label; }

// The label this workgroup places, and the labels it tests against: every label slot, of which
// those decided before this round and shown have regions (regions_of).
uint position;
uint placed;

#define PLACE_CULL_CHUNK (PLACE_GROUP_X * PLACE_GROUP_Y)
shared uint tile_placed[PLACE_CULL_CHUNK];
shared uint tile_placed_count;
shared vec2 tile_anchors[PLACE_CULL_CHUNK];
shared uint tile_anchor_count;
shared uint tile_bits;
shared uint tile_hope;
shared uint64_t tile_best;
shared uint64_t group_best[PLACE_GROUP_X * PLACE_GROUP_Y];
shared uint any_hit;  // MARK and COMMIT: some invocation found a constraining label

float table_at(uint layer, int x, int y) {
  const uint column = uint(clamp(x, 0, int(params.width) - 1));
  const uint row = uint(clamp(y, 0, int(params.height) - 1));
  const float value = tables[(layer * params.height + row) * params.width + column];
  return x < 0 || y < 0 ? 0.0 : value;
}

#include "shared/placement_cost.h"
#include "shared/placement_bound.h"
#include "shared/placement_rounds.h"

// Label i against label j: j's regions where j was decided before this round and is shown.
PairRegionsGpu regions_of(uint i, uint j) {
  const uint64_t key = j != i && round_of[j] < params.step ? results[j] : PLACEMENT_NONE;
  return pair_regions(labels[i], labels[j], key_placed(labels[j], key), params.margin);
}
uint placed_count() { return tile_placed_count; }
PairRegionsGpu placed_regions(uint k) { return regions_of(position, tile_placed[k]); }
uint anchor_count() { return tile_anchor_count; }
vec2 anchor_at(uint k) { return tile_anchors[k]; }
float cost_of(uint64_t key) {
  return key == PLACEMENT_NONE ? uintBitsToFloat(0x7F800000u) : uintBitsToFloat(uint(key >> 32));
}

#include "place_label_tile.glsl"
#include "place_label_evaluate.glsl"

bool undecided(uint i) {
  return i < params.label_count && ranks[i] != ROUNDS_NO_RANK && round_of[i] == ROUND_UNDECIDED;
}

void mark(uint i, uint r) {
  if (gl_LocalInvocationIndex == 0u) any_hit = r == 0u ? 1u : 0u;
  barrier();
  const uint threads = PLACE_GROUP_X * PLACE_GROUP_Y;
  if (r > 0u) {
    const uint64_t mine = results[i];
    for (uint j = gl_LocalInvocationIndex; j < params.label_count && any_hit == 0u; j += threads) {
      if (round_of[j] == r - 1u && rounds_constrains(labels[i], mine, labels[j], results[j])) {
        any_hit = 1u;
      }
    }
  }
  barrier();
  if (gl_LocalInvocationIndex == 0u && any_hit != 0u) {
    results[i] = PLACEMENT_NONE;
    round_list[atomicAdd(round_args[3u * r + 1u], 1u)] = i;
  }
}

void evaluate(uint r) {
  const uint i = round_list[gl_WorkGroupID.y];
  const uint s = rounds_rank(ranks[i]);
  const uvec2 tiles_xy = placement_tiles(params.width, params.height);
  const uint tiles = tiles_xy.x * tiles_xy.y;
  const uint searched = rounds_searched_tiles(buckets[s], tiles_budget());
  position = i;
  placed = params.label_count;
  for (uint q = gl_WorkGroupID.x; q < searched; q += gl_NumWorkGroups.x) {
    const uvec2 entry = tile_list[s * tiles + q];
    const uint index = entry.x & PLACEMENT_TILE_INDEX_MASK;
    const uvec2 tile = uvec2(index % tiles_xy.x, index / tiles_xy.x);
    const uint64_t group =
        evaluate_tile(i, tile, 0u, uintBitsToFloat(entry.y), true, 1.0 / 0.0, false);
    if (gl_LocalInvocationIndex == 0u && group < results[i]) atomicMin(results[i], group);
    barrier();
  }
}

void commit(uint i, uint r) {
  if (gl_LocalInvocationIndex == 0u) any_hit = 0u;
  barrier();
  const uint threads = PLACE_GROUP_X * PLACE_GROUP_Y;
  const uint64_t mine = results[i];
  const uint rank = rounds_rank(ranks[i]), first = rounds_group_first(ranks[i]);
  for (uint j = gl_LocalInvocationIndex; j < params.label_count && any_hit == 0u; j += threads) {
    // (undecided when the round began: a label deciding in this round writes r)
    const bool open = ranks[j] != ROUNDS_NO_RANK && (round_of[j] == ROUND_UNDECIDED || round_of[j] == r);
    const uint other = rounds_rank(ranks[j]);
    if (j != i && open && other < rank &&
        (other < first || rounds_conflict(labels[i], mine, labels[j], results[j]))) {
      any_hit = 1u;
    }
  }
  barrier();
  if (gl_LocalInvocationIndex == 0u) {
    if (any_hit == 0u || r + 1u == rounds_recorded()) {
      round_of[i] = r;
    } else {
      atomicAdd(round_counts[r + 1u], 1u);
    }
  }
}

void main() {
  const uint r = params.step;
  if (params.phase == ROUNDS_PHASE_EVALUATE) {
    evaluate(r);
    return;
  }
  const uint i = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (!undecided(i)) return;
  if (params.phase == ROUNDS_PHASE_MARK) mark(i, r);
  else commit(i, r);
}
