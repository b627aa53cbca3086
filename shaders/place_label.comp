#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
#include "shared/placement.h"

// One label: constraints, eq. 3.1 and the argmin at every pixel, in one dispatch. The result
// (cost bits << 32 | pixel) goes to results[label] with one 64-bit atomicMin per workgroup; the
// next label's dispatch reads it there, so the greedy loop never returns to the CPU.
layout(local_size_x = PLACEMENT_GROUP, local_size_y = PLACEMENT_GROUP) in;
layout(binding = PLACEMENT_BINDING_TABLES, std430) readonly buffer Tables { float tables[]; };
layout(binding = PLACEMENT_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = PLACEMENT_BINDING_ORDER, std430) readonly buffer Order { uint order[]; };
// coherent: the bound read below sees other workgroups' atomicMin results (a stale value is only
// a weaker bound, never a wrong one: results only decrease).
layout(binding = PLACEMENT_BINDING_RESULTS, std430) coherent buffer Results { uint64_t results[]; };
layout(binding = PLACEMENT_BINDING_CONSTRAINTS, std430) writeonly buffer Constraints { uint constraints[]; };
layout(push_constant) uniform Push { PlacementParams params; };

// The placed labels and anchors this tile's candidates can reach (culled once per tile).
shared uint tile_placed[LABEL_MAX];
shared uint tile_placed_count;
shared uint tile_anchors[LABEL_MAX];
shared uint tile_anchor_count;
shared uint tile_bits;  // constraints every candidate of the tile has

LabelGpu label_at(uint i) { return labels[i]; }
uint placed_count() { return tile_placed_count; }
uint placed_label(uint k) { return tile_placed[k]; }
uint anchor_count() { return tile_anchor_count; }
uint anchor_label(uint k) { return tile_anchors[k]; }
vec3 placed(uint j) {
  const uint64_t r = results[j];
  if (r == PLACEMENT_NONE) return vec3(0.0);
  const uint pixel = uint(r & 0xFFFFFFFFul);
  const uvec2 p = uvec2(pixel % params.width, pixel / params.width);
  return vec3(box_origin(p, labels[j].size) + labels[j].size * 0.5, 1.0);
}
float table_at(uint layer, int x, int y) {
  if (x < 0 || y < 0) return 0.0;
  return tables[layer * params.width * params.height + uint(y) * params.width + uint(x)];
}

#include "shared/placement_cost.h"

shared uint64_t group_best[PLACEMENT_GROUP * PLACEMENT_GROUP];

// The rectangle of box centres this tile's candidates have (centre and half size).
void tile_centres(LabelGpu me, out vec2 centre, out vec2 extent) {
  const vec2 first = box_origin(gl_WorkGroupID.xy * PLACEMENT_GROUP, me.size) + me.size * 0.5;
  extent = vec2(0.5 * float(PLACEMENT_GROUP - 1));
  centre = first + extent;
}

// The integral costs every candidate box of the tile covers: the part all their boxes share
// (integral costs are >= 0, so each box's integral is at least this).
float shared_box_integral(LabelGpu me) {
  const vec2 first = box_origin(gl_WorkGroupID.xy * PLACEMENT_GROUP, me.size);
  const vec2 lo = max(first + vec2(float(PLACEMENT_GROUP - 1)), vec2(0.0));
  const vec2 hi = min(first + me.size, vec2(params.width, params.height));
  if (hi.x <= lo.x || hi.y <= lo.y) return 0.0;
  return max(box_integral(me.layer, lo, hi - lo), 0.0);
}

// The bits a constraint region sets at all four corners of the tile's centre region: each
// region (a dilated shadow, an anchor's box) is convex, so it then holds every candidate.
uint corner_bits(uint label, vec2 centre, vec2 extent, uint j_or_anchor, bool anchor) {
  uint all = 0xFFFFFFFFu;
  for (int k = 0; k < 4; ++k) {
    const vec2 c = centre + extent * vec2((k & 1) != 0 ? 1.0 : -1.0, (k & 2) != 0 ? 1.0 : -1.0);
    if (anchor) {
      const vec2 h = labels[label].size * 0.5 + vec2(params.margin);
      const vec2 d = abs(labels[j_or_anchor].anchor - c);
      all &= (d.x <= h.x && d.y <= h.y) ? CONSTRAINT_ANCHOR : 0u;
    } else {
      const vec2 h = labels[label].size * 0.5 + vec2(params.margin);
      all &= placed_bits(labels[label], c, h, j_or_anchor, 0u);
    }
  }
  return all;
}

