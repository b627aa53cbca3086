#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
#include "shared/placement.h"

// The greedy label loop, one dispatch per step: constraints, eq. 3.1 and the argmin over
// lists of 32x32 tiles (placement_bounds.comp sorted each label's tiles into buckets by a lower
// bound of their cost). Dispatch j does two things at once:
//  - MAIN, the label at order position j - 1: every tile its best may still lie in. Bucket 0's
//    tiles were evaluated by the speculative pass of the dispatch before; of those, only the ones
//    label j - 2's regions reach are evaluated again, the others hand on their minimum.
//  - SPEC, the label at order position j: its bucket-0 tiles, with the constraints of the labels
//    up to j - 2 (j - 1 is not final yet), a minimum per tile and no pruning.
// Each workgroup's (cost, pixel) goes to results[label] with one 64-bit atomicMin; the dispatch's
// last workgroup finds label j - 1 final, writes its constraint regions for the labels after it,
// bounds label j's best by the true cost of its speculative winners (the speculative cost plus
// what j - 1's regions add there) and sizes j's main pass and the next dispatch. A dispatch is
// either indirect, of that size, or direct, of a workgroup for every tile twice over, those past
// the passes' sizes leaving at once (Placement chooses: see LabelDispatch). The loop never returns to the CPU, and
// a label's speculative pass is off the chain of dependent dispatches.
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
layout(binding = PLACEMENT_BINDING_ARGS, std430) writeonly buffer Args { uint args[]; };
layout(binding = PLACEMENT_BINDING_SPECULATIVE, std430) coherent buffer Speculative { uint64_t speculative[]; };
// Read for the label being placed (written by earlier labels' dispatches); written, once a label
// is final, for every label after it.
layout(binding = PLACEMENT_BINDING_REGIONS, std430) buffer Regions { PairRegionsGpu regions[]; };
layout(push_constant) uniform Push { PlacementParams params; };

// The order position this workgroup places, and the placed ones it tests against (0 .. placed - 1).
uint position;
uint placed;

// The placed labels and anchors this tile's candidates can reach (culled once per tile).
shared uint tile_placed[LABEL_MAX];
shared uint tile_placed_count;
shared vec2 tile_anchors[LABEL_MAX];
shared uint tile_anchor_count;
shared uint tile_bits;  // constraints every candidate of the tile has

// The regions of the label at order position s against the one placed at order position t.
PairRegionsGpu regions_of(uint s, uint t) { return regions[s * params.label_count + t]; }
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

