// The tidy-up's state per label on the GPU (placement.tidy), for C++ and GLSL; apart
// from shared/placement.h since it needs 64-bit integers in GLSL.
#ifndef STRATA_SHARED_TIDY_GPU_H
#define STRATA_SHARED_TIDY_GPU_H

#include "placement.h"

STRATA_BEGIN
// A label's tidy-up state (placement.tidy).
struct TidyGpu {
  TidyLabel label;  // this round
  TidyLabel next;   // after its owner's change (TIDY_PHASE_OWNERS)
  ivec4 conflicts;  // its conflicts with all others this round (TIDY_PHASE_CONFLICTS; 16-byte
                    // aligned here for GLSL, with no padding in C++)
  uint64_t best;    // tidy_key of its best change, or TIDY_NONE
  float free;       // tidy_free_cost of `label`
  uint rank;        // insertion order position
  uint partner;     // as owner: its swap partner, itself, or TIDY_NO_PARTNER (not an owner)
  uint conflicted;  // 1: in some conflict (moves and hiding are searched)
  uint take;        // 1: its owner's change was applied: `next` is its state (set by the
                    // selection, taken into `label` by the next round's conflicts step)
  uint pad;
};
STRATA_END

#endif
