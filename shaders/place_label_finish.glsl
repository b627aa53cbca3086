// Included by place_label.comp (after place_label_regions.glsl): the dispatch's last workgroup,
// finish(). Label j - 1 is final: its constraint regions for labels j and j + 1 (the next
// dispatch's region writer does the rest). Label j's speculative pass and classification are
// complete: each bucket-0 tile's winner and each entry's cheapest sample is a real candidate
// whose true cost is at most its cost so far plus the weight of what j - 1's regions (none for
// j = 0) add there, so the smallest of those bounds j's best. Its main pass, in the next
// dispatch, takes bucket 0 and the other entries whose bound plus the weight of their classified
// bits does not exceed that. This is on the loop's critical path: what it reads is loaded first,
// and nothing waits on a store.

// The bound candidate of entry i of list p: the speculative winner of a bucket-0 tile, the
// classification's cheapest sample of the others; none from `end` on.
uint64_t bound_key(uint p, uint i, uint end, uint count0, uint tiles) {
  return i >= end ? PLACEMENT_NONE : i < count0 ? speculative[(p & 1u) * tiles + i] : samples[i];
}

// The bound of label j's best (list p, the label placed at `placed` now counted): the smallest
// true cost of the first chunk's bound candidates (`keys`, loaded already) and the later chunks'.
float bound_of_best(LabelGpu me, LabelGpu placed_label, vec3 placed, uint p, uint count0,
                    uint total, uint lanes, uint64_t keys[4]) {
  const uint threads = PLACE_GROUP_X * PLACE_GROUP_Y;
  const uvec2 tiles_xy = placement_tiles(params.width, params.height);
  const uint tiles = tiles_xy.x * tiles_xy.y;
  const uint t = gl_LocalInvocationIndex;
  const uint chunk_size = 4u * lanes;
  const PairRegionsGpu r = pair_regions(me, placed_label, placed, params.margin);
  // (the first 4 x 256 entries' candidates only: the bound need not be the smallest, and the list
  // begins with the lowest buckets; with all invocations taking entries, the chunk loaded above)
  float bound = uintBitsToFloat(0x7F800000u);
  const uint bound_end = min(total, 4u * threads);
  for (uint chunk = 0u; chunk < bound_end; chunk += chunk_size) {
    [[unroll]] for (uint c = 0u; c < 4u; ++c) {
      const uint i = t < lanes ? chunk + c * lanes + t : bound_end;
      const uint64_t key = chunk == 0u ? keys[c] : bound_key(p, i, bound_end, count0, tiles);
      if (key == PLACEMENT_NONE) continue;
      const uint pixel = uint(key & 0xFFFFFFFFul);
      const uvec2 q = uvec2(pixel % params.width, pixel / params.width);
      const uint bits = region_bits(r, box_origin(q, me.size) + me.size * 0.5, 0u);
      if (params.hard != 0u && bits != 0u) continue;  // no longer allowed: bounds nothing
      bound = min(bound, cost_of(key) + constraint_weight(bits));
    }
  }
  bound = subgroupMin(bound);
  if (subgroupElect()) atomicMin(bound_bits, floatBitsToUint(bound));  // costs >= 0
  barrier();
  // (rounding: the true cost is the free cost plus the weight of all bits, summed in another
  // order; an infinite bound stays infinite)
  return uintBitsToFloat(bound_bits) * 1.0001;
}

// Where label j's main pass stops reading its list, for a bound `best` of its best.
uint main_pass_end(float best, uint count0, uint total) {
  // An entry of bucket b has (bound - lowest) >= its edge, rounded; one that is kept has bound <=
  // best, so (best - lowest) >= the edge too (rounding is monotonic): the buckets past the first
  // whose edge is above best - lowest hold nothing to keep, and are not read.
  const float reach = best - finish_lowest;
  uint end = count0;
  for (uint b = 1u; b < PLACEMENT_BUCKETS && placement_bucket_edge(b, params.bucket_width) <= reach; ++b) {
    end = finish_ends[b];
  }
  return min(end, total);
}

