// Included by place_label.comp (its MAIN and SPEC workgroups: the main pass's tiles of the label
// at order position j - 1, the speculative pass's of the label at position j) and by
// place_rounds.comp (EVALUATE): a workgroup evaluates a tile of 32x32 candidates. Each
// invocation takes PLACE_SPAN_X x PLACE_SPAN_Y candidates; a tile's constraints are culled once
// for all of them (cull), and the workgroup returns its lowest (cost, pixel). The includer says
// which labels constrain: `placed` of them, regions_of(position, s) against the s-th.

// The tile's candidate-reaching placed labels and anchors of the chunk from `from` (placed labels
// by the includer's numbering, indices of anchors), and the constraints all of its candidates
// have (the shared counts start at 0; a barrier follows).
void cull(LabelGpu me, uvec2 tile, uint from) {
  vec2 centre, extent;
  tile_centres(me, tile, centre, extent);
  const uint threads = PLACE_GROUP_X * PLACE_GROUP_Y;
  const uint placed_end = min(placed, from + PLACE_CULL_CHUNK);
  for (uint s = from + gl_LocalInvocationIndex; s < placed_end; s += threads) {
    uint touch, full;
    region_reach(regions_of(position, s), centre, extent, touch, full);
    if (full != 0u) atomicOr(tile_bits, full);
    if ((touch & ~full) != 0u) tile_placed[atomicAdd(tile_placed_count, 1u)] = s;
  }
  // Anchors: a candidate's box (margin included) covering one.
  const vec2 h = constraint_half_size(me, params.margin);
  const uint anchors_end = min(params.label_count, from + PLACE_CULL_CHUNK);
  for (uint k = from + gl_LocalInvocationIndex; k < anchors_end; k += threads) {
    if ((labels[k].flags & LABEL_ENABLED) == 0u) continue;
    const vec2 d = abs(labels[k].anchor - centre);
    if (d.x > extent.x + h.x + 1.0 || d.y > extent.y + h.y + 1.0) continue;
    if (anchor_covers_rectangle(labels[k].anchor, centre, extent, h)) atomicOr(tile_bits, CONSTRAINT_ANCHOR);
    else tile_anchors[atomicAdd(tile_anchor_count, 1u)] = labels[k].anchor;
  }
}

// The pixel of an invocation's candidate q: SPAN_X x SPAN_Y of them from `base`, a workgroup's
// width or height apart (neighbouring invocations read neighbouring table entries).
uvec2 candidate_pixel(uvec2 base, uint q) {
  return base + uvec2(q % PLACE_SPAN_X, q / PLACE_SPAN_X) * uvec2(PLACE_GROUP_X, PLACE_GROUP_Y);
}

