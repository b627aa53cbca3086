// Included by place_label_first.comp and place_label_rest.comp (PLACEMENT_FIRST_PASS decides).
// One label: constraints, eq. 3.1 and the argmin over a list of 32x32 tiles, in one dispatch.
// The result (cost bits << 32 | pixel) goes to results[label] with one 64-bit atomicMin per
// workgroup; the next label's dispatches read it there, so the greedy loop never returns to the
// CPU. Two passes per label (placement_bounds.comp sorted its tiles into buckets by a lower bound
// of their cost): the FIRST takes bucket 0; its last workgroup sizes the REST pass to the buckets
// whose bounds the best cost found so far leaves possible.
layout(local_size_x = PLACE_GROUP_X, local_size_y = PLACE_GROUP_Y) in;
layout(binding = PLACEMENT_BINDING_TABLES, std430) readonly buffer Tables { float tables[]; };
layout(binding = PLACEMENT_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = PLACEMENT_BINDING_ORDER, std430) readonly buffer Order { uint order[]; };
// coherent: the bound reads below see other workgroups' atomicMin results (a stale value is only
// a weaker bound, never a wrong one: results only decrease).
layout(binding = PLACEMENT_BINDING_RESULTS, std430) coherent buffer Results { uint64_t results[]; };
layout(binding = PLACEMENT_BINDING_CONSTRAINTS, std430) writeonly buffer Constraints { uint constraints[]; };
layout(binding = PLACEMENT_BINDING_BUCKETS, std430) coherent buffer Buckets { PlacementBucketsGpu buckets[]; };
layout(binding = PLACEMENT_BINDING_TILES, std430) readonly buffer Tiles { uvec2 tile_list[]; };
layout(binding = PLACEMENT_BINDING_LOWER, std430) readonly buffer Lower { uint lower[]; };
// Read for the label being placed (written by earlier labels' dispatches); written, once a label
// is final, for every label after it.
layout(binding = PLACEMENT_BINDING_REGIONS, std430) buffer Regions { PairRegionsGpu regions[]; };
#ifdef PLACEMENT_FIRST_PASS
layout(binding = PLACEMENT_BINDING_REST_ARGS, std430) writeonly buffer RestArgs { uint rest_args[]; };
#endif
layout(push_constant) uniform Push { PlacementParams params; };

// The placed labels and anchors this tile's candidates can reach (culled once per tile).
shared uint tile_placed[LABEL_MAX];
shared uint tile_placed_count;
shared vec2 tile_anchors[LABEL_MAX];
shared uint tile_anchor_count;
shared uint tile_bits;  // constraints every candidate of the tile has

// The regions of the label being placed against the one placed at order position s.
PairRegionsGpu regions_of(uint s) { return regions[params.step * params.label_count + s]; }
uint placed_count() { return tile_placed_count; }
PairRegionsGpu placed_regions(uint k) { return regions_of(tile_placed[k]); }
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

// The tile's candidate-reaching placed labels and anchors, and the constraints all of its
// candidates have.
void cull(LabelGpu me, uvec2 tile) {
  if (gl_LocalInvocationIndex == 0u) {
    tile_placed_count = 0u;
    tile_anchor_count = 0u;
    tile_bits = 0u;
  }
  barrier();
  vec2 centre, extent;
  tile_centres(me, tile, centre, extent);
  const uint threads = PLACE_GROUP_X * PLACE_GROUP_Y;
  for (uint s = gl_LocalInvocationIndex; s < params.step; s += threads) {
    const PairRegionsGpu r = regions_of(s);
    uint touch = 0u, full = 0u;
    if ((r.info.x & REGION_BOX) != 0u) {
      const vec4 p[6] = {r.box[0], r.box[1], r.box[2], r.box[3], vec4(0.0), vec4(0.0)};
      if (region_may_touch(p, centre, extent)) {
        touch |= CONSTRAINT_LABEL;
        if (region_holds_corners(p, centre, extent)) full |= CONSTRAINT_LABEL;
      }
    }
    if ((r.info.x & REGION_CONNECTOR) != 0u && region_may_touch(r.connector, centre, extent)) {
      touch |= CONSTRAINT_CONNECTOR;
      if (region_holds_corners(r.connector, centre, extent)) full |= CONSTRAINT_CONNECTOR;
    }
    if (full != 0u) atomicOr(tile_bits, full);
    if ((touch & ~full) != 0u) tile_placed[atomicAdd(tile_placed_count, 1u)] = s;
  }
  // Anchors: a candidate's box (margin included) covering one; exact at the corners as above.
  const vec2 h = me.size * 0.5 + vec2(params.margin);
  for (uint k = gl_LocalInvocationIndex; k < params.label_count; k += threads) {
    if ((labels[k].flags & LABEL_ENABLED) == 0u) continue;
    const vec2 d = abs(labels[k].anchor - centre);
    if (d.x > extent.x + h.x + 1.0 || d.y > extent.y + h.y + 1.0) continue;
    bool covers = true;
    for (int c = 0; c < 4; ++c) {
      const vec2 corner = centre + extent * vec2((c & 1) != 0 ? 1.0 : -1.0, (c & 2) != 0 ? 1.0 : -1.0);
      const vec2 dc = abs(labels[k].anchor - corner);
      covers = covers && dc.x <= h.x && dc.y <= h.y;
    }
    if (covers) atomicOr(tile_bits, CONSTRAINT_ANCHOR);
    else tile_anchors[atomicAdd(tile_anchor_count, 1u)] = labels[k].anchor;
  }
  barrier();
}

