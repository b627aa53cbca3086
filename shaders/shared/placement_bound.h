// A lower bound of eq. 3.1 over a rectangle of candidates, written once for placement_bounds.comp
// and the CPU reference of the rounds (passes/placement_reference.cpp), which must agree to the
// last bit on which tiles a label's rounds search. What the includer provides (params, table_at)
// is placement_free_cost_access.h.

#ifndef __cplusplus
#include "placement_free_cost_access.h"  // (C++: the reference's struct is checked against it)
#endif

// Candidates p of first..last (pixels) may hold the label when its box [p - floor(size / 2),
// + size) lies on screen (internal labels: only the anchor's pixel).
bool has_candidates(LabelGpu me, uvec2 first, uvec2 last) {
  if ((me.flags & LABEL_INTERNAL) != 0u) {
    uvec2 a = uvec2(me.anchor);
    return all(greaterThanEqual(a, first)) && all(lessThanEqual(a, last));
  }
  vec2 half_size = floor(me.size * 0.5f);
  vec2 lo = max(vec2(first), half_size);
  vec2 hi = min(vec2(last), vec2(float(params.width), float(params.height)) - me.size + half_size);
  return all(lessThanEqual(lo, hi));
}

// Eq. 3.1 over the candidates first..last (pixels) is at least: the distance terms at their
// nearest box centre, direction 1, no constraints, and the integral costs over the part all their
// boxes share (costs are >= 0). The table's float sums of two boxes may differ from their true
// order by a few ulps of the table's largest value, so that much is taken off the shared part;
// the rest is scaled by 0.9999 against rounding in the candidates' own sums. Internal labels have
// one candidate: 0. No candidate: infinity.
float cell_bound(LabelGpu me, uvec2 first, uvec2 last) {
  if (!has_candidates(me, first, last)) return uintBitsToFloat(0x7F800000u);
  if ((me.flags & LABEL_INTERNAL) != 0u) return 0.0f;
  CostWeightsGpu w = params.weights;
  vec2 lo_centre = box_origin(first, me.size) + me.size * 0.5f;
  vec2 hi_centre = box_origin(last, me.size) + me.size * 0.5f;
  vec2 to_anchor = max(max(lo_centre - me.anchor, me.anchor - hi_centre), vec2(0.0f));
  vec2 to_previous = max(max(lo_centre - me.previous, me.previous - hi_centre), vec2(0.0f));
  // The hold is added unless the held position is one of the cell's candidates' centres.
  vec2 to_held = max(max(lo_centre - me.held, me.held - hi_centre), vec2(0.0f));
  float hold = any(greaterThan(to_held, vec2(0.5f))) ? me.hold : 0.0f;
  float bound = 0.9999f * (w.distance_to_anchor * length(to_anchor) + w.connector_direction +
                           w.previous_position * length(to_previous) + hold);
  vec2 shared_lo = max(box_origin(last, me.size), vec2(0.0f));
  vec2 shared_hi = min(box_origin(first, me.size) + me.size,
                       vec2(float(params.width), float(params.height)));
  if (all(lessThan(shared_lo, shared_hi))) {
    ivec2 a = ivec2(shared_lo), b = ivec2(shared_hi) - ivec2(1);
    float sum = table_at(me.layer, b.x, b.y) - table_at(me.layer, a.x - 1, b.y) -
                table_at(me.layer, b.x, a.y - 1) + table_at(me.layer, a.x - 1, a.y - 1);
    float slack = 1e-4f * table_at(me.layer, int(params.width) - 1, int(params.height) - 1);
    bound += w.integral_costs * max(sum - slack, 0.0f);
  }
  return bound;
}

// A tile's bound: the lowest of its cells' of PLACEMENT_CELL x PLACEMENT_CELL candidates (the
// integral part needs cells smaller than the label boxes: what all boxes of a whole tile share is
// often nothing). Cell c counts across the tile, row by row.
float tile_cell_bound(LabelGpu me, uint tile, uint c) {
  uint tiles_x = placement_tiles(params.width, params.height).x;
  uint cells_x = uint(PLACEMENT_TILE / PLACEMENT_CELL);
  uvec2 first = uvec2(tile % tiles_x, tile / tiles_x) * uint(PLACEMENT_TILE) +
                uvec2(c % cells_x, c / cells_x) * uint(PLACEMENT_CELL);
  return cell_bound(me, first, first + uvec2(uint(PLACEMENT_CELL) - 1u));
}

// The buckets of a label's tile list that its rounds search (placement_rounds.h): all up to the
// last whose running count stays within `budget` tiles, bucket 0 always. Returns their tiles.
uint rounds_searched_tiles(PlacementBucketsGpu b, uint budget) {
  uint total = b.counts[0];
  for (uint k = 1u; k < uint(PLACEMENT_BUCKETS); ++k) {
    if (total + b.counts[k] > budget) break;
    total += b.counts[k];
  }
  return total;
}
