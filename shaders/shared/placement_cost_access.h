// What placement_cost.h reads from its includer, besides placement_free_cost_access.h's, stated
// once: a concept in C++, declarations in GLSL (placement_free_cost_access.h says why).
#ifndef STRATA_SHARED_PLACEMENT_COST_ACCESS_H
#define STRATA_SHARED_PLACEMENT_COST_ACCESS_H

#include "placement_free_cost_access.h"

#ifdef __cplusplus
STRATA_BEGIN
template <typename T>
concept PlacementCostAccess = PlacementFreeCostAccess<T> && requires(const T& t, uint k) {
  // how many placed labels to test against (all placed so far, or the ones a GPU tile's
  // candidates can reach) ...
  { t.placed_count() } -> std::same_as<uint>;
  // ... and the k-th one's regions (pair_regions)
  { t.placed_regions(k) } -> std::same_as<PairRegionsGpu>;
  // how many anchors to test against (shown labels') ...
  { t.anchor_count() } -> std::same_as<uint>;
  // ... and where the k-th is
  { t.anchor_at(k) } -> std::same_as<vec2>;
};
STRATA_END
#else
uint placed_count();
PairRegionsGpu placed_regions(uint k);
uint anchor_count();
vec2 anchor_at(uint k);
#endif

#endif
