// The layout tidy-up (shared/layout_tidy.h) and the placements' output, one phase per dispatch
// (params.phase; params.step: the round): its start from the label loop's (cost, pixel) results,
// four dispatches per round, and each label's placement (box centre, cost, shown). A round whose
// round before applied nothing leaves at once. The changes a round applies are taken up by the
// next round's conflicts step (each label's workgroup stores its own; every workgroup reads the
// others' as `take` says), or by the output: a fifth dispatch per round for that alone cost time
// on every round, even a round with nothing to do.
// Included by placement_finalize.comp (up to TIDY_SHARED_MAX labels) and
// placement_finalize_large.comp (more: TIDY_STATES_IN_BUFFER), and with TIDY_SEARCH_ONLY by
// placement_tidy_search.comp and placement_tidy_search_large.comp: the search step in a pipeline
// of its own, the other steps without it. (One pipeline for all of them took lavapipe twice as
// long to create; on a GPU, registers are allocated for a pipeline's largest step.)
layout(local_size_x = 64) in;
layout(binding = PLACEMENT_BINDING_TABLES, std430) readonly buffer Tables { float tables[]; };
layout(binding = PLACEMENT_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = PLACEMENT_BINDING_ORDER, std430) readonly buffer Order { uint order[]; };
layout(binding = PLACEMENT_BINDING_RESULTS, std430) readonly buffer Results { uint64_t results[]; };
layout(binding = PLACEMENT_BINDING_PLACEMENTS, std430) writeonly buffer Placements { PlacementGpu placements[]; };
layout(binding = PLACEMENT_BINDING_TIDY, std430) buffer Tidy { TidyGpu tidy[]; };
layout(binding = PLACEMENT_BINDING_TIDY_ROUNDS, std430) buffer Rounds { uint rounds[]; };
// The rounds' dispatch sizes where they are indirect (CPU devices, Placement::add_finalize): zero
// workgroups for a round after one that changed nothing. (Written on every device, unread where
// the rounds are direct: 12 atomics per owner that applied a change.)
layout(binding = PLACEMENT_BINDING_TIDY_ARGS, std430) buffer Args { uint tidy_args[]; };

layout(push_constant) uniform Push { PlacementParams params; };

// Round r runs: its steps' dispatch sizes.
void write_round_args(uint r) {
  for (uint k = 0u; k < TIDY_ROUND_STEPS; ++k) {
    const uvec3 size = tidy_phase_groups(TIDY_PHASE_CONFLICTS + k, params.label_count);
    for (uint c = 0u; c < 3u; ++c) {
      // (every owner that applied a change writes the same sizes)
      atomicMax(tidy_args[(r * TIDY_ROUND_STEPS + k) * 3u + c], size[c]);
    }
  }
}

float table_at(uint layer, int x, int y) {
  if (x < 0 || y < 0) return 0.0f;
  return tables[(layer * params.height + uint(y)) * params.width + uint(x)];
}

#include "shared/layout_tidy.h"

// A round's dispatches read every label's state many times over (each change is weighed against
// all labels): with up to TIDY_SHARED_MAX labels (placement_finalize.comp) each workgroup copies
// what its phase reads into shared memory first. (Read from the buffer, a round took 40 us or
// more on an H100, latency-bound.) With more (placement_finalize_large.comp, TIDY_STATES_IN_BUFFER)
// the phases read the buffer: no phase writes what it reads (the search writes the bests, the
// owners the partners and next states, the apply states it does not read), so the copy is only a
// cache. (Two shaders, so that the small case's reads are plain shared-memory loads with no
// choice made per read.)
uint tidy_count() { return params.label_count; }
LabelGpu tidy_input(uint k) { return labels[k]; }
// (read once per change weighed, by one invocation: from the buffer in both shaders)
ivec4 tidy_conflicts_now(uint k) { return tidy[k].conflicts; }
// The conflicts step and the output see the changes the round before applied (TidyGpu::take).
bool tidy_takes(uint phase) { return phase == TIDY_PHASE_CONFLICTS || phase == TIDY_PHASE_OUTPUT; }
#ifdef TIDY_STATES_IN_BUFFER
// (if, not ?: a selection between two buffer structs stored elsewhere makes glslang write
// invalid SPIR-V)
TidyLabel tidy_state(uint k) {
  if (tidy_takes(params.phase) && tidy[k].take != 0u) return tidy[k].next;
  return tidy[k].label;
}
float tidy_free(uint k) {
  return tidy_takes(params.phase) && tidy[k].take != 0u ? tidy_free_cost(tidy[k].next, labels[k])
                                                        : tidy[k].free;
}
uint tidy_rank(uint k) { return tidy[k].rank; }
uint64_t tidy_best(uint k) { return tidy[k].best; }
TidyLabel tidy_next(uint k) { return tidy[k].next; }
uint tidy_partner(uint k) { return tidy[k].partner; }
void load_states(uint n, uint phase) {}
#else
shared TidyLabel s_label[TIDY_SHARED_MAX];
shared float s_free[TIDY_SHARED_MAX];
shared uint s_rank[TIDY_SHARED_MAX];
TidyLabel tidy_state(uint k) { return s_label[k]; }
float tidy_free(uint k) { return s_free[k]; }
uint tidy_rank(uint k) { return s_rank[k]; }
#ifdef TIDY_SEARCH_ONLY
// (placement_tidy_search.comp: the search reads only the states, free costs and ranks, so its
// workgroups keep 10 KB of shared memory instead of 21.5 and more of them fit an SM)
uint64_t tidy_best(uint k) { return tidy[k].best; }
TidyLabel tidy_next(uint k) { return tidy[k].next; }
uint tidy_partner(uint k) { return tidy[k].partner; }
#else
shared TidyLabel s_next[TIDY_SHARED_MAX];
shared uint64_t s_best[TIDY_SHARED_MAX];
shared uint s_partner[TIDY_SHARED_MAX];
uint64_t tidy_best(uint k) { return s_best[k]; }
TidyLabel tidy_next(uint k) { return s_next[k]; }
uint tidy_partner(uint k) { return s_partner[k]; }
#endif

