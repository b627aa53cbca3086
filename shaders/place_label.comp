#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "shared/placement.h"

// The greedy label loop, one dispatch per step: constraints, eq. 3.1 and the argmin over
// lists of 32x32 tiles (placement_bounds.comp sorted each label's tiles into buckets by a lower
// bound of their cost without constraints). Dispatch j has four kinds of workgroups:
//  - CLASSIFY, the label at order position j: its list entries past bucket 0 against the labels
//    placed up to j - 2 and the anchors (see classify()): the constraint bits every candidate of
//    a tile has, and four sampled candidates' costs.
//  - MAIN, the label at order position j - 1: the tiles its best may still lie in. Bucket 0's
//    tiles were evaluated by the speculative pass of the dispatch before; of those, only the ones
//    label j - 2's regions reach are evaluated again, the others hand on their minimum.
//  - SPEC, the label at order position j: its bucket-0 tiles, with the constraints of the labels
//    up to j - 2 (j - 1 is not final yet), a minimum per tile and no pruning.
//  - one region writer: label j - 2's constraint regions for the labels from j + 1 on.
// The main pass's workgroups meet in results[label] with one 64-bit atomicMin each; the
// dispatch's last workgroup finds label j - 1 final, writes its regions for labels j and j + 1,
// bounds label j's best by the true cost of its speculative winners and samples (their cost plus
// what j - 1's regions add there), and keeps, for j's main pass, the classified entries whose
// bound with their bits does not exceed that (see finish()). A dispatch is either indirect, of
// that size, or direct, of enough workgroups for any counts, those past them leaving at once
// (Placement chooses: see LabelDispatch). The loop never returns to the CPU, and a label's
// speculative pass and classification are off the chain of dependent dispatches.
layout(local_size_x = PLACE_GROUP_X, local_size_y = PLACE_GROUP_Y) in;
layout(binding = PLACEMENT_BINDING_TABLES, std430) readonly buffer Tables { float tables[]; };
layout(binding = PLACEMENT_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = PLACEMENT_BINDING_ORDER, std430) readonly buffer Order { uint order[]; };
// coherent: the bound reads below see other workgroups' atomicMin results (a stale value is only
// a weaker bound, never a wrong one: results only decrease).
layout(binding = PLACEMENT_BINDING_RESULTS, std430) coherent buffer Results { uint64_t results[]; };
layout(binding = PLACEMENT_BINDING_CONSTRAINTS, std430) writeonly buffer Constraints { uint constraints[]; };
layout(binding = PLACEMENT_BINDING_BUCKETS, std430) coherent buffer Buckets { PlacementBucketsGpu buckets[]; };
// Written past bucket 0: the classification's bits in label j's list (read in the next dispatch)
// and, by the dispatch's last workgroup, label j's main pass moved up.
layout(binding = PLACEMENT_BINDING_TILES, std430) coherent buffer Tiles { uvec2 tile_list[]; };
layout(binding = PLACEMENT_BINDING_ARGS, std430) writeonly buffer Args { uint args[]; };
layout(binding = PLACEMENT_BINDING_SPECULATIVE, std430) coherent buffer Speculative { uint64_t speculative[]; };
// Read for the labels being placed and classified (written by earlier dispatches); written, once
// a label is final, for the labels after it (rows no workgroup of the same dispatch reads).
layout(binding = PLACEMENT_BINDING_REGIONS, std430) buffer Regions { PairRegionsGpu regions[]; };
// The classification's cheapest sample per list entry of label j, read by the last workgroup.
layout(binding = PLACEMENT_BINDING_SAMPLES, std430) coherent buffer Samples { uint64_t samples[]; };
layout(push_constant) uniform Push { PlacementParams params; };

// The order position this workgroup places, and the placed ones it tests against (0 .. placed - 1).
uint position;
uint placed;

// The placed labels and anchors this tile's candidates can reach, culled by chunks of
// PLACE_CULL_CHUNK labels (one chunk up to that many labels; more take turns through the lists).
#define PLACE_CULL_CHUNK (PLACE_GROUP_X * PLACE_GROUP_Y)
shared uint tile_placed[PLACE_CULL_CHUNK];
shared uint tile_placed_count;
shared vec2 tile_anchors[PLACE_CULL_CHUNK];
shared uint tile_anchor_count;
shared uint tile_bits;  // constraints every candidate of the tile has