shared uint64_t tile_best;  // the label's best when this workgroup started

float cost_of(uint64_t key) {
  return key == PLACEMENT_NONE ? uintBitsToFloat(0x7F800000u) : uintBitsToFloat(uint(key >> 32));
}

#ifdef PLACEMENT_FIRST_PASS
// The last first-pass workgroup: the buckets a candidate cheaper than (or as cheap as) the best
// so far may be in are those whose lower edge is not above it; the rest pass takes them.
uint size_rest_pass(uint s, uint label) {
  memoryBarrierBuffer();
  const float best = cost_of(atomicMin(results[label], PLACEMENT_NONE));  // an atomic read
  const float above = best - uintBitsToFloat(lower[s]);
  uint rest = 0u;
  for (uint b = 1u; b < PLACEMENT_BUCKETS; ++b) {
    // (an infinite best: every bucket)
    if (!(above >= placement_bucket_edge(b, params.bucket_width))) break;
    rest += buckets[s].counts[b];
  }
  buckets[s].rest = rest;
  const uvec3 size = placement_dispatch_size(rest);
  rest_args[3u * s] = size.x;
  rest_args[3u * s + 1u] = size.y;
  rest_args[3u * s + 2u] = size.z;
  return rest;
}
#endif

shared uint finishing;          // 1: this workgroup is the label's last, its result is final
shared uint64_t final_result;

// The label at order position s is final: its constraint regions for every label after it.
void write_regions(uint s, uint j) {
  const vec3 placed_j = placed_from(final_result, j);
  const uint threads = PLACE_GROUP_X * PLACE_GROUP_Y;
  // Two invocations per later label: its box half and its connector half.
  for (uint t = gl_LocalInvocationIndex; s + 1u + t / 2u < params.order_count; t += threads) {
    const uint k_pos = s + 1u + t / 2u;
    const uint slot = k_pos * params.label_count + s;
    const LabelGpu k = labels[order[k_pos]];
    if ((t & 1u) == 0u) {
      const PairBoxRegion r = pair_box_region(k, labels[j], placed_j, params.margin);
      regions[slot].box = r.box;
      regions[slot].info = r.info;
    } else {
      regions[slot].connector = pair_connector_region(k, labels[j], placed_j, params.margin).p;
    }
  }
}

shared uint tile_hope;  // 1: some candidate's cost without constraints is not above the best

// The pixel of an invocation's candidate q: SPAN_X x SPAN_Y of them from `base`, a workgroup's
// width or height apart (neighbouring invocations read neighbouring table entries).
uvec2 candidate_pixel(uvec2 base, uint q) {
  return base + uvec2(q % PLACE_SPAN_X, q / PLACE_SPAN_X) * uvec2(PLACE_GROUP_X, PLACE_GROUP_Y);
}

