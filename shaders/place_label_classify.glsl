// Included by place_label.comp: the CLASSIFY workgroups of dispatch j, which classify the label
// at order position j: its list entries past bucket 0 (the main pass's, in the next dispatch)
// against the labels placed up to j - 2 and the anchors.
// Per entry, the constraint bits every candidate of the tile has (into the entry: the main pass
// adds their weight to the tile's bound and skips the tile when that exceeds the label's bound),
// and the cheapest of four sampled candidates with their bits (into samples: the dispatch's last
// workgroup bounds the label's best by them, as by the speculative winners). The plane tests
// lean the safe way by a rounding margin: a bit every candidate has is never claimed wrongly, and
// a sample is never cheaper than it is. 256 / classify_tiles invocations per entry, each taking
// every so many placed labels and anchors.

// Sample q of a tile: the candidate in the middle of its quarter q.
uvec2 sample_pixel(uvec2 tile, uint q) {
  return tile * PLACEMENT_TILE + uvec2(PLACEMENT_TILE / 4u) * (uvec2(q & 1u, q >> 1u) * 2u + 1u);
}

// Does the box half or the connector half of a pair's regions hold every candidate centre of the
// rectangle (middle c, half size e), bit 0, and each sample centre, bit 1 + q?
uint classify_region(uint pair, bool connector, vec2 c, vec2 e, vec2 sample_centres[4]) {
  bool all_in = true;
  uint in_samples = 0xFu;
  [[unroll]] for (uint k = 0u; k < 6u; ++k) {
    if (!connector && k >= 4u) break;
    const vec4 p = connector ? regions[pair].connector[k] : regions[pair].box[k];
    const vec2 n = vec2(p);
    const float slack = 1e-4 * (abs(n.x * c.x) + abs(n.y * c.y) + abs(p.z) + abs(n.x) * e.x + abs(n.y) * e.y);
    // (the rectangle's corner farthest along n decides for all of it)
    all_in = all_in && dot(n, c) + abs(n.x) * e.x + abs(n.y) * e.y <= p.z - slack;
    [[unroll]] for (uint q = 0u; q < 4u; ++q) {
      if (!(dot(n, sample_centres[q]) <= p.z + slack)) in_samples &= ~(1u << q);
    }
  }
  return (all_in ? 1u : 0u) | (in_samples << 1u);
}

// CLASSIFY workgroup `group` of dispatch j: its classify_tiles entries of label j's list, counted
// from `first` (the first past bucket 0), those up to `end`.
void classify(uint j, uint group, uint first, uint end) {
  const uint t = gl_LocalInvocationIndex;
  const uint lanes = PLACE_GROUP_X * PLACE_GROUP_Y / params.classify_tiles;
  const uint local = t / lanes, lane = t % lanes;
  const uint index = first + group * params.classify_tiles + local;
  const bool valid = index < end;
  const uvec2 tiles_xy = placement_tiles(params.width, params.height);
  const uint tiles = tiles_xy.x * tiles_xy.y;
  const uint list = j * tiles + min(index, tiles - 1u);
  const uvec2 entry = tile_list[list];
  const LabelGpu me = labels[params.spec_label];
  if (t < params.classify_tiles) class_bits[t] = 0u;
  barrier();
  const uint tile_index = entry.x & PLACEMENT_TILE_INDEX_MASK;
  const uvec2 tile = uvec2(tile_index % tiles_xy.x, tile_index / tiles_xy.x);
  vec2 centre, extent;
  tile_centres(me, tile, centre, extent);
  vec2 sample_centres[4];
  [[unroll]] for (uint q = 0u; q < 4u; ++q) {
    sample_centres[q] = box_origin(sample_pixel(tile, q), me.size) + me.size * 0.5;
  }
  uint bits = 0u;
  // (the labels placed up to j - 2, as for the speculative pass)
  for (uint s = lane; valid && s + 2u <= j; s += lanes) {
    const uint pair = placement_pair_slot(j, s);
    // (both halves are tested before their presence is known: no load waits for another)
    const uint info = regions[pair].info.x;
    const uint held_halves[2] = {classify_region(pair, false, centre, extent, sample_centres),
                                 classify_region(pair, true, centre, extent, sample_centres)};
    [[unroll]] for (uint half_index = 0u; half_index < 2u; ++half_index) {
      const bool connector = half_index == 1u;
      const uint kind = connector ? CONSTRAINT_CONNECTOR : CONSTRAINT_LABEL;
      if ((info & (connector ? REGION_CONNECTOR : REGION_BOX)) == 0u) continue;
      const uint held = held_halves[half_index];
      if ((held & 1u) != 0u) bits |= kind;
      [[unroll]] for (uint q = 0u; q < 4u; ++q) {
        if ((held & (2u << q)) != 0u) bits |= kind << (3u * q + 3u);
      }
    }
  }
  // (as cull() and constraint_bits() take the anchors)
  const vec2 h = constraint_half_size(me, params.margin);
  for (uint k = lane; valid && k < params.label_count; k += lanes) {
    if ((labels[k].flags & LABEL_ENABLED) == 0u) continue;
    const vec2 a = labels[k].anchor;
    if (anchor_covers_rectangle(a, centre, extent, h)) bits |= CONSTRAINT_ANCHOR;
    if ((me.flags & LABEL_INTERNAL) != 0u) continue;
    [[unroll]] for (uint q = 0u; q < 4u; ++q) {
      const vec2 d = abs(a - sample_centres[q]);
      if (d.x <= h.x && d.y <= h.y) bits |= CONSTRAINT_ANCHOR << (3u * q + 3u);
    }
  }
  if (valid && bits != 0u) atomicOr(class_bits[local], bits);
  barrier();
  if (!valid || lane != 0u) return;
  const uint found = class_bits[local];
  tile_list[list].x = (entry.x & ~(7u << PLACEMENT_TILE_CLASS_SHIFT)) | ((found & 7u) << PLACEMENT_TILE_CLASS_SHIFT);
  uint64_t best = PLACEMENT_NONE;
  [[unroll]] for (uint q = 0u; q < 4u; ++q) {
    const uvec2 p = sample_pixel(tile, q);
    const uint sample_bits = (found >> (3u * q + 3u)) & 7u;
    if (p.x >= params.width || p.y >= params.height || !candidate_allowed(me, p)) continue;
    if (params.hard != 0u && sample_bits != 0u) continue;
    const vec2 origin = box_origin(p, me.size);
    const float cost = free_cost(me, origin, origin + me.size * 0.5) + constraint_weight(sample_bits);
    best = min(best, (uint64_t(floatBitsToUint(cost)) << 32) | uint64_t(p.y * params.width + p.x));
  }
  atomicExchange(samples[index], best);
}