// The tile's candidate-reaching placed labels and anchors, and the constraints all of its
// candidates have (the shared counts start at 0; a barrier follows).
void cull(LabelGpu me, uvec2 tile) {
  vec2 centre, extent;
  tile_centres(me, tile, centre, extent);
  const uint threads = PLACE_GROUP_X * PLACE_GROUP_Y;
  for (uint s = gl_LocalInvocationIndex; s < placed; s += threads) {
    uint touch, full;
    region_reach(regions_of(position, s), centre, extent, touch, full);
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
}

float cost_of(uint64_t key) {
  return key == PLACEMENT_NONE ? uintBitsToFloat(0x7F800000u) : uintBitsToFloat(uint(key >> 32));
}

// An atomic read of a 64-bit (cost, pixel) (atomics take no function parameters).
#define ATOMIC_READ(value) atomicMin(value, PLACEMENT_NONE)

shared uint finishing;  // 1: this workgroup is the dispatch's last
shared uint64_t final_result;
shared uint bound_bits;  // the speculative winners' smallest true cost (bits)

// The dispatch's last workgroup. Label j - 1 is final: its constraint regions for every label
// after it (two invocations per later label: its box half and its connector half). Label j's
// speculative pass is complete: each of its bucket-0 tiles' winners is a real candidate whose
// true cost is at most its speculative one plus the weight of what j - 1's regions (none for
// j = 0) add there, so the smallest of those bounds j's best; its main pass, in the next
// dispatch, takes bucket 0 and the buckets whose lower edge that bound does not exceed. This is
// on the loop's critical path: what it reads is loaded first, and nothing waits on a store.
void finish(uint j) {
  const uint threads = PLACE_GROUP_X * PLACE_GROUP_Y;
  const uvec2 tiles_xy = placement_tiles(params.width, params.height);
  const uint tiles = tiles_xy.x * tiles_xy.y;
  const uint t = gl_LocalInvocationIndex;
  const bool sizing = j < params.order_count;
  const uint p = min(j, params.order_count - 1u);
  // (the speculative entry is read before its count: the buffer holds every tile's)
  const uint count0 = buckets[p].counts[0];
  const uint64_t first_key = t < tiles ? ATOMIC_READ(speculative[(p & 1u) * tiles + t]) : PLACEMENT_NONE;
  uint counts[PLACEMENT_BUCKETS];
  [[unroll]] for (uint b = 0u; b < PLACEMENT_BUCKETS; ++b) counts[b] = t == 0u ? buckets[p].counts[b] : 0u;
  const float lowest = uintBitsToFloat(lower[p]);
  const uint next_count0 = t == 0u && p + 1u < params.order_count ? buckets[p + 1u].counts[0] : 0u;
  const LabelGpu placed_label = labels[params.label];
  const LabelGpu me = labels[params.spec_label];
  const vec3 placed = j > 0u ? placed_from(final_result, params.label) : vec3(0.0);

  if (j > 0u) {
    const uint s = j - 1u;
    for (uint u = t; s + 1u + u / 2u < params.order_count; u += threads) {
      const uint k_pos = s + 1u + u / 2u;
      const uint slot = k_pos * params.label_count + s;
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
  if (!sizing) return;
  const PairRegionsGpu r = pair_regions(me, placed_label, placed, params.margin);
  float bound = uintBitsToFloat(0x7F800000u);
  for (uint i = t; i < count0; i += threads) {
    const uint64_t key = i == t ? first_key : ATOMIC_READ(speculative[(p & 1u) * tiles + i]);
    if (key == PLACEMENT_NONE) continue;
    const uint pixel = uint(key & 0xFFFFFFFFul);
    const uvec2 q = uvec2(pixel % params.width, pixel / params.width);
    const uint bits = region_bits(r, box_origin(q, me.size) + me.size * 0.5, 0u);
    if (params.hard != 0u && bits != 0u) continue;  // no longer allowed: bounds nothing
    bound = min(bound, cost_of(key) + constraint_weight(bits));
  }
  bound = subgroupMin(bound);
  if (subgroupElect()) atomicMin(bound_bits, floatBitsToUint(bound));  // costs >= 0
  barrier();
  if (t != 0u) return;
  // (rounding: the true cost is the free cost plus the weight of all bits, summed in another
  // order; an infinite bound stays infinite)
  const float best = uintBitsToFloat(bound_bits) * 1.0001;
  const float above = best - lowest;
  uint rest = 0u;
  [[unroll]] for (uint b = 1u; b < PLACEMENT_BUCKETS; ++b) {
    if (above >= placement_bucket_edge(b, params.bucket_width)) rest += counts[b];
  }
  buckets[p].rest = rest;
  buckets[p].bound = best;
  buckets[p].main = count0 + rest;
  // The next dispatch's size, when indirect: this main pass and the next label's speculative one.
  const uvec3 size = placement_dispatch_size(max(count0 + rest + next_count0, 1u));
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

// The tile's lowest (cost, pixel): every candidate for a speculative pass; for the main pass,
// only those whose cost is not above the best known (`bound`: the tile's lower bound).
uint64_t evaluate_tile(uint label, uvec2 tile, float bound, bool prune, float best_bound, bool write) {
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
    tile_bits = 0u;
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
    cull(me, tile);
  }
  barrier();
  hopeless = tile_hope == 0u ||
             (prune && (0.9999 * (bound + constraint_weight(tile_bits)) > best ||
                        (params.hard != 0u && tile_bits != 0u)));
  uint64_t key = PLACEMENT_NONE;
  [[unroll]] for (uint q = 0u; q < PLACE_SPAN_X * PLACE_SPAN_Y; ++q) {
    if (hopeless) break;
    if ((candidates & (1u << q)) == 0u) continue;
    const uvec2 p = candidate_pixel(base, q);
    const vec2 origin = box_origin(p, me.size);
    const vec2 centre = origin + me.size * 0.5;
    // Bits weighing more than best - cost without them lose (strictly: 0.999), so the search
    // stops there (hard mode: at the first); all of them otherwise.
    const float budget = !prune              ? 1.0 / 0.0
                         : params.hard != 0u ? 0.0
                                             : (best - free_costs[q]) / 0.999;
    const uint bits = constraint_bits(me, centre, tile_bits, budget);
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
  // (the main pass's tile is read together with the counts: neither waits for the other)
  const uint main_count = j > 0u ? buckets[j - 1u].main : 0u;
  const uint spec_count = j < params.order_count ? buckets[j].counts[0] : 0u;
  const uvec2 main_entry = tile_list[(j > 0u ? j - 1u : 0u) * tiles + min(w, tiles - 1u)];
  // The dispatch covers any count; the workgroups past these leave at once. One always stays:
  // the last to finish sizes the next dispatch.
  const uint working = max(main_count + spec_count, 1u);
  if (w >= working) return;
  const bool is_main = w < main_count;
  const uint slot = is_main ? w : w - main_count;
  const bool is_spec = !is_main && slot < spec_count;
  position = is_main ? j - 1u : j;
  placed = is_main ? position : max(position, 1u) - 1u;
  const uint label = is_main ? params.label : params.spec_label;

  uint64_t group = PLACEMENT_NONE;
  if (is_main || is_spec) {
    const uvec2 entry = is_main ? main_entry : tile_list[position * tiles + slot];
    const uint tile_index = entry.x & ~PLACEMENT_BUCKET0_TILE;
    const uvec2 tile = uvec2(tile_index % tiles_x, tile_index / tiles_x);
    // A bucket-0 tile of the main pass: its speculative minimum stands unless the label placed
    // last reaches its candidates (kept constraint images need every candidate evaluated).
    bool evaluate = true;
    if (is_main && (entry.x & PLACEMENT_BUCKET0_TILE) != 0u && params.write_constraints == 0u) {
      uint touch = 0u, full;
      if (position > 0u) {
        vec2 centre, extent;
        tile_centres(labels[label], tile, centre, extent);
        region_reach(regions_of(position, position - 1u), centre, extent, touch, full);
      }
      evaluate = touch != 0u;
      if (!evaluate) group = speculative[(position & 1u) * tiles + slot];
    }
    if (evaluate) {
      const float best_bound = is_main ? buckets[position].bound : 0.0;
      const bool keep = params.write_constraints != 0u;
      group = evaluate_tile(label, tile, uintBitsToFloat(entry.y), is_main && !keep, best_bound,
                            is_main && keep);
    }
  }
  if (gl_LocalInvocationIndex == 0u) {
    // Thousands of workgroups share one address: only those that improve on it touch it.
    if (is_main && group != PLACEMENT_NONE && group < results[label]) atomicMin(results[label], group);
    if (is_spec) atomicExchange(speculative[(position & 1u) * tiles + slot], group);
    memoryBarrierBuffer();
    finishing = atomicAdd(buckets[j].done, 1u) + 1u == working ? 1u : 0u;
    if (finishing != 0u) {
      bound_bits = 0x7F800000u;
      memoryBarrierBuffer();
      if (j > 0u) final_result = ATOMIC_READ(results[params.label]);
    }
  }
  barrier();
  if (finishing != 0u) finish(j);
}
