// Constraints (thesis 3.2.1, 4.1.1) and the cost of eq. 3.1 at one candidate position, written
// once for the GPU (place_label.comp) and the CPU reference (passes/placement_reference.cpp).
// What the includer provides (params, the placed labels' regions, the anchors, table_at) is
// placement_cost_access.h.
//
// A candidate is a pixel p; the label box then spans pixels [box_origin(p), + size) and its
// centre is box_origin + size / 2 (box_origin: shared/placement.h).

#ifndef __cplusplus
#include "placement_cost_access.h"  // (C++: the reference's struct is checked against it)
#endif
#include "placement_free_cost.h"

// A placed box or connector B constrains a new label whose anchor is a and whose box (half size
// h, margin included) is centred at c when the convex hull of a and that box touches B: the new
// box or connector would touch it. Those c form a convex region: B's "shadow" from a (B and
// everything behind it as seen from a) dilated by the box (Stein & Decoret). Its edges are
// parallel to the two silhouette rays from a past B, to B's edges that face a, or to the box's
// (axis) edges, so it is the intersection of the half-planes n.c <= support of the shadow in n +
// support of the box in n over those normals n (exact: the Minkowski sum's support function is
// the sum). B is a box (v0..v3, counter-clockwise from lo) or a segment (v0, v1 = v2 = v3).
struct ShadowPlanes {
  vec4 p[6];
};

vec4 dilated_plane(vec2 n, float support, vec2 h) {
  return vec4(n, support + abs(n.x) * h.x + abs(n.y) * h.y, 0.0f);
}

ShadowPlanes shadow_planes(vec2 a, vec2 h, vec2 v0, vec2 v1, vec2 v2, vec2 v3, bool segment) {
  ShadowPlanes r;
  for (int k = 0; k < 6; ++k) r.p[k] = vec4(0.0f);
  vec2 v[4] = {v0, v1, v2, v3};
  vec2 lo = min(min(v0, v1), min(v2, v3)), hi = max(max(v0, v1), max(v2, v3));
  vec2 e = v1 - v0;
  // a on B: the hull always touches it, every centre is constrained (all planes 0 <= 0).
  if (segment) {
    float t = dot(a - v0, e);
    bool on = e.x * (a.y - v0.y) - e.y * (a.x - v0.x) == 0.0f && t >= 0.0f && t <= dot(e, e);
    if (dot(e, e) == 0.0f) on = a == v0;
    if (on) return r;
  } else if (all(greaterThanEqual(a, lo)) && all(lessThanEqual(a, hi))) {
    return r;
  }
  // The silhouette: the directions from a to B's vertices span less than 180 degrees, so the
  // sign of a cross product orders them; the most counter-clockwise and the most clockwise
  // (the first of equals).
  vec2 d_first = v0 - a, d_last = v0 - a;
  for (int k = 1; k < 4; ++k) {
    vec2 d = v[k] - a;
    if (d_first.x * d.y - d_first.y * d.x > 0.0f) d_first = d;
    if (d_last.x * d.y - d_last.y * d.x < 0.0f) d_last = d;
  }
  // Outward normals of the two rays (every vertex lies on the inner side).
  r.p[0] = dilated_plane(vec2(-d_first.y, d_first.x), dot(vec2(-d_first.y, d_first.x), a), h);
  r.p[1] = dilated_plane(vec2(d_last.y, -d_last.x), dot(vec2(d_last.y, -d_last.x), a), h);
  // The axes along which the shadow is bounded: B lies entirely on the near side of a.
  if (hi.x <= a.x) r.p[2] = dilated_plane(vec2(1.0f, 0.0f), hi.x, h);
  if (lo.x >= a.x) r.p[3] = dilated_plane(vec2(-1.0f, 0.0f), -lo.x, h);
  if (hi.y <= a.y) r.p[4] = dilated_plane(vec2(0.0f, 1.0f), hi.y, h);
  if (lo.y >= a.y) r.p[5] = dilated_plane(vec2(0.0f, -1.0f), -lo.y, h);
  if (segment) {
    // The segment's own edge, facing a (a box's facing edges are axes, above). At most two
    // axis planes are set unless the segment has no length or lies on a line through a; the
    // ray planes then hold the region, and an axis slot is free for this one.
    vec2 n = vec2(-e.y, e.x);
    if (dot(n, a - v0) < 0.0f) n = -n;
    vec4 plane = dilated_plane(n, dot(n, v0), h);
    if (r.p[2] == vec4(0.0f))
      r.p[2] = plane;
    else if (r.p[3] == vec4(0.0f))
      r.p[3] = plane;
    else if (r.p[4] == vec4(0.0f))
      r.p[4] = plane;
    else
      r.p[5] = plane;
  }
  return r;
}

// Label k's regions against placed label j (its box centre and 1 in z if shown, else 0), in two
// halves that the GPU computes on different invocations: the box's (and the info bits) ...
struct PairBoxRegion {
  vec4 box[4];
  uvec4 info;
};

