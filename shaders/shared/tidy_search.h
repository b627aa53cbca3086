// One round of the tidy-up (tidy.h), written once for the GPU and the CPU:
//   1. every label's best change (tidy_key of its J change and the change id; none when no change
//      lowers J): moves and hiding for labels in some conflict, swaps for pairs whose leaders
//      cross or run through the other's box;
//   2. owners: a label whose best change is a move or hiding, or the lower of two labels whose
//      best changes are the same swap;
//   3. an owner's change is applied unless a better owner's (lower key; ties: lower label)
//      interacts with it: applying both would change J by more than the sum of their changes
//      (some pair of their labels conflicts differently). So every applied pair of changes adds
//      at most its own changes and J falls every round; the best owner is always applied.
// What the includer provides, besides tidy.h's needs (the labels, their states, the steps'
// results), is tidy_search_access.h.

#ifndef __cplusplus
#include "tidy_search_access.h"  // (C++: the reference's struct is checked against it)
#endif

// Label i's conflicts with the others of first, first + stride, ... (the GPU splits the labels
// over a workgroup's invocations). (Conflict counts are symmetric: tidy_conflicts(a, b) ==
// tidy_conflicts(b, a).)
ivec4 tidy_conflicts_of(uint i, uint first, uint stride) {
  TidyLabel l = tidy_state(i);
  ivec4 reach = tidy_extent(l);
  ivec4 sum = ivec4(0);
  for (uint k = first; k < tidy_count(); k += stride) {
    if (k == i) continue;
    TidyLabel other = tidy_state(k);
    if (tidy_rects_touch(reach, tidy_extent(other))) sum += tidy_conflicts(l, other);
  }
  return sum;
}

// How label i's conflicts with the others (but `skip`) change when it goes from its state
// (`from`) to `to`. The part whose first is 0 takes all of `from`'s at once (tidy_conflicts_now,
// less skip's); the others of first, first + stride, ... are weighed against `to` only. (Weighing
// each against both, as the search once did, took most of a round: docs/performance.md.)
ivec4 tidy_conflict_change(uint i, TidyLabel from, TidyLabel to, uint skip, uint first,
                           uint stride) {
  ivec4 change = ivec4(0);
  ivec4 reach = tidy_extent(to);
  for (uint k = first; k < tidy_count(); k += stride) {
    if (k == i || k == skip) continue;
    TidyLabel other = tidy_state(k);
    if (tidy_rects_touch(reach, tidy_extent(other))) change += tidy_conflicts(to, other);
  }
  if (first == 0u) {
    change -= tidy_conflicts_now(i);
    if (skip != TIDY_NO_PARTNER) change += tidy_conflicts(from, tidy_state(skip));
  }
  return change;
}

// Label i's state after change `change` (itself when the change is not possible).
TidyLabel tidy_changed(uint i, uint change) {
  TidyLabel l = tidy_state(i);
  if (change == TIDY_HIDE) {
    l.flags &= ~TIDY_PLACED;
    return l;
  }
  if (change < TIDY_MOVES) return tidy_move(l, tidy_input(i), change);
  return tidy_centred(l, tidy_input(i), tidy_centre(tidy_state(change - TIDY_SWAP)));
}

// May label i be hidden? Only when its box shares area with the box of a label earlier in the
// insertion order (so of higher priority) or covers an anchor (of the labels first, first +
// stride, ...), and nothing better is found.
bool tidy_may_hide(uint i, uint first, uint stride) {
  TidyLabel l = tidy_state(i);
  for (uint k = first; k < tidy_count(); k += stride) {
    if (k == i) continue;
    TidyLabel other = tidy_state(k);
    if (tidy_covers(l, other)) return true;
    if ((other.flags & TIDY_PLACED) != 0u && tidy_rank(k) < tidy_rank(i) &&
        tidy_conflicts(l, other).z != 0) {
      return true;
    }
  }
  return false;
}