// The workgroup's copy of the labels' states (the bests only after the search has them).
void load_states(uint n, uint phase) {
  for (uint k = gl_LocalInvocationID.x; k < n; k += gl_WorkGroupSize.x) {
#ifdef TIDY_SEARCH_ONLY
    s_label[k] = tidy[k].label;
    s_free[k] = tidy[k].free;
#else
    const bool taken = tidy_takes(phase) && tidy[k].take != 0u;
    if (taken) {  // (not ?: as in tidy_state of the buffer variant)
      s_label[k] = tidy[k].next;
    } else {
      s_label[k] = tidy[k].label;
    }
    // (the conflicts step reads no free costs)
    s_free[k] = taken && phase == TIDY_PHASE_OUTPUT ? tidy_free_cost(tidy[k].next, labels[k])
                                                    : tidy[k].free;
#endif
    s_rank[k] = tidy[k].rank;
#ifndef TIDY_SEARCH_ONLY
    if (phase != TIDY_PHASE_CONFLICTS && phase != TIDY_PHASE_SEARCH) s_best[k] = tidy[k].best;
    if (phase == TIDY_PHASE_SELECT) {
      s_next[k] = tidy[k].next;
      s_partner[k] = tidy[k].partner;
    }
#endif
  }
  barrier();
}
#endif
shared uint s_any;
shared ivec4 s_conflicts;  // TIDY_PHASE_CONFLICTS: the workgroup's label's, summed

#include "shared/layout_tidy_search.h"

bool movable(uint k) {
  return (tidy_state(k).flags & (TIDY_PLACED | TIDY_MOVABLE)) == (TIDY_PLACED | TIDY_MOVABLE);
}

// The pair at position p of (0, 1), (0, 2) ... (0, n - 1), (1, 2) ...: row i starts at
// i (2n - i - 1) / 2. (The root gives the row to within one or two; integers settle it. A loop
// over the rows cost an invocation up to n steps.)
uvec2 pair_at(uint p, uint n) {
  const float b = float(2u * n - 1u);
  int i = int(floor((b - sqrt(max(b * b - 8.0 * float(p), 0.0))) * 0.5));
  i = clamp(i, 0, int(n) - 2);
  while (i > 0 && uint(i) * (2u * n - uint(i) - 1u) / 2u > p) --i;
  while (uint(i) + 2u < n && (uint(i) + 1u) * (2u * n - uint(i) - 2u) / 2u <= p) ++i;
  const uint row = uint(i);
  return uvec2(row, row + 1u + p - row * (2u * n - row - 1u) / 2u);
}

#ifdef TIDY_SEARCH_ONLY
// TIDY_PHASE_SEARCH: item q is (label, move or hiding) below n x TIDY_SWAP, a pair of labels
// (i < j) above; TIDY_SEARCH_LANES invocations take an item, splitting the other labels.
shared ivec4 s_counts[64 / TIDY_SEARCH_LANES];
shared uint s_hide[64 / TIDY_SEARCH_LANES];