void cull(LabelGpu me, uint label) {
  if (gl_LocalInvocationIndex == 0u) {
    tile_placed_count = 0u;
    tile_anchor_count = 0u;
    tile_bits = 0u;
  }
  barrier();
  vec2 centre, extent;
  tile_centres(me, centre, extent);
  const uint threads = PLACEMENT_GROUP * PLACEMENT_GROUP;
  for (uint s = gl_LocalInvocationIndex; s < params.step; s += threads) {
    const uint j = order[s];
    if (!may_constrain(me, centre, extent, j)) continue;
    const uint full = corner_bits(label, centre, extent, j, false);
    if (full != 0u) atomicOr(tile_bits, full);
    if (full != (CONSTRAINT_LABEL | CONSTRAINT_CONNECTOR)) tile_placed[atomicAdd(tile_placed_count, 1u)] = j;
  }
  const vec2 reach = extent + me.size * 0.5 + vec2(params.margin);
  for (uint k = gl_LocalInvocationIndex; k < params.label_count; k += threads) {
    if ((labels[k].flags & LABEL_ENABLED) == 0u) continue;
    const vec2 d = abs(labels[k].anchor - centre);
    if (d.x > reach.x || d.y > reach.y) continue;
    if (corner_bits(label, centre, extent, k, true) != 0u) atomicOr(tile_bits, CONSTRAINT_ANCHOR);
    else tile_anchors[atomicAdd(tile_anchor_count, 1u)] = k;
  }
  barrier();
}

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  const uint label = order[params.step];
  const LabelGpu me = labels[label];
  cull(me, label);
  // A lower bound of every candidate's cost in this tile: the distance term at the nearest
  // centre, the smallest direction term (1), the constraints the whole tile has, the integral
  // over the part all its boxes share; the previous-position term is >= 0. If another workgroup
  // already found something cheaper, no candidate here can be the argmin (strictly greater: ties
  // cannot be lost either). The full constraint image (tests, debugging) needs every tile.
  vec2 centre, extent;
  tile_centres(me, centre, extent);
  const vec2 gap = max(abs(me.anchor - centre) - extent, vec2(0.0));
  float bound = params.weights.distance_to_anchor * length(gap) + params.weights.connector_direction;
  if ((tile_bits & CONSTRAINT_LABEL) != 0u) bound += params.weights.label_shadow;
  if ((tile_bits & CONSTRAINT_CONNECTOR) != 0u) bound += params.weights.connector_shadow;
  if ((tile_bits & CONSTRAINT_ANCHOR) != 0u) bound += params.weights.anchor_constraint;
  // (0.999: the tables' float sums of the shared part and of a box can differ in the last bits.)
  bound += 0.999 * params.weights.integral_costs * shared_box_integral(me);
  const uint64_t best_so_far = results[label];
  const bool hopeless = params.write_constraints == 0u && (me.flags & LABEL_INTERNAL) == 0u &&
                        best_so_far != PLACEMENT_NONE &&
                        bound > uintBitsToFloat(uint(best_so_far >> 32));
  uint64_t key = PLACEMENT_NONE;
  if (!hopeless && p.x < params.width && p.y < params.height && candidate_allowed(me, p)) {
    const vec2 origin = box_origin(p, me.size);
    const vec2 centre = origin + me.size * 0.5;
    const uint bits = constraint_bits(label, centre, tile_bits);
    const uint pixel = p.y * params.width + p.x;
    if (params.write_constraints != 0u) constraints[pixel] = bits;
    if (params.hard == 0u || bits == 0u) {
      const float cost = candidate_cost(me, origin, centre, bits);
      key = (uint64_t(floatBitsToUint(cost)) << 32) | uint64_t(pixel);  // costs are >= 0
    }
  }
  // Lowest cost, then lowest pixel index: the subgroup's minimum cost, then the first pixel with it.
  const uint cost_bits = uint(key >> 32);
  const uint best_bits = subgroupMin(cost_bits);
  const uint best_pixel = subgroupMin(cost_bits == best_bits ? uint(key) : 0xFFFFFFFFu);
  if (subgroupElect()) group_best[gl_SubgroupID] = (uint64_t(best_bits) << 32) | uint64_t(best_pixel);
  barrier();
  if (gl_LocalInvocationIndex == 0u) {
    uint64_t best = PLACEMENT_NONE;
    for (uint s = 0u; s < gl_NumSubgroups; ++s) best = min(best, group_best[s]);
    // Thousands of workgroups share one address: only those that improve on it touch it.
    if (best < results[label]) atomicMin(results[label], best);
  }
}
