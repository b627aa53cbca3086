// Included by place_label.comp (after place_label_evaluate.glsl): one item of a dispatch's passes.

// Item `item` of dispatch j's passes, a tile: the main pass's (label j - 1) below main_count, the
// speculative pass's (label j) past it. Its lowest (cost, pixel); the speculative pass's also
// into `speculative`.
uint64_t pass_item(uint j, uint item, uint main_count, float best_bound) {
  const uvec2 tiles_xy = placement_tiles(params.width, params.height);
  const uint tiles_x = tiles_xy.x, tiles = tiles_xy.x * tiles_xy.y;
  const bool is_main = item < main_count;
  const uint slot = is_main ? item : item - main_count;
  position = is_main ? j - 1u : j;
  placed = is_main ? position : max(position, 1u) - 1u;
  const uint label = is_main ? params.label : params.spec_label;
  uint64_t group = PLACEMENT_NONE;
  const uvec2 entry = tile_list[position * tiles + slot];
  const uint tile_index = entry.x & PLACEMENT_TILE_INDEX_MASK;
  const uvec2 tile = uvec2(tile_index % tiles_x, tile_index / tiles_x);
  const uint known = (entry.x >> PLACEMENT_TILE_CLASS_SHIFT) & 7u;
  const float bound = uintBitsToFloat(entry.y);
  const bool keep = params.write_constraints != 0u;
  // A bucket-0 tile of the main pass: its speculative minimum stands unless the label placed
  // last reaches its candidates (kept constraint images need every candidate evaluated).
  bool evaluate = true;
  if (is_main && (entry.x & PLACEMENT_BUCKET0_TILE) != 0u && !keep) {
    uint touch = 0u, full;
    if (position > 0u) {
      vec2 centre, extent;
      tile_centres(labels[label], tile, centre, extent);
      region_reach(regions_of(position, position - 1u), centre, extent, touch, full);
    }
    evaluate = touch != 0u;
    if (!evaluate) group = speculative[(position & 1u) * tiles + slot];
  }
  // A classified tile whose bound with the bits all its candidates have is above the label's
  // bound holds no winner (hard mode: any bit forbids every candidate).
  if (is_main && !keep &&
      (bound + constraint_weight(known) > best_bound || (params.hard != 0u && known != 0u))) {
    evaluate = false;
  }
  if (evaluate) {
    group = evaluate_tile(label, tile, known, bound, is_main && !keep, is_main ? best_bound : 0.0,
                          is_main && keep);
  }
  if (!is_main && gl_LocalInvocationIndex == 0u) {
    atomicExchange(speculative[(position & 1u) * tiles + slot], group);
  }
  return group;
}