// Does a change of conflict counts put boxes on more boxes or anchors (where those weigh)?
bool tidy_adds_hard(ivec4 c) {
  return (c.z > 0 && params.weights.label_shadow > 0.0f) ||
         (c.w > 0 && params.weights.anchor_constraint > 0.0f);
}

// Label i's change `change` in parts, so that the GPU can split the sums over the other labels
// between invocations: whether it is possible at all (moves somewhere new; hiding a shown label),
// the conflict counts it changes (over the labels first, first + stride, ...; the swapped pair's
// own term with the part whose first is 0), and J's change from those counts.
bool tidy_change_possible(uint i, uint change) {
  TidyLabel from = tidy_state(i), to = tidy_changed(i, change);
  if (change == TIDY_HIDE) return to.flags != from.flags;
  if (to.pixel == from.pixel) return false;
  if (change < TIDY_SWAP) return true;
  uint j = change - TIDY_SWAP;
  return tidy_changed(j, TIDY_SWAP + i).pixel != tidy_state(j).pixel;
}

ivec4 tidy_change_conflicts(uint i, uint change, uint first, uint stride) {
  TidyLabel from = tidy_state(i), to = tidy_changed(i, change);
  if (change < TIDY_SWAP) return tidy_conflict_change(i, from, to, TIDY_NO_PARTNER, first, stride);
  uint j = change - TIDY_SWAP;
  TidyLabel from_j = tidy_state(j), to_j = tidy_changed(j, TIDY_SWAP + i);
  ivec4 c = tidy_conflict_change(i, from, to, j, first, stride) +
            tidy_conflict_change(j, from_j, to_j, i, first, stride);
  if (first == 0u) c += tidy_conflicts(to, to_j) - tidy_conflicts(from, from_j);
  return c;
}

// J's change for a possible change whose conflict counts change by `conflicts`; 0 (never a gain)
// when it would make more boxes share area or cover more anchors: those stay as hard as in the
// placement, whose label shadow and anchor weights outweigh any position (a label in very salient
// content could otherwise buy its way onto another's box).
float tidy_change_delta(uint i, uint change, ivec4 conflicts) {
  if (tidy_adds_hard(conflicts)) return 0.0f;
  TidyLabel to = tidy_changed(i, change);
  float weight = tidy_weight(conflicts);
  if (change < TIDY_SWAP) {
    float hiding = change == TIDY_HIDE ? params.weights.label_shadow : 0.0f;
    return (tidy_free_cost(to, tidy_input(i)) + hiding - tidy_free(i)) + weight;
  }
  uint j = change - TIDY_SWAP;
  float before = tidy_free(i) + tidy_free(j);
  float after = tidy_free_cost(to, tidy_input(i)) +
                tidy_free_cost(tidy_changed(j, TIDY_SWAP + i), tidy_input(j));
  return (after - before) + weight;
}

// J's change for label i's change `change` in one piece (the CPU reference); 0 when it is not
// possible.
float tidy_delta(uint i, uint change) {
  if (!tidy_change_possible(i, change)) return 0.0f;
  if (change == TIDY_HIDE && !tidy_may_hide(i, 0u, 1u)) return 0.0f;
  return tidy_change_delta(i, change, tidy_change_conflicts(i, change, 0u, 1u));
}

// Is i's best change a swap with j (whatever its key)?
bool tidy_best_swaps_with(uint i, uint j) {
  uint64_t best = tidy_best(i);
  return best != TIDY_NONE && uint(best & 0xFFFFFFFFul) == TIDY_SWAP + j;
}

// Step 2: the change label i owns, as its partner: i itself for a move or hiding, the other
// label of a swap; TIDY_NO_PARTNER when i owns none. (tidy_best only.)
uint tidy_owned_partner(uint i) {
  uint64_t best = tidy_best(i);
  if (best == TIDY_NONE) return TIDY_NO_PARTNER;
  uint change = uint(best & 0xFFFFFFFFul);
  if (change < TIDY_SWAP) return i;
  uint j = change - TIDY_SWAP;
  return i < j && tidy_best_swaps_with(j, i) ? j : TIDY_NO_PARTNER;
}