// The regions of the label at order position s against the one placed at order position t.
PairRegionsGpu regions_of(uint s, uint t) { return regions[placement_pair_slot(s, t)]; }
uint placed_count() { return tile_placed_count; }
PairRegionsGpu placed_regions(uint k) { return regions_of(position, tile_placed[k]); }
uint anchor_count() { return tile_anchor_count; }
vec2 anchor_at(uint k) { return tile_anchors[k]; }
vec3 placed_from(uint64_t r, uint j) {
  if (r == PLACEMENT_NONE) return vec3(0.0);
  const uint pixel = uint(r & 0xFFFFFFFFul);
  const uvec2 p = uvec2(pixel % params.width, pixel / params.width);
  return vec3(box_origin(p, labels[j].size) + labels[j].size * 0.5, 1.0);
}
// (The load does not depend on the test, so a candidate's four are issued together; clamped, so
// a candidate off screen reads inside the table.)
float table_at(uint layer, int x, int y) {
  const uint column = uint(clamp(x, 0, int(params.width) - 1));
  const uint row = uint(clamp(y, 0, int(params.height) - 1));
  const float value = tables[(layer * params.height + row) * params.width + column];
  return x < 0 || y < 0 ? 0.0 : value;
}

#include "shared/placement_cost.h"

shared uint64_t group_best[PLACE_GROUP_X * PLACE_GROUP_Y];  // per subgroup

// The rectangle of box centres this tile's candidates have (centre and half size).
void tile_centres(LabelGpu me, uvec2 tile, out vec2 centre, out vec2 extent) {
  const vec2 first = box_origin(tile * PLACEMENT_TILE, me.size) + me.size * 0.5;
  extent = vec2(0.5 * float(PLACEMENT_TILE - 1));
  centre = first + extent;
}

// Does the region (4 or 6 planes) touch the rectangle of centres (middle c, half size e)? A
// tile's may-constrain test: it only has to be conservative (the slack covers rounding in the
// per-candidate tests), so no plane separates them by more than that.
bool region_may_touch(vec4 p[6], vec2 c, vec2 e) {
  [[unroll]] for (int k = 0; k < 6; ++k) {
    // How far the rectangle's nearest point lies beyond the plane.
    const float gap = dot(vec2(p[k]), c) - abs(p[k].x) * e.x - abs(p[k].y) * e.y - p[k].z;
    const float scale = abs(p[k].x * c.x) + abs(p[k].y * c.y) + abs(p[k].z) +
                        abs(p[k].x) * e.x + abs(p[k].y) * e.y;
    if (gap > 1e-4 * scale) return false;
  }
  return true;
}

// Does the region hold every candidate of the tile? Each is convex and the rounded per-candidate
// test is monotonic in each coordinate, so its four corner candidates decide it exactly.
bool region_holds_corners(vec4 p[6], vec2 c, vec2 e) {
  [[unroll]] for (int k = 0; k < 4; ++k) {
    const vec2 corner = c + e * vec2((k & 1) != 0 ? 1.0 : -1.0, (k & 2) != 0 ? 1.0 : -1.0);
    if (!region_holds(p[0], p[1], p[2], p[3], p[4], p[5], corner)) return false;
  }
  return true;
}

// The REGION_* bits of r whose regions may touch the tile's candidates (centre c, half size e),
// in `touch`, and those that hold all of them, in `full`.
void region_reach(PairRegionsGpu r, vec2 c, vec2 e, out uint touch, out uint full) {
  touch = 0u;
  full = 0u;
  if ((r.info.x & REGION_BOX) != 0u) {
    const vec4 p[6] = {r.box[0], r.box[1], r.box[2], r.box[3], vec4(0.0), vec4(0.0)};
    if (region_may_touch(p, c, e)) {
      touch |= CONSTRAINT_LABEL;
      if (region_holds_corners(p, c, e)) full |= CONSTRAINT_LABEL;
    }
  }
  if ((r.info.x & REGION_CONNECTOR) != 0u && region_may_touch(r.connector, c, e)) {
    touch |= CONSTRAINT_CONNECTOR;
    if (region_holds_corners(r.connector, c, e)) full |= CONSTRAINT_CONNECTOR;
  }
}