PairBoxRegion pair_box_region(LabelGpu k, LabelGpu j, vec3 placed_j, float margin) {
  PairBoxRegion r;
  for (int i = 0; i < 4; ++i) r.box[i] = vec4(0.0f);
  r.info = uvec4(0u);
  if (placed_j.z < 0.5f) return r;
  vec2 h = constraint_half_size(k, margin);
  vec2 centre = vec2(placed_j);
  vec2 lo = centre - j.size * 0.5f, hi = centre + j.size * 0.5f;
  ShadowPlanes planes =
      shadow_planes(k.anchor, h, lo, vec2(hi.x, lo.y), hi, vec2(lo.x, hi.y), false);
  // (A box's shadow has at most two axis planes: the ray planes and those two.)
  int used = 0;
  for (int i = 0; i < 6; ++i) {
    if (planes.p[i] != vec4(0.0f) && used < 4) r.box[used++] = planes.p[i];
  }
  r.info.x = REGION_BOX | ((j.flags & LABEL_INTERNAL) == 0u ? REGION_CONNECTOR : 0u);
  return r;
}

// ... and the connector's (zero planes when j is hidden or internal).
ShadowPlanes pair_connector_region(LabelGpu k, LabelGpu j, vec3 placed_j, float margin) {
  ShadowPlanes c;
  for (int i = 0; i < 6; ++i) c.p[i] = vec4(0.0f);
  if (placed_j.z < 0.5f || (j.flags & LABEL_INTERNAL) != 0u) return c;
  vec2 h = constraint_half_size(k, margin);
  vec2 centre = vec2(placed_j);
  return shadow_planes(k.anchor, h, j.anchor, centre, centre, centre, true);
}

PairRegionsGpu pair_regions(LabelGpu k, LabelGpu j, vec3 placed_j, float margin) {
  PairRegionsGpu r;
  PairBoxRegion b = pair_box_region(k, j, placed_j, margin);
  ShadowPlanes c = pair_connector_region(k, j, placed_j, margin);
  for (int i = 0; i < 4; ++i) r.box[i] = b.box[i];
  for (int i = 0; i < 6; ++i) r.connector[i] = c.p[i];
  r.info = b.info;
  return r;
}

// Does the box-shadow or connector-shadow region (4 or 6 planes) hold the centre c?
bool region_holds(vec4 p0, vec4 p1, vec4 p2, vec4 p3, vec4 p4, vec4 p5, vec2 c) {
  return dot(vec2(p0), c) <= p0.z && dot(vec2(p1), c) <= p1.z && dot(vec2(p2), c) <= p2.z &&
         dot(vec2(p3), c) <= p3.z && dot(vec2(p4), c) <= p4.z && dot(vec2(p5), c) <= p5.z;
}

// The label- and connector-shadow bits label j gives the label being placed at centre c, from
// their regions; `known` bits are not tested again.
uint region_bits(PairRegionsGpu r, vec2 c, uint known) {
  uint bits = 0u;
  if ((r.info.x & REGION_BOX) != 0u && (known & CONSTRAINT_LABEL) == 0u &&
      region_holds(r.box[0], r.box[1], r.box[2], r.box[3], vec4(0.0f), vec4(0.0f), c)) {
    bits |= CONSTRAINT_LABEL;
  }
  if ((r.info.x & REGION_CONNECTOR) != 0u && (known & CONSTRAINT_CONNECTOR) == 0u &&
      region_holds(r.connector[0], r.connector[1], r.connector[2], r.connector[3], r.connector[4],
                   r.connector[5], c)) {
    bits |= CONSTRAINT_CONNECTOR;
  }
  return bits;
}

// What eq. 3.1 adds for the constraint bits.
float constraint_weight(uint bits) {
  float sum = 0.0f;
  if ((bits & CONSTRAINT_LABEL) != 0u) sum += params.weights.label_shadow;
  if ((bits & CONSTRAINT_CONNECTOR) != 0u) sum += params.weights.connector_shadow;
  if ((bits & CONSTRAINT_ANCHOR) != 0u) sum += params.weights.anchor_constraint;
  return sum;
}

// The constraint bits of placing label `me` with its box centred at c. Kinds already in `known`
// are not tested again (a GPU tile may know them for all its candidates). The search stops once
// the bits found weigh more than `budget` (the GPU's candidates that cannot win any more; the
// CPU reference passes infinity and always gets every bit). The label loop runs it for an
// invocation's four candidates at once (candidate_bits in place_label_evaluate.glsl), the debug
// view and the reference one candidate at a time.
uint constraint_bits(LabelGpu me, vec2 c, uint known, float budget) {
  vec2 h = constraint_half_size(me, params.margin);
  const uint shadows = CONSTRAINT_LABEL | CONSTRAINT_CONNECTOR;
  uint bits = known;
  for (uint k = 0u; k < placed_count() && (bits & shadows) != shadows; ++k) {
    bits |= region_bits(placed_regions(k), c, bits);
    if (constraint_weight(bits) > budget) return bits;
  }
  if ((me.flags & LABEL_INTERNAL) == 0u && (bits & CONSTRAINT_ANCHOR) == 0u) {
    for (uint k = 0u; k < anchor_count(); ++k) {
      vec2 d = abs(anchor_at(k) - c);
      if (d.x <= h.x && d.y <= h.y) return bits | CONSTRAINT_ANCHOR;
    }
  }
  return bits;
}

// Eq. 3.1 at centre c with the given constraint bits: the free cost plus their weight (added
// last, so the GPU adds them to a free cost it already has and gets the same float).
float candidate_cost(LabelGpu me, vec2 origin, vec2 c, uint bits) {
  return free_cost(me, origin, c) + constraint_weight(bits);
}