// Step 2: label i's owner: i, the owner of the swap i is the higher label of, or TIDY_NO_PARTNER.
uint tidy_owner(uint i) {
  if (tidy_owned_partner(i) != TIDY_NO_PARTNER) return i;
  uint64_t best = tidy_best(i);
  if (best == TIDY_NONE || uint(best & 0xFFFFFFFFul) < TIDY_SWAP) return TIDY_NO_PARTNER;
  uint j = uint(best & 0xFFFFFFFFul) - TIDY_SWAP;
  return tidy_owned_partner(j) == i ? j : TIDY_NO_PARTNER;
}

// Step 2: label i's state after its owner's change (itself when it has no owner).
TidyLabel tidy_after(uint i) {
  uint owner = tidy_owner(i);
  if (owner == TIDY_NO_PARTNER) return tidy_state(i);
  if (owner != i) return tidy_changed(i, TIDY_SWAP + owner);
  return tidy_changed(i, uint(tidy_best(i) & 0xFFFFFFFFul));
}

// How much more J changes with both labels a and b changed than the two changes alone counted.
// (The four terms in a loop, as the pairs in tidy_blocked: one copy of tidy_conflicts, not
// sixteen, which shader compilers inline: on lavapipe that was most of the pipeline's creation.)
ivec4 tidy_pair_correction(uint a, uint b) {
  TidyLabel a0 = tidy_state(a), a1 = tidy_next(a), b0 = tidy_state(b), b1 = tidy_next(b);
  ivec4 reach = tidy_union(tidy_extent(a0), tidy_extent(a1));
  if (!tidy_rects_touch(reach, tidy_union(tidy_extent(b0), tidy_extent(b1)))) return ivec4(0);
  ivec4 c = ivec4(0);
  for (uint k = 0u; k < 4u; ++k) {
    // (a1, b1) and (a0, b0) add, the mixed pairs subtract
    TidyLabel x = a1, y = b1;
    if ((k & 1u) != 0u) x = a0;
    if ((k & 2u) != 0u) y = b0;
    ivec4 term = tidy_conflicts(x, y);
    if (k == 1u || k == 2u) c -= term;
    else c += term;
  }
  return c;
}

// Step 3: is owner i's change held back by a better owner's (of first, first + stride, ...) that
// interacts with it?
bool tidy_blocked(uint i, uint first, uint stride) {
  uint64_t key = tidy_best(i);
  uint pi = tidy_partner(i);
  for (uint l = first; l < tidy_count(); l += stride) {
    uint pl = tidy_partner(l);
    if (l == i || pl == TIDY_NO_PARTNER) continue;
    uint64_t other = tidy_best(l);
    if (other > key || (other == key && l > i)) continue;
    // (i or its partner against l or its partner: the pairs a swap adds)
    ivec4 c = ivec4(0);
    for (uint k = 0u; k < 4u; ++k) {
      if (((k & 1u) != 0u && pl == l) || ((k & 2u) != 0u && pi == i)) continue;
      c += tidy_pair_correction((k & 2u) != 0u ? pi : i, (k & 1u) != 0u ? pl : l);
    }
    if (tidy_adds_hard(c) || tidy_weight(c) > 0.0f) return true;
  }
  return false;
}

// Label i's placement after the tidy-up, from the label loop's (cost bits << 32 | pixel) result:
// hidden, kept with the loop's cost, or moved, costing its free cost plus its conflicts' weights.
PlacementGpu tidy_placement(uint i, uint64_t result) {
  TidyLabel l = tidy_state(i);
  if ((l.flags & TIDY_PLACED) == 0u) return hidden_placement(tidy_input(i));
  bool kept = result != PLACEMENT_NONE && l.pixel == uint(result & 0xFFFFFFFFul);
  float cost = kept ? uintBitsToFloat(uint(result >> 32))
                    : tidy_free(i) + tidy_weight(tidy_conflicts_of(i, 0u, 1u));
  return shown_placement(tidy_input(i), l.pixel, cost, params.width);
}