// Does every box (half size h, margin included) centred in the rectangle (middle c, half size e)
// cover the anchor a? Exact at the rectangle's corners, as the candidates' own test.
bool anchor_covers_rectangle(vec2 a, vec2 c, vec2 e, vec2 h) {
  bool covers = true;
  for (int k = 0; k < 4; ++k) {
    const vec2 d = abs(a - (c + e * vec2((k & 1) != 0 ? 1.0 : -1.0, (k & 2) != 0 ? 1.0 : -1.0)));
    covers = covers && d.x <= h.x && d.y <= h.y;
  }
  return covers;
}

// The tile's candidate-reaching placed labels and anchors of the chunk from `from` (order
// positions of placed labels, indices of anchors), and the constraints all of its candidates have
// (the shared counts start at 0; a barrier follows).
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

// Classification, in dispatch j, of the label at order position j: its list entries past bucket 0
// (the main pass's, in the next dispatch) against the labels placed up to j - 2 and the anchors.
// Per entry, the constraint bits every candidate of the tile has (into the entry: the main pass
// adds their weight to the tile's bound and skips the tile when that exceeds the label's bound),
// and the cheapest of four sampled candidates with their bits (into samples: the dispatch's last
// workgroup bounds the label's best by them, as by the speculative winners). The plane tests
// lean the safe way by a rounding margin: a bit every candidate has is never claimed wrongly, and
// a sample is never cheaper than it is. 256 / classify_tiles invocations per entry, each taking
// every so many placed labels and anchors.
shared uint class_bits[PLACEMENT_CLASSIFY_TILES_MAX];  // bits 0-2: every candidate's; 3q + 3..5: sample q's

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

float cost_of(uint64_t key) {
  return key == PLACEMENT_NONE ? uintBitsToFloat(0x7F800000u) : uintBitsToFloat(uint(key >> 32));
}

// The dispatch's passes: the main pass's size and bound, the speculative pass's size, the entries
// of the speculative pass's label's list.
shared uint dispatch_main, dispatch_spec, dispatch_listed;
shared float dispatch_bound;

// The regions of the labels at order positions first .. last - 1 against the one at position s,
// placed at `placed` (two invocations per label: its box half and its connector half).
void write_regions(uint s, uint first, uint last, LabelGpu placed_label, vec3 placed) {
  const uint threads = PLACE_GROUP_X * PLACE_GROUP_Y;
  for (uint u = gl_LocalInvocationIndex; first + u / 2u < last; u += threads) {
    const uint k_pos = first + u / 2u;
    const uint slot = placement_pair_slot(k_pos, s);
    const LabelGpu k = labels[order[k_pos]];
    if ((u & 1u) == 0u) {
      const PairBoxRegion r = pair_box_region(k, placed_label, placed, params.margin);
      regions[slot].box = r.box;
      regions[slot].info = r.info;
    } else {
      regions[slot].connector = pair_connector_region(k, placed_label, placed, params.margin).p;
    }
  }
}

shared uint finishing;  // 1: this workgroup is the dispatch's last
shared uint bound_bits;  // the bound candidates' smallest true cost (bits)
shared uint kept;  // entries past bucket 0 the main pass takes
shared float finish_lowest;  // the label's lowest tile bound
shared uint finish_ends[PLACEMENT_BUCKETS];  // where each bucket's entries end in its list

