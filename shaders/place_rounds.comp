#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "shared/placement.h"

// The greedy placement in parallel rounds (shared/placement_rounds.h), four dispatches a round
// (params.step: the round, params.phase: ROUNDS_PHASE_*):
//  - MARK, a workgroup per label: an undecided label whose choice a label decided in the round
//    before constrains (every label in round 0) forgets its choice and joins the round's list,
//    which sizes the search (an indirect dispatch);
//  - EVALUATE, a workgroup per listed label and tile it searches (those past the workgroups take
//    turns): the tile's cheapest candidate against the labels decided before the round, into the
//    label's result by a 64-bit atomicMin (place_label_evaluate.glsl, as the sequential loop);
//    WIDE, the same over the rest of a label's tiles where its best is one no label wants;
//  - COMMIT, a workgroup per label: an undecided label's conflicts with the undecided labels
//    before it in the order, as a row of bits (its own bit: a label of a higher priority is
//    undecided); the dispatch's last workgroup then decides the labels of the round in
//    ROUNDS_SELECT_PASSES passes over all labels (shared/placement_rounds.h; the last round
//    decides all).
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
// coherent: COMMIT's last workgroup reads every workgroup's rows and writes the rounds.
layout(binding = PLACEMENT_BINDING_ROUND_OF, std430) coherent buffer RoundOf { uint round_of[]; };
layout(binding = PLACEMENT_BINDING_ROUND_LIST, std430) buffer RoundList { uint round_list[]; };
layout(binding = PLACEMENT_BINDING_ROUND_ARGS, std430) buffer RoundArgs { uint round_args[]; };
layout(binding = PLACEMENT_BINDING_ROUND_COUNTS, std430) buffer RoundCounts { uint round_counts[]; };
layout(binding = PLACEMENT_BINDING_ROUND_BITS, std430) coherent buffer RoundBits { uint round_bits[]; };
layout(binding = PLACEMENT_BINDING_ROUND_DONE, std430) coherent buffer RoundDone { uint round_done[]; };
layout(binding = PLACEMENT_BINDING_ROUND_WIDE, std430) coherent buffer RoundWide { uint round_wide[]; };
layout(binding = PLACEMENT_BINDING_KEEP_OUT, std430) readonly buffer KeepOut { uvec4 keep_out[]; };
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
// COMMIT's last workgroup: 2 bits a label (SELECT_*), whether a pass changed one, the waiting.
#define SELECT_OPEN 0u
#define SELECT_IN 1u
#define SELECT_OUT 2u
#define SELECT_NONE 3u  // not undecided
shared uint select_state[2][LABEL_MAX / 16];
shared uint select_waiting;
shared uint finishing;
shared uint64_t round_best;  // EVALUATE: the label's best when the workgroup takes a tile

uvec4 keep_out_at(uint i) {
  return keep_out[i];
}
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
    round_wide[i] = 0u;
    round_list[atomicAdd(round_args[3u * r + 1u], 1u)] = i;
  }
}

// EVALUATE (the searched tiles) or WIDE (the rest of the list, for a label whose best is one no
// label wants).
void evaluate(uint r, bool wide) {
  const uint i = round_list[gl_WorkGroupID.y];
  const uint s = rounds_rank(ranks[i]);
  const uvec2 tiles_xy = placement_tiles(params.width, params.height);
  const uint tiles = tiles_xy.x * tiles_xy.y;
  const PlacementBucketsGpu b = buckets[s];
  const uint searched = rounds_searched_tiles(b, tiles_budget());
  uint listed = 0u;
  for (uint k = 0u; k < PLACEMENT_BUCKETS; ++k) listed += b.counts[k];
  // (whether WIDE goes on was decided by EVALUATE's last workgroup of the label: results[i]
  // already falls again while WIDE runs)
  if (wide && round_wide[i] != gl_NumWorkGroups.x + 1u) return;
  position = i;
  placed = params.label_count;
  uint bucket = 0u, bucket_end = b.counts[0];
  const uint from = wide ? searched : 0u, to = wide ? listed : searched;
  for (uint q = from + gl_WorkGroupID.x; q < to; q += gl_NumWorkGroups.x) {
    // The list is in bucket order: once a bucket's lowest bound is above the best found, so is
    // every tile's after it.
    // (the best as one invocation read it: the workgroup leaves together, or its barriers hang)
    while (q >= bucket_end && bucket + 1u < PLACEMENT_BUCKETS) bucket_end += b.counts[++bucket];
    if (gl_LocalInvocationIndex == 0u) round_best = results[i];
    barrier();
    if (bucket > 0u && b.lowest + placement_bucket_edge(bucket, params.bucket_width) > cost_of(round_best)) {
      break;
    }
    const uvec2 entry = tile_list[s * tiles + q];
    const uint index = entry.x & PLACEMENT_TILE_INDEX_MASK;
    const uvec2 tile = uvec2(index % tiles_xy.x, index / tiles_xy.x);
    const uint64_t group =
        evaluate_tile(i, tile, 0u, uintBitsToFloat(entry.y), true, 1.0 / 0.0, false);
    if (gl_LocalInvocationIndex == 0u && group < results[i]) atomicMin(results[i], group);
    barrier();
  }
  if (!wide && gl_LocalInvocationIndex == 0u) {
    // The label's last EVALUATE workgroup reads its best over the searched tiles.
    memoryBarrierBuffer();
    if (atomicAdd(round_wide[i], 1u) + 1u == gl_NumWorkGroups.x) {
      memoryBarrierBuffer();
      const bool on = cost_of(atomicMin(results[i], PLACEMENT_NONE)) >= rounds_wide_cost() && to < listed;
      round_wide[i] = gl_NumWorkGroups.x + (on ? 1u : 0u);
    }
  }
}

