#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#include "shared/tidy_gpu.h"

// The layout tidy-up (shared/layout_tidy.h) and the placements' output, one phase per dispatch
// (params.phase; params.step: the round): its start from the label loop's (cost, pixel) results,
// five dispatches per round, and each label's placement (box centre, cost, shown). A round whose
// round before applied nothing leaves at once.
layout(local_size_x = 64) in;
layout(binding = PLACEMENT_BINDING_TABLES, std430) readonly buffer Tables { float tables[]; };
layout(binding = PLACEMENT_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = PLACEMENT_BINDING_ORDER, std430) readonly buffer Order { uint order[]; };
layout(binding = PLACEMENT_BINDING_RESULTS, std430) readonly buffer Results { uint64_t results[]; };
layout(binding = PLACEMENT_BINDING_PLACEMENTS, std430) writeonly buffer Placements { PlacementGpu placements[]; };
layout(binding = PLACEMENT_BINDING_TIDY, std430) buffer Tidy { TidyGpu tidy[]; };
layout(binding = PLACEMENT_BINDING_TIDY_ROUNDS, std430) buffer Rounds { uint rounds[]; };
layout(push_constant) uniform Push { PlacementParams params; };

float table_at(uint layer, int x, int y) {
  if (x < 0 || y < 0) return 0.0f;
  return tables[(layer * params.height + uint(y)) * params.width + uint(x)];
}

#include "shared/layout_tidy.h"

uint tidy_count() { return params.label_count; }
LabelGpu tidy_input(uint k) { return labels[k]; }
TidyLabel tidy_state(uint k) { return tidy[k].label; }
float tidy_free(uint k) { return tidy[k].free; }
uint tidy_rank(uint k) { return tidy[k].rank; }
uint64_t tidy_best(uint k) { return tidy[k].best; }
TidyLabel tidy_next(uint k) { return tidy[k].next; }
uint tidy_partner(uint k) { return tidy[k].partner; }

#include "shared/layout_tidy_search.h"

bool movable(uint k) {
  return (tidy[k].label.flags & (TIDY_PLACED | TIDY_MOVABLE)) == (TIDY_PLACED | TIDY_MOVABLE);
}

// TIDY_PHASE_SEARCH: item q is (label, move or hiding) below n x TIDY_SWAP, a pair of labels above.
void search(uint q, uint n) {
  const uint singles = n * TIDY_SWAP;
  if (q < singles) {
    const uint i = q / TIDY_SWAP, change = q % TIDY_SWAP;
    if (tidy[i].conflicted == 0u) return;
    const float delta = tidy_delta(i, change);
    if (delta < 0.0f) atomicMin(tidy[i].best, tidy_key(delta, change));
    return;
  }
  const uint i = (q - singles) / n, j = (q - singles) % n;
  if (j <= i || !movable(i) || !movable(j)) return;
  const ivec4 c = tidy_conflicts(tidy[i].label, tidy[j].label);
  if (c.x + c.y == 0) return;
  const float delta = tidy_delta(i, TIDY_SWAP + j);
  if (delta >= 0.0f) return;
  atomicMin(tidy[i].best, tidy_key(delta, TIDY_SWAP + j));
  atomicMin(tidy[j].best, tidy_key(delta, TIDY_SWAP + i));
}

void main() {
  const uint t = gl_GlobalInvocationID.x;
  const uint n = params.label_count;
  const uint phase = params.phase;
  if (phase == TIDY_PHASE_START) {
    if (t <= params.tidy_rounds) rounds[t] = t == 0u ? 1u : 0u;
    if (t >= n) return;
    tidy[t].label = tidy_label(labels[t], results[t]);
    tidy[t].free = tidy_free_cost(tidy[t].label, labels[t]);
    tidy[t].rank = LABEL_MAX;
    for (uint k = 0u; k < params.order_count; ++k) {
      if (order[k] == t) tidy[t].rank = k;
    }
    return;
  }
  if (phase == TIDY_PHASE_OUTPUT) {
    if (t >= n) return;
    const TidyLabel l = tidy[t].label;
    const uint64_t r = results[t];
    PlacementGpu p = hidden_placement(labels[t]);
    if ((l.flags & TIDY_PLACED) != 0u) {
      const bool kept = r != PLACEMENT_NONE && l.pixel == uint(r & 0xFFFFFFFFul);
      const float cost = kept ? uintBitsToFloat(uint(r >> 32))
                              : tidy[t].free + tidy_weight(tidy_all_conflicts(t));
      p = shown_placement(labels[t], l.pixel, cost, params.width);
    }
    placements[t] = p;
    return;
  }
  // A round: nothing to do once the round before applied nothing.
  const uint r = params.step;
  if (rounds[r] == 0u) return;
  if (phase == TIDY_PHASE_SEARCH) {
    search(t, n);
    return;
  }
  if (t >= n) return;
  if (phase == TIDY_PHASE_CONFLICTS) {
    tidy[t].best = TIDY_NONE;
    tidy[t].conflicted = movable(t) && tidy_conflicted(t) ? 1u : 0u;
  } else if (phase == TIDY_PHASE_OWNERS) {
    tidy[t].partner = tidy_owned_partner(t);
    tidy[t].next = tidy_after(t);
  } else if (phase == TIDY_PHASE_SELECT) {
    tidy[t].applied = tidy[t].partner != TIDY_NO_PARTNER && !tidy_blocked(t) ? 1u : 0u;
  } else if (phase == TIDY_PHASE_APPLY) {
    const uint owner = tidy_owner(t);
    if (owner == TIDY_NO_PARTNER || tidy[owner].applied == 0u) return;
    tidy[t].label = tidy[t].next;
    tidy[t].free = tidy_free_cost(tidy[t].next, labels[t]);
    if (owner == t) atomicAdd(rounds[r + 1u], 1u);
  }
}