// The dispatch's last workgroup. Label j - 1 is final: its constraint regions for labels j and
// j + 1 (the next dispatch's region writer does the rest). Label j's speculative pass and
// classification are complete: each bucket-0 tile's winner and each entry's cheapest sample is a
// real candidate whose true cost is at most its cost so far plus the weight of what j - 1's
// regions (none for j = 0) add there, so the smallest of those bounds j's best. Its main pass, in
// the next dispatch, takes bucket 0 and the other entries whose bound plus the weight of their
// classified bits does not exceed that. This is on the loop's critical path: what it reads is
// loaded first, and nothing waits on a store.
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
  const uint chunk_size = 4u * lanes;
  [[unroll]] for (uint c = 0u; c < 4u; ++c) {
    const uint i = t < lanes ? c * lanes + t : total;
    keys[c] = i >= total ? PLACEMENT_NONE : i < count0 ? speculative[(p & 1u) * tiles + i] : samples[i];
    entries[c] = i < total ? tile_list[p * tiles + i] : uvec2(0u);
  }
  // The label's lowest tile bound and where its buckets end in the list: the main pass only looks
  // at the buckets whose entries can still be cheap enough (below). (One invocation reads them
  // for the workgroup.)
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
  const PairRegionsGpu r = pair_regions(me, placed_label, placed, params.margin);
  // (the first 4 x 256 entries' candidates only: the bound need not be the smallest, and the list
  // begins with the lowest buckets; with all invocations taking entries, the chunk loaded above)
  float bound = uintBitsToFloat(0x7F800000u);
  const uint bound_end = min(total, 4u * threads);
  for (uint chunk = 0u; chunk < bound_end; chunk += chunk_size) {
    [[unroll]] for (uint c = 0u; c < 4u; ++c) {
      const uint i = t < lanes ? chunk + c * lanes + t : bound_end;
      const uint64_t key = chunk == 0u ? keys[c]
                           : i >= bound_end ? PLACEMENT_NONE
                           : i < count0 ? speculative[(p & 1u) * tiles + i]
                                        : samples[i];
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
  const float best = uintBitsToFloat(bound_bits) * 1.0001;
  // An entry of bucket b has (bound - lowest) >= its edge, rounded; one that is kept has bound <=
  // best, so (best - lowest) >= the edge too (rounding is monotonic): the buckets past the first
  // whose edge is above best - lowest hold nothing to keep, and are not read.
  const float reach = best - finish_lowest;
  uint end = count0;
  for (uint b = 1u; b < PLACEMENT_BUCKETS && placement_bucket_edge(b, params.bucket_width) <= reach; ++b) {
    end = finish_ends[b];
  }
  end = min(end, total);
  // The main pass: bucket 0, then the other entries whose bound with the bits all their
  // candidates have is not above that, moved up in place (a chunk is read before any of it is
  // written, and writes never pass the reads).
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
  barrier();
  if (t != 0u) return;
  buckets[p].rest = kept;
  buckets[p].bound = best;
  buckets[p].main = count0 + kept;
  // The next dispatch's size, when indirect: this main pass, the next label's speculative pass and
  // classification, and the region writer.
  const uvec3 size =
      placement_dispatch_size(placement_label_groups(count0 + kept, next_count0, next_total, params.classify_tiles));
  args[3u * j + 3u] = size.x;
  args[3u * j + 4u] = size.y;
  args[3u * j + 5u] = size.z;
}

shared uint tile_hope;  // 1: some candidate's cost without constraints is not above the best
shared uint64_t tile_best;  // the label's best when this workgroup started

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
  if (!hopeless) {
    // (every candidate's cost is computed, allowed or not, so that nothing waits on the tests;
    // the tile's constraints are culled meanwhile, whether or not a candidate turns out worth it)
    [[unroll]] for (uint q = 0u; q < PLACE_SPAN_X * PLACE_SPAN_Y; ++q) {
      const uvec2 p = candidate_pixel(base, q);
      const vec2 origin = box_origin(p, me.size);
      free_costs[q] = free_cost(me, origin, origin + me.size * 0.5);
      const bool allowed = p.x < params.width && p.y < params.height && candidate_allowed(me, p);
      if (allowed && !(free_costs[q] > best)) candidates |= 1u << q;
    }
    if (subgroupOr(candidates) != 0u && subgroupElect()) atomicOr(tile_hope, 1u);
    cull(me, tile, 0u);
  }
  barrier();
  hopeless = tile_hope == 0u ||
             (prune && (0.9999 * (bound + constraint_weight(tile_bits)) > best ||
                        (params.hard != 0u && tile_bits != 0u)));
  uint64_t key = PLACEMENT_NONE;
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
  // Lowest cost, then lowest pixel index: the subgroup's minimum cost, then the first pixel with it.
  const uint cost_bits = uint(key >> 32);
  const uint best_bits = subgroupMin(cost_bits);
  const uint best_pixel = subgroupMin(cost_bits == best_bits ? uint(key) : 0xFFFFFFFFu);
  if (subgroupElect()) group_best[gl_SubgroupID] = (uint64_t(best_bits) << 32) | uint64_t(best_pixel);
  barrier();
  uint64_t group = PLACEMENT_NONE;
  for (uint k = 0u; k < gl_NumSubgroups; ++k) group = min(group, group_best[k]);
  return group;
}