// constraint_bits() for the invocation's candidates (bit q of `wanted`) at once, over the
// culled chunk in the tile's lists (the bits and the rejected candidates carry over from the
// chunks before): one pass over its labels and anchors, each region loaded once for all
// candidates (four passes made a chain of four times as many dependent loads). A candidate leaves
// the pass when it has both shadow bits or weighs more than its budget, as constraint_bits()
// returns there; the bits that decide (rejected, or the cost's weight) are the same, whatever
// the chunks, since each kind of bit is found or not; with an infinite budget all of them.
void candidate_bits(LabelGpu me, vec2 centres[PLACE_SPAN_X * PLACE_SPAN_Y], uint wanted,
                    float budgets[PLACE_SPAN_X * PLACE_SPAN_Y],
                    inout uint bits[PLACE_SPAN_X * PLACE_SPAN_Y], inout uint rejected) {
  const uint shadows = CONSTRAINT_LABEL | CONSTRAINT_CONNECTOR;
  uint open = 0u;  // candidates still taking the placed labels
  [[unroll]] for (uint q = 0u; q < PLACE_SPAN_X * PLACE_SPAN_Y; ++q) {
    bits[q] |= tile_bits;
    if ((wanted & ~rejected & (1u << q)) != 0u && (bits[q] & shadows) != shadows) open |= 1u << q;
  }
  for (uint k = 0u; k < placed_count() && open != 0u; ++k) {
    const PairRegionsGpu r = placed_regions(k);
    [[unroll]] for (uint q = 0u; q < PLACE_SPAN_X * PLACE_SPAN_Y; ++q) {
      if ((open & (1u << q)) == 0u) continue;
      bits[q] |= region_bits(r, centres[q], bits[q]);
      if (constraint_weight(bits[q]) > budgets[q]) {
        rejected |= 1u << q;
        open &= ~(1u << q);
      } else if ((bits[q] & shadows) == shadows) {
        open &= ~(1u << q);
      }
    }
  }
  if ((me.flags & LABEL_INTERNAL) != 0u) return;
  const vec2 h = constraint_half_size(me, params.margin);
  uint seeking = 0u;  // candidates that may still cover an anchor
  [[unroll]] for (uint q = 0u; q < PLACE_SPAN_X * PLACE_SPAN_Y; ++q) {
    if ((wanted & ~rejected & (1u << q)) != 0u && (bits[q] & CONSTRAINT_ANCHOR) == 0u) {
      seeking |= 1u << q;
    }
  }
  for (uint k = 0u; k < anchor_count() && seeking != 0u; ++k) {
    const vec2 a = anchor_at(k);
    [[unroll]] for (uint q = 0u; q < PLACE_SPAN_X * PLACE_SPAN_Y; ++q) {
      const vec2 d = abs(a - centres[q]);
      if ((seeking & (1u << q)) != 0u && d.x <= h.x && d.y <= h.y) {
        bits[q] |= CONSTRAINT_ANCHOR;
        seeking &= ~(1u << q);
        if (constraint_weight(bits[q]) > budgets[q]) rejected |= 1u << q;
      }
    }
  }
}

// Each of the invocation's candidates' cost without constraints, and (bit q) those allowed and
// not above `best`; the tile's constraints are culled meanwhile. (Every candidate's cost is
// computed, allowed or not, so that nothing waits on the tests; the culling is done whether or
// not a candidate turns out worth it.)
uint hopeful_candidates(LabelGpu me, uvec2 tile, uvec2 base, float best,
                        out float free_costs[PLACE_SPAN_X * PLACE_SPAN_Y]) {
  uint candidates = 0u;
  [[unroll]] for (uint q = 0u; q < PLACE_SPAN_X * PLACE_SPAN_Y; ++q) {
    const uvec2 p = candidate_pixel(base, q);
    const vec2 origin = box_origin(p, me.size);
    free_costs[q] = free_cost(me, origin, origin + me.size * 0.5);
    const bool allowed = p.x < params.width && p.y < params.height && candidate_allowed(me, p);
    if (allowed && !(free_costs[q] > best)) candidates |= 1u << q;
  }
  if (subgroupOr(candidates) != 0u && subgroupElect()) atomicOr(tile_hope, 1u);
  cull(me, tile, 0u);
  return candidates;
}

// The lowest (cost, pixel) of the invocation's candidates (bit q of `candidates`) whose bits weigh
// no more than their budget; with `write`, every one's bits go to the constraint image.
uint64_t lowest_key(uvec2 base, uint candidates, bool hopeless, bool write,
                    float free_costs[PLACE_SPAN_X * PLACE_SPAN_Y],
                    float budgets[PLACE_SPAN_X * PLACE_SPAN_Y],
                    uint all_bits[PLACE_SPAN_X * PLACE_SPAN_Y]) {
  uint64_t key = PLACEMENT_NONE;
  [[unroll]] for (uint q = 0u; q < PLACE_SPAN_X * PLACE_SPAN_Y; ++q) {
    if (hopeless) break;
    if ((candidates & (1u << q)) == 0u) continue;
    const uvec2 p = candidate_pixel(base, q);
    const float budget = budgets[q];
    const uint bits = all_bits[q];
    const uint pixel = p.y * params.width + p.x;
    if (write) constraints[pixel] = bits;
    if (constraint_weight(bits) > budget) continue;
    if (params.hard == 0u || bits == 0u) {
      const float cost = free_costs[q] + constraint_weight(bits);
      key = min(key, (uint64_t(floatBitsToUint(cost)) << 32) | uint64_t(pixel));  // costs >= 0
    }
  }
  return key;
}