// Label i's row of conflicts (COMMIT), its own bit for "a higher priority is undecided".
void conflicts(uint i, uint r) {
  const uint words = rounds_row_words(params.label_count);
  const uint threads = PLACE_GROUP_X * PLACE_GROUP_Y;
  for (uint w = gl_LocalInvocationIndex; w < words; w += threads) round_bits[i * words + w] = 0u;
  barrier();
  const uint64_t mine = results[i];
  const uint rank = rounds_rank(ranks[i]), first = rounds_group_first(ranks[i]);
  for (uint j = gl_LocalInvocationIndex; j < params.label_count; j += threads) {
    if (j == i || !undecided(j)) continue;
    const uint other = rounds_rank(ranks[j]);
    if (other >= rank) continue;
    if (other < first) {
      atomicOr(round_bits[i * words + i / 32u], 1u << (i % 32u));
    } else if (rounds_conflict(labels[i], mine, labels[j], results[j])) {
      atomicOr(round_bits[i * words + j / 32u], 1u << (j % 32u));
    }
  }
}

// States by pass parity (each pass reads the last one's and writes its own: the same states
// however the invocations interleave).
uint select_of(uint parity, uint i) {
  return (select_state[parity][i / 16u] >> (2u * (i % 16u))) & 3u;
}
void select_set(uint parity, uint i, uint s) {
  atomicOr(select_state[parity][i / 16u], s << (2u * (i % 16u)));
}

// The last workgroup of COMMIT: the round's labels, decided (shared/placement_rounds.h).
void select_and_decide(uint r) {
  const uint n = params.label_count, words = rounds_row_words(n);
  const uint threads = PLACE_GROUP_X * PLACE_GROUP_Y;
  for (uint k = gl_LocalInvocationIndex; k < (n + 15u) / 16u; k += threads) {
    select_state[0][k] = 0u;
    select_state[1][k] = 0u;
  }
  if (gl_LocalInvocationIndex == 0u) select_waiting = 0u;
  barrier();
  for (uint i = gl_LocalInvocationIndex; i < n; i += threads) {
    if (!undecided(i)) select_set(0u, i, SELECT_NONE);
    else if ((round_bits[i * words + i / 32u] & (1u << (i % 32u))) != 0u) select_set(0u, i, SELECT_OUT);
  }
  barrier();
  const bool last = r + 1u == rounds_recorded();
  // ROUNDS_SELECT_PASSES passes (rounds_select_pass); the labels still open wait.
  uint parity = 0u;
  for (uint pass = 0u; pass < ROUNDS_SELECT_PASSES && !last; ++pass) {
    const uint next = parity ^ 1u;
    for (uint i = gl_LocalInvocationIndex; i < n; i += threads) {
      uint state = select_of(parity, i);
      if (state == SELECT_OPEN) {
        bool any_in = false, all_out = true;
        for (uint w = 0u; w < words && !any_in; ++w) {
          uint bits = round_bits[i * words + w];
          if (w == i / 32u) bits &= ~(1u << (i % 32u));
          while (bits != 0u) {
            const uint j = w * 32u + uint(findLSB(bits));
            bits &= bits - 1u;
            const uint s = select_of(parity, j);
            any_in = any_in || s == SELECT_IN;
            all_out = all_out && s == SELECT_OUT;
          }
        }
        state = any_in ? SELECT_OUT : all_out ? SELECT_IN : SELECT_OPEN;
      }
      select_set(next, i, state);
    }
    barrier();
    for (uint k = gl_LocalInvocationIndex; k < (n + 15u) / 16u; k += threads) select_state[parity][k] = 0u;
    barrier();
    parity = next;
  }
  for (uint i = gl_LocalInvocationIndex; i < n; i += threads) {
    if (!undecided(i)) continue;
    if (last || select_of(parity, i) == SELECT_IN) {
      round_of[i] = r;
    } else {
      atomicAdd(select_waiting, 1u);
    }
  }
  barrier();
  if (gl_LocalInvocationIndex == 0u) round_counts[r + 1u] = select_waiting;
}

// COMMIT: the rows, then the last workgroup to finish decides.
void commit(uint i, uint r) {
  if (undecided(i)) conflicts(i, r);
  memoryBarrierBuffer();
  barrier();
  if (gl_LocalInvocationIndex == 0u) {
    const uint groups = gl_NumWorkGroups.x * gl_NumWorkGroups.y;
    finishing = atomicAdd(round_done[r], 1u) + 1u == groups ? 1u : 0u;
    memoryBarrierBuffer();
  }
  barrier();
  if (finishing != 0u) select_and_decide(r);
}

void main() {
  const uint r = params.step;
  if (params.phase == ROUNDS_PHASE_EVALUATE || params.phase == ROUNDS_PHASE_WIDE) {
    evaluate(r, params.phase == ROUNDS_PHASE_WIDE);
    return;
  }
  const uint i = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (params.phase == ROUNDS_PHASE_COMMIT) {
    commit(i, r);
  } else if (undecided(i)) {
    mark(i, r);
  }
}
