// The greedy placement in parallel rounds, written once for place_rounds.comp and the CPU
// reference (passes/placement_reference.cpp); included after placement_cost.h.
//
// Every label of the insertion order starts undecided. In a round, each undecided label takes its
// cheapest candidate (eq. 3.1) against the labels decided in earlier rounds, over the tiles its
// rounds search (rounds_searched_tiles; with PlacementSettings::wide_search, all of its tiles
// where those hold no position a label wants: rounds_wide_cost). Then the round decides labels
// in ROUNDS_SELECT_PASSES passes over the undecided ones. A label whose choice and an earlier
// undecided label's constrain each other (rounds_conflict) depends on it (earlier: in insertion
// order); a label while a label of a higher priority is undecided waits. In each pass, a label is
// decided when every label it depends on was left out in the pass before, and left out when one
// of them was decided in the pass before; labels still open after the passes wait. (Passes
// without end would find the first maximal independent set, in insertion order, of the graph of
// conflicting choices: what the sequential greedy keeps of the round's choices.) The first
// undecided label is always decided, so every round decides one at least, and labels decided in
// one round never constrain each other: each one's choice is what it would be with the others
// decided first. A label's choice
// stands while no newly decided label constrains it (costs only grow as labels are decided), so
// the GPU searches again only for those (place_rounds.comp).

// A label whose best over the tiles its rounds search (rounds_searched_tiles) costs this much or
// more (it overlaps a decided label's box, covers an anchor or is illegible; or has none) searches
// the rest of its tile list too.
float rounds_wide_cost() {
  CostWeightsGpu w = params.weights;
  return min(min(w.label_shadow, w.anchor_constraint), w.illegible);
}

// Label me's box centre for the result key (z = 1), or 0 for none.
vec3 key_placed(LabelGpu me, uint64_t key) {
  if (key == PLACEMENT_NONE) return vec3(0.0f);
  uint pixel = uint(key & 0xFFFFFFFFul);
  uvec2 p = uvec2(pixel % params.width, pixel / params.width);
  return vec3(box_origin(p, me.size) + me.size * 0.5f, 1.0f);
}

// The rectangle (xy: low corner, zw: high) that label me's constraints can reach at box centre
// c: its anchor and its box with the margin.
vec4 rounds_reach(LabelGpu me, vec2 c) {
  vec2 h = constraint_half_size(me, params.margin);
  return vec4(min(me.anchor, c - h), max(me.anchor, c + h));
}

// Do labels a and b, at result keys ka and kb, constrain each other: does either one's box or
// connector, placed there, touch the other's shadow regions (the label and connector bits eq. 3.1
// would add to its cost)? Rectangles of what each can reach a pixel apart do not.
bool rounds_conflict(LabelGpu a, uint64_t ka, LabelGpu b, uint64_t kb) {
  if (ka == PLACEMENT_NONE || kb == PLACEMENT_NONE) return false;
  vec3 pa = key_placed(a, ka), pb = key_placed(b, kb);
  vec4 ra = rounds_reach(a, vec2(pa)), rb = rounds_reach(b, vec2(pb));
  if (any(greaterThan(vec2(ra), vec2(rb.z, rb.w) + vec2(1.0f))) ||
      any(greaterThan(vec2(rb), vec2(ra.z, ra.w) + vec2(1.0f)))) {
    return false;
  }
  if (region_bits(pair_regions(a, b, pb, params.margin), vec2(pa), 0u) != 0u) return true;
  return region_bits(pair_regions(b, a, pa, params.margin), vec2(pb), 0u) != 0u;
}

// Does label b, newly decided at key kb, add to label a's cost at key ka (a's choice stands
// otherwise)?
bool rounds_constrains(LabelGpu a, uint64_t ka, LabelGpu b, uint64_t kb) {
  if (ka == PLACEMENT_NONE || kb == PLACEMENT_NONE) return false;
  vec3 pa = key_placed(a, ka), pb = key_placed(b, kb);
  return region_bits(pair_regions(a, b, pb, params.margin), vec2(pa), 0u) != 0u;
}