void main() {
  const uint j = params.step;  // this dispatch: MAIN for position j - 1, SPEC for position j
  const uvec2 tiles_xy = placement_tiles(params.width, params.height);
  const uint tiles_x = tiles_xy.x, tiles = tiles_xy.x * tiles_xy.y;
  const uint w = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  // (one invocation reads them: thousands of workgroups read the same few words)
  if (gl_LocalInvocationIndex == 0u) {
    dispatch_main = j > 0u ? buckets[j - 1u].main : 0u;
    dispatch_bound = j > 0u ? buckets[j - 1u].bound : 0.0;
    uint count0 = 0u, listed = 0u;
    if (j < params.order_count) {
      count0 = buckets[j].counts[0];
      [[unroll]] for (uint b = 0u; b < PLACEMENT_BUCKETS; ++b) listed += buckets[j].counts[b];
    }
    dispatch_spec = count0;
    dispatch_listed = listed;
  }
  barrier();
  const uint main_count = dispatch_main, spec_count = dispatch_spec, listed = dispatch_listed;
  const float best_bound = dispatch_bound;
  const uint classify_count = placement_classify_groups(listed - spec_count, params.classify_tiles);
  // The workgroups: the classification's (first, so that they start at once), the passes', and
  // a region writer: the label at position j - 2, final since the last dispatch, against the
  // labels from j + 1 on (the ones up to j have them from that dispatch's last workgroup). The
  // passes' items are the main pass's tiles, then the speculative pass's; a dispatch with fewer
  // workgroups for them (a direct one: see LabelDispatch) has each take every so many. Those past
  // all this leave at once. The last to finish sizes the next dispatch.
  const uint items = main_count + spec_count;
  const uint groups = gl_NumWorkGroups.x * gl_NumWorkGroups.y;
  const uint stride = min(items, groups - classify_count - 1u);
  const uint working = classify_count + stride + 1u;
  if (w >= working) return;
  if (w + 1u == working && j >= 2u && j + 1u < params.order_count) {
    const uint s = order[j - 2u];
    write_regions(j - 2u, j + 1u, params.order_count, labels[s], placed_from(results[s], s));
  }
  const bool is_classify = w < classify_count;
  if (is_classify) classify(j, w, spec_count, listed);
  uint64_t main_group = PLACEMENT_NONE;
  const bool has_items = !is_classify && w + 1u < working;
  for (uint item = w - classify_count; has_items && item < items; item += stride) {
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
    if (is_main && !keep && (bound + constraint_weight(known) > best_bound ||
                             (params.hard != 0u && known != 0u))) {
      evaluate = false;
    }
    if (evaluate) {
      group = evaluate_tile(label, tile, known, bound, is_main && !keep, is_main ? best_bound : 0.0,
                            is_main && keep);
    }
    if (is_main) main_group = min(main_group, group);
    if (!is_main && gl_LocalInvocationIndex == 0u) {
      atomicExchange(speculative[(position & 1u) * tiles + slot], group);
    }
  }
  if (gl_LocalInvocationIndex == 0u) {
    // Thousands of workgroups share one address: only those that improve on it touch it.
    if (main_group != PLACEMENT_NONE && main_group < results[params.label]) {
      atomicMin(results[params.label], main_group);
    }
    memoryBarrierBuffer();
    finishing = atomicAdd(buckets[j].done, 1u) + 1u == working ? 1u : 0u;
    if (finishing != 0u) {
      bound_bits = 0x7F800000u;
      kept = 0u;
      memoryBarrierBuffer();
    }
  }
  barrier();
  if (finishing != 0u) finish(j);
}