void main() {
  const uint s = params.step;
  const uint label = params.label;
  const LabelGpu me = labels[label];
  const uvec2 tiles_xy = placement_tiles(params.width, params.height);
  const uint tiles_x = tiles_xy.x, tiles = tiles_xy.x * tiles_xy.y;
#ifdef PLACEMENT_FIRST_PASS
  const bool first_pass = true;
#else
  const bool first_pass = false;
#endif
  // (the tile is read before the count: neither waits for the other)
  const uint w = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  const uint slot = min(w, tiles - 1u);
  const uvec2 entry = tile_list[s * tiles + (first_pass ? tiles - 1u - slot : slot)];
  const uint count = first_pass ? buckets[s].counts[0] : buckets[s].rest;
  if (w >= count) return;  // the whole workgroup
  const uint tile_index = entry.x;
  const uvec2 tile = uvec2(tile_index % tiles_x, tile_index / tiles_x);
  const uvec2 base = tile * PLACEMENT_TILE + gl_LocalInvocationID.xy;

  // A candidate can only win if its cost is not above the best another workgroup has found
  // (strictly above: ties cannot be lost either): first the tile's bound from
  // placement_bounds.comp, then each candidate's cost without constraints (constraint terms only
  // add, and rounded sums are monotonic), then with the constraints the whole tile has. The
  // constraint image (tests, debugging) needs every candidate.
  if (gl_LocalInvocationIndex == 0u) {
    tile_best = results[label];
    tile_hope = 0u;
  }
  barrier();
  const bool may_skip = params.write_constraints == 0u;
  const float best = cost_of(tile_best);
  const float bound = uintBitsToFloat(entry.y);
  bool hopeless = may_skip && bound > best;
  float free_costs[PLACE_SPAN_X * PLACE_SPAN_Y];
  uint candidates = 0u;  // bit q: candidate q is worth its constraints
  if (!hopeless) {
    // (every candidate's cost is computed, allowed or not, so that nothing waits on the tests)
    [[unroll]] for (uint q = 0u; q < PLACE_SPAN_X * PLACE_SPAN_Y; ++q) {
      const uvec2 p = candidate_pixel(base, q);
      const vec2 origin = box_origin(p, me.size);
      free_costs[q] = free_cost(me, origin, origin + me.size * 0.5);
      const bool allowed = p.x < params.width && p.y < params.height && candidate_allowed(me, p);
      if (allowed && (!may_skip || !(free_costs[q] > best))) candidates |= 1u << q;
    }
    if (subgroupOr(candidates) != 0u && subgroupElect()) atomicOr(tile_hope, 1u);
  }
  barrier();
  hopeless = tile_hope == 0u;
  if (!hopeless) {
    cull(me, tile);
    hopeless = may_skip && (0.9999 * (bound + constraint_weight(tile_bits)) > best ||
                            (params.hard != 0u && tile_bits != 0u));
  }
  uint64_t key = PLACEMENT_NONE;
  [[unroll]] for (uint q = 0u; q < PLACE_SPAN_X * PLACE_SPAN_Y; ++q) {
    if (hopeless) break;
    if ((candidates & (1u << q)) == 0u) continue;
    const uvec2 p = candidate_pixel(base, q);
    const vec2 origin = box_origin(p, me.size);
    const vec2 centre = origin + me.size * 0.5;
    // Bits weighing more than best - cost without them lose (strictly: 0.999), so the search
    // stops there (hard mode: at the first); all of them for the constraint image.
    const float budget = !may_skip       ? 1.0 / 0.0
                         : params.hard != 0u ? 0.0
                                             : (best - free_costs[q]) / 0.999;
    const uint bits = constraint_bits(me, centre, tile_bits, budget);
    const uint pixel = p.y * params.width + p.x;
    if (params.write_constraints != 0u) constraints[pixel] = bits;
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
  if (gl_LocalInvocationIndex == 0u) {
    uint64_t group = PLACEMENT_NONE;
    for (uint k = 0u; k < gl_NumSubgroups; ++k) group = min(group, group_best[k]);
    // Thousands of workgroups share one address: only those that improve on it touch it.
    if (group != PLACEMENT_NONE && group < results[label]) atomicMin(results[label], group);
    // The last workgroup of the label's last pass (the first, if it left the second nothing)
    // finds its result final.
    memoryBarrierBuffer();
    finishing = 0u;
#ifdef PLACEMENT_FIRST_PASS
    if (atomicAdd(buckets[s].done, 1u) + 1u == count && size_rest_pass(s, label) == 0u) finishing = 1u;
#else
    if (atomicAdd(buckets[s].done_rest, 1u) + 1u == count) finishing = 1u;
#endif
    if (finishing != 0u) {
      memoryBarrierBuffer();
      final_result = atomicMin(results[label], PLACEMENT_NONE);  // an atomic read
    }
  }
  barrier();
  if (finishing != 0u) write_regions(s, label);
}
