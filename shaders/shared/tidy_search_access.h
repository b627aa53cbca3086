// What tidy_search.h reads from its includer, besides tidy.h's (placement_free_cost_access.h),
// stated once: a concept in C++, declarations in GLSL (placement_free_cost_access.h says why).
#ifndef STRATA_SHARED_TIDY_SEARCH_ACCESS_H
#define STRATA_SHARED_TIDY_SEARCH_ACCESS_H

#include "placement_free_cost_access.h"

#ifdef __cplusplus
STRATA_BEGIN
template <typename T>
concept TidySearchAccess = PlacementFreeCostAccess<T> && requires(const T& t, uint k) {
  { t.tidy_count() } -> std::same_as<uint>;        // labels
  { t.tidy_input(k) } -> std::same_as<LabelGpu>;   // the label as placed
  { t.tidy_state(k) } -> std::same_as<TidyLabel>;  // its state this round
  { t.tidy_free(k) } -> std::same_as<float>;       // tidy_free_cost of that state
  { t.tidy_rank(k) } -> std::same_as<uint>;        // its insertion order position
  { t.tidy_best(k) } -> std::same_as<uint64_t>;    // step 1's result (steps 2 and 3)
  // its state after its owner's change (itself if none; step 3)
  { t.tidy_next(k) } -> std::same_as<TidyLabel>;
  // an owner's swap partner (TIDY_NO_PARTNER: none; step 3)
  { t.tidy_partner(k) } -> std::same_as<uint>;
  // tidy_conflicts_of(k, 0, 1) this round (step 1)
  { t.tidy_conflicts_now(k) } -> std::same_as<ivec4>;
};
STRATA_END
#else
uint tidy_count();
LabelGpu tidy_input(uint k);
TidyLabel tidy_state(uint k);
float tidy_free(uint k);
uint tidy_rank(uint k);
uint64_t tidy_best(uint k);
TidyLabel tidy_next(uint k);
uint tidy_partner(uint k);
ivec4 tidy_conflicts_now(uint k);
#endif

#endif