void search(uint t, uint n) {
  const uint q = t / TIDY_SEARCH_LANES, lane = t % TIDY_SEARCH_LANES;
  const uint slot = gl_LocalInvocationID.x / TIDY_SEARCH_LANES;
  const uint singles = n * TIDY_SWAP;
  uint i = 0u, change = 0u;
  bool live = false;
  // (A workgroup whose items could change nothing leaving before it copied the states, deciding
  // that from the buffer, made the tidy-up slower on a GPU.)
  load_states(n, TIDY_PHASE_SEARCH);
  if (q < singles) {
    i = q / TIDY_SWAP;
    change = q % TIDY_SWAP;
    live = tidy[i].conflicted != 0u;
  } else if (q < singles + n * (n - 1u) / 2u) {
    const uvec2 pair = pair_at(q - singles, n);
    i = pair.x;
    change = TIDY_SWAP + pair.y;
    if (movable(pair.x) && movable(pair.y)) {
      const ivec4 c = tidy_conflicts(tidy_state(pair.x), tidy_state(pair.y));
      live = c.x + c.y != 0;
    }
  }
  live = live && tidy_change_possible(i, change);
  if (lane == 0u) {
    s_counts[slot] = ivec4(0);
    s_hide[slot] = 0u;
  }
  barrier();
  if (live) {
    const ivec4 c = tidy_change_conflicts(i, change, lane, TIDY_SEARCH_LANES);
    if (c != ivec4(0)) {
      atomicAdd(s_counts[slot].x, c.x);
      atomicAdd(s_counts[slot].y, c.y);
      atomicAdd(s_counts[slot].z, c.z);
      atomicAdd(s_counts[slot].w, c.w);
    }
    if (change == TIDY_HIDE && tidy_may_hide(i, lane, TIDY_SEARCH_LANES)) atomicOr(s_hide[slot], 1u);
  }
  barrier();
  if (!live || lane != 0u || (change == TIDY_HIDE && s_hide[slot] == 0u)) return;
  const float delta = tidy_change_delta(i, change, s_counts[slot]);
  if (delta >= 0.0f) return;
  atomicMin(tidy[i].best, tidy_key(delta, change));
  if (change >= TIDY_SWAP) atomicMin(tidy[change - TIDY_SWAP].best, tidy_key(delta, TIDY_SWAP + i));
}

void main() {
  // (the search's items can pass 65535 workgroups across: its dispatch is two-dimensional)
  const uint t = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                 gl_LocalInvocationID.x;
  // A round: nothing to do once the round before applied nothing.
  if (rounds[params.step] != 0u) search(t, params.label_count);  // (the same for the whole dispatch)
}
#else
void main() {
  const uint t = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                 gl_LocalInvocationID.x;
  const uint n = params.label_count;
  const uint phase = params.phase;
  if (phase == TIDY_PHASE_START) {
    if (t <= params.tidy_rounds) rounds[t] = t == 0u ? 1u : 0u;
    if (t == 0u && params.tidy_rounds > 0u) write_round_args(0u);  // (the rest start at zero)
    if (t >= n) return;
    tidy[t].label = tidy_label(labels[t], results[t]);
    tidy[t].free = tidy_free_cost(tidy[t].label, labels[t]);
    tidy[t].rank = LABEL_MAX;  // (not in the order)
    tidy[t].take = 0u;
    for (uint k = 0u; k < params.order_count; ++k) {
      if (order[k] == t) tidy[t].rank = k;
    }
    return;
  }
  if (phase == TIDY_PHASE_OUTPUT) {
    load_states(n, phase);
    if (t < n) placements[t] = tidy_placement(t, results[t]);
    return;
  }
  // A round: nothing to do once the round before applied nothing.
  const uint r = params.step;
  if (rounds[r] == 0u) return;  // (the same for the whole dispatch)
  load_states(n, phase);
  if (phase == TIDY_PHASE_CONFLICTS || phase == TIDY_PHASE_SELECT) {
    // One workgroup per label, its invocations splitting the other labels between them.
    const uint i = gl_WorkGroupID.x, lane = gl_LocalInvocationID.x;
    if (lane == 0u) {
      s_any = 0u;
      s_conflicts = ivec4(0);
    }
    barrier();
    bool any = false;
    if (phase == TIDY_PHASE_CONFLICTS) {
      const ivec4 c = tidy_conflicts_of(i, lane, gl_WorkGroupSize.x);
      if (c != ivec4(0)) {
        atomicAdd(s_conflicts.x, c.x);
        atomicAdd(s_conflicts.y, c.y);
        atomicAdd(s_conflicts.z, c.z);
        atomicAdd(s_conflicts.w, c.w);
      }
    } else {
      any = tidy_partner(i) != TIDY_NO_PARTNER && tidy_blocked(i, lane, gl_WorkGroupSize.x);
    }
    if (any) atomicOr(s_any, 1u);
    barrier();
    if (lane != 0u) return;
    if (phase == TIDY_PHASE_CONFLICTS) {
      // (the label's state after the round before, stored: the steps after this one read
      // `label`; `take` stays until the owners step, so every workgroup of this one sees the same)
      if (tidy[i].take != 0u) {
        tidy[i].label = tidy[i].next;
        tidy[i].free = tidy_free_cost(tidy[i].next, labels[i]);
      }
      tidy[i].best = TIDY_NONE;
      tidy[i].conflicts = s_conflicts;
      tidy[i].conflicted = movable(i) && s_conflicts != ivec4(0) ? 1u : 0u;
    } else if (tidy_partner(i) != TIDY_NO_PARTNER && s_any == 0u) {
      // Owner i's change is applied: its labels take their next states.
      tidy[i].take = 1u;
      tidy[tidy_partner(i)].take = 1u;
      atomicAdd(rounds[r + 1u], 1u);
      if (r + 1u < params.tidy_rounds) write_round_args(r + 1u);
    }
    return;
  }
  if (t >= n) return;
  // TIDY_PHASE_OWNERS
  tidy[t].partner = tidy_owned_partner(t);
  tidy[t].next = tidy_after(t);
  tidy[t].take = 0u;
}
#endif