// The workgroup's lowest key: lowest cost, then lowest pixel index (the subgroup's minimum cost,
// then the first pixel with it; then the lowest of the subgroups').
uint64_t workgroup_lowest(uint64_t key) {
  const uint cost_bits = uint(key >> 32);
  const uint best_bits = subgroupMin(cost_bits);
  const uint best_pixel = subgroupMin(cost_bits == best_bits ? uint(key) : 0xFFFFFFFFu);
  if (subgroupElect()) group_best[gl_SubgroupID] = (uint64_t(best_bits) << 32) | uint64_t(best_pixel);
  barrier();
  uint64_t group = PLACEMENT_NONE;
  for (uint k = 0u; k < gl_NumSubgroups; ++k) group = min(group, group_best[k]);
  return group;
}

// The tile's lowest (cost, pixel): every candidate for a speculative pass; for the main pass,
// only those whose cost is not above the best known (`bound`: the tile's lower bound).
uint64_t evaluate_tile(uint label, uvec2 tile, uint known, float bound, bool prune, float best_bound,
                       bool write) {
  const LabelGpu me = labels[label];
  const uvec2 base = tile * PLACEMENT_TILE + gl_LocalInvocationID.xy;
  // A candidate can only win if its cost is not above the best another workgroup has found
  // (strictly above: ties cannot be lost either): first the tile's bound from
  // placement_bounds.comp, then each candidate's cost without constraints (constraint terms only
  // add, and rounded sums are monotonic), then with the constraints the whole tile has.
  if (gl_LocalInvocationIndex == 0u) {
    tile_best = prune ? results[label] : PLACEMENT_NONE;
    tile_hope = 0u;
    tile_placed_count = 0u;
    tile_anchor_count = 0u;
    tile_bits = known;
  }
  barrier();
  const float best = prune ? min(cost_of(tile_best), best_bound) : uintBitsToFloat(0x7F800000u);
  bool hopeless = prune && bound > best;
  float free_costs[PLACE_SPAN_X * PLACE_SPAN_Y];
  uint candidates = 0u;  // bit q: candidate q is worth its constraints
  if (!hopeless) candidates = hopeful_candidates(me, tile, base, best, free_costs);
  barrier();
  hopeless = tile_hope == 0u ||
             (prune && (0.9999 * (bound + constraint_weight(tile_bits)) > best ||
                        (params.hard != 0u && tile_bits != 0u)));
  // Bits weighing more than best - cost without them lose (strictly: 0.999), so the search
  // stops there (hard mode: at the first); all of them otherwise.
  vec2 centres[PLACE_SPAN_X * PLACE_SPAN_Y];
  float budgets[PLACE_SPAN_X * PLACE_SPAN_Y];
  [[unroll]] for (uint q = 0u; q < PLACE_SPAN_X * PLACE_SPAN_Y; ++q) {
    const vec2 origin = box_origin(candidate_pixel(base, q), me.size);
    centres[q] = origin + me.size * 0.5;
    budgets[q] = !prune              ? 1.0 / 0.0
                 : params.hard != 0u ? 0.0
                                     : (best - free_costs[q]) / 0.999;
  }
  uint all_bits[PLACE_SPAN_X * PLACE_SPAN_Y];
  [[unroll]] for (uint q = 0u; q < PLACE_SPAN_X * PLACE_SPAN_Y; ++q) all_bits[q] = 0u;
  uint rejected = 0u;
  const uint wanted = hopeless ? 0u : candidates;
  candidate_bits(me, centres, wanted, budgets, all_bits, rejected);
  // Past PLACE_CULL_CHUNK labels, the next chunks in turn (`hopeless` is the workgroup's).
  for (uint from = PLACE_CULL_CHUNK; !hopeless && from < params.label_count;
       from += PLACE_CULL_CHUNK) {
    barrier();  // (the lists are read)
    if (gl_LocalInvocationIndex == 0u) {
      tile_placed_count = 0u;
      tile_anchor_count = 0u;
    }
    barrier();
    cull(me, tile, from);
    barrier();
    candidate_bits(me, centres, wanted, budgets, all_bits, rejected);
  }
  const uint64_t key = lowest_key(base, candidates, hopeless, write, free_costs, budgets, all_bits);
  return workgroup_lowest(key);
}