// The main pass: bucket 0, then the other entries whose bound with the bits all their
// candidates have is not above `best`, moved up in place in list p (a chunk is read before any of
// it is written, and writes never pass the reads). `entries`: the first chunk, loaded already.
void keep_main_pass(uint p, uint count0, uint end, uint lanes, float best, uvec2 entries[4]) {
  const uvec2 tiles_xy = placement_tiles(params.width, params.height);
  const uint tiles = tiles_xy.x * tiles_xy.y;
  const uint t = gl_LocalInvocationIndex;
  const uint chunk_size = 4u * lanes;
  for (uint chunk = 0u; chunk < end; chunk += chunk_size) {
    bool keep[4];
    [[unroll]] for (uint c = 0u; c < 4u; ++c) {
      const uint i = t < lanes ? chunk + c * lanes + t : end;
      if (chunk > 0u) entries[c] = i < end ? tile_list[p * tiles + i] : uvec2(0u);
      const uint known = (entries[c].x >> PLACEMENT_TILE_CLASS_SHIFT) & 7u;
      keep[c] = i >= count0 && i < end &&
                !(uintBitsToFloat(entries[c].y) + constraint_weight(known) > best) &&
                !(params.hard != 0u && known != 0u);
    }
    if (chunk > 0u) barrier();
    [[unroll]] for (uint c = 0u; c < 4u; ++c) {
      const uvec4 ballot = subgroupBallot(keep[c]);
      uint offset = 0u;
      if (subgroupElect()) offset = atomicAdd(kept, subgroupBallotBitCount(ballot));
      offset = subgroupBroadcastFirst(offset) + subgroupBallotExclusiveBitCount(ballot);
      if (keep[c]) tile_list[p * tiles + count0 + offset] = entries[c];
    }
  }
}

// Label j's main pass (its size and bound, in list p's buckets) for the next dispatch, and that
// dispatch's size, when indirect: this main pass, the next label's speculative pass and
// classification, and the region writer.
void size_next_dispatch(uint j, uint p, uint count0, uint next_count0, uint next_total,
                        float best) {
  buckets[p].rest = kept;
  buckets[p].bound = best;
  buckets[p].main = count0 + kept;
  const uvec3 size =
      placement_dispatch_size(placement_label_groups(count0 + kept, next_count0, next_total, params.classify_tiles));
  args[3u * j + 3u] = size.x;
  args[3u * j + 4u] = size.y;
  args[3u * j + 5u] = size.z;
}

// The dispatch's last workgroup, in dispatch j (above).
void finish(uint j) {
  const uint threads = PLACE_GROUP_X * PLACE_GROUP_Y;
  const uvec2 tiles_xy = placement_tiles(params.width, params.height);
  const uint tiles = tiles_xy.x * tiles_xy.y;
  const uint t = gl_LocalInvocationIndex;
  const bool sizing = j < params.order_count;
  const uint p = min(j, params.order_count - 1u);
  const uint count0 = dispatch_spec, total = dispatch_listed;
  // Everything this reads is loaded first. The list is taken in chunks of four entries per
  // invocation (of the first `lanes`): a bound candidate each (the speculative winners for
  // bucket 0, the classification's samples for the others) and the entry; the first chunk now.
  // (Plain reads: every workgroup wrote its part before it counted, and this one counted last.)
  uint64_t keys[4];
  uvec2 entries[4];
  const uint lanes = params.finish_lanes != 0u ? min(params.finish_lanes, threads) : threads;
  [[unroll]] for (uint c = 0u; c < 4u; ++c) {
    const uint i = t < lanes ? c * lanes + t : total;
    keys[c] = bound_key(p, i, total, count0, tiles);
    entries[c] = i < total ? tile_list[p * tiles + i] : uvec2(0u);
  }
  // The label's lowest tile bound and where its buckets end in the list: the main pass only looks
  // at the buckets whose entries can still be cheap enough (main_pass_end). (One invocation reads
  // them for the workgroup.)
  if (t == 0u) {
    finish_lowest = buckets[p].lowest;
    uint end = 0u;
    [[unroll]] for (uint b = 0u; b < PLACEMENT_BUCKETS; ++b) {
      end += buckets[p].counts[b];
      finish_ends[b] = end;
    }
  }
  uint next_count0 = 0u, next_total = 0u;
  if (t == 0u && p + 1u < params.order_count) {
    next_count0 = buckets[p + 1u].counts[0];
    [[unroll]] for (uint b = 0u; b < PLACEMENT_BUCKETS; ++b) next_total += buckets[p + 1u].counts[b];
  }
  const LabelGpu placed_label = labels[params.label];
  const LabelGpu me = labels[params.spec_label];
  const vec3 placed = j > 0u ? placed_from(results[params.label], params.label) : vec3(0.0);

  // The next dispatch's passes need j - 1's regions for positions j and j + 1; its region writer
  // does the rest.
  if (j > 0u) write_regions(j - 1u, j, min(j + 2u, params.order_count), placed_label, placed);
  if (!sizing) return;
  const float best = bound_of_best(me, placed_label, placed, p, count0, total, lanes, keys);
  keep_main_pass(p, count0, main_pass_end(best, count0, total), lanes, best, entries);
  barrier();
  if (t != 0u) return;
  size_next_dispatch(j, p, count0, next_count0, next_total, best);
}
