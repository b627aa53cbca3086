// Constraints (thesis 3.2.1, 4.1.1) and the cost of eq. 3.1 at one candidate position, written
// once for the GPU (place_label.comp) and the CPU reference (labeling/placement_reference.cpp).
// The includer provides:
//   params                         PlacementParams
//   LabelGpu label_at(uint i)
//   uint placed_count()            how many labels to test against (those placed so far, or the
//   uint placed_label(uint k)      ... ones a GPU tile's candidates can reach), and which
//   uint anchor_count()            how many anchors to test against, and which
//   uint anchor_label(uint k)
//   vec3 placed(uint j)            label j's box centre (xy) and 1 in z if it is shown, else 0
//   float table_at(uint layer, int x, int y)   summed-area table of the layer's integral costs
//
// A candidate is a pixel p; the label box then spans pixels [box_origin(p), + size) and its
// centre is box_origin + size / 2 (box_origin: shared/placement.h).

// A dilated shadow as half-planes: the candidate centres c with dot(plane.xy, c) <= plane.z for
// every plane (kind REGION_PLANES_ONLY), or every c, or none.
struct Region {
  vec3 planes[REGION_PLANES];
  uint count;
  uint kind;
};

// The centres c at which the box of half size h, together with the anchor a, touches the convex
// set with vertices q0..q3 (n = 4: a box, corners in order; n = 2: the segment q0-q1). That set
// is the shadow of the convex set seen from a, dilated by the box (a Minkowski sum of two convex
// polygons), so it is the intersection of half-planes along both polygons' edge normals: the
// axes (the box's, and the placed box's) and the perpendiculars of the lines from a through the
// vertices (the shadow's two tangents, and for a segment its own normal). A normal along which
// the shadow is unbounded (some ray from a through a vertex points along it) gives no plane.
Region shadow_region(vec2 a, vec2 q0, vec2 q1, vec2 q2, vec2 q3, uint n, vec2 h) {
  Region r;
  r.count = 0u;
  r.kind = REGION_PLANES_ONLY;
  vec2 q[4] = {q0, q1, q2, q3};
  if (n == 4u) {
    if (a.x >= min(q0.x, q2.x) && a.x <= max(q0.x, q2.x) && a.y >= min(q0.y, q2.y) &&
        a.y <= max(q0.y, q2.y)) {
      r.kind = REGION_EVERYWHERE;  // the anchor lies on the placed box
      return r;
    }
  } else {
    vec2 d = q1 - q0, e = a - q0;
    if (abs(d.x * e.y - d.y * e.x) <= 1e-6f * dot(d, d) && dot(e, d) >= 0.0f && dot(e, d) <= dot(d, d)) {
      r.kind = REGION_EVERYWHERE;  // the anchor lies on the placed connector
      return r;
    }
  }
  vec2 normals[REGION_PLANES];
  uint m = 0u;
  normals[m++] = vec2(1.0f, 0.0f);
  normals[m++] = vec2(-1.0f, 0.0f);
  normals[m++] = vec2(0.0f, 1.0f);
  normals[m++] = vec2(0.0f, -1.0f);
  for (uint k = 0u; k < n; ++k) {
    vec2 d = q[k] - a;
    normals[m++] = vec2(-d.y, d.x);
    normals[m++] = vec2(d.y, -d.x);
  }
  if (n == 2u) {
    vec2 d = q1 - q0;
    normals[m++] = vec2(-d.y, d.x);
    normals[m++] = vec2(d.y, -d.x);
  }
  for (uint k = 0u; k < m; ++k) {
    vec2 nn = normals[k];
    bool bounded = true;
    float support = -3.4e38f;
    for (uint v = 0u; v < n; ++v) {
      vec2 d = q[v] - a;
      if (dot(nn, d) > 1e-5f * length(nn) * length(d)) bounded = false;
      support = max(support, dot(nn, q[v]));
    }
    if (!bounded) continue;
    r.planes[r.count] = vec3(nn, support + h.x * abs(nn.x) + h.y * abs(nn.y));
    r.count += 1u;
  }
  return r;
}

// Touching counts (as in the separating-axis view): a centre exactly on a plane, up to float
// rounding, is inside.
bool in_region(Region r, vec2 c) {
  if (r.kind != REGION_PLANES_ONLY) return r.kind == REGION_EVERYWHERE;
  for (uint k = 0u; k < r.count; ++k) {
    if (dot(vec2(r.planes[k]), c) > r.planes[k].z + 1e-5f * (abs(r.planes[k].z) + 1.0f)) return false;
  }
  return true;
}

// The dilated shadow of placed label j's box, and of its connector, for the new label `me`
// (h: the new box's half size with the margin).
Region label_shadow_region(LabelGpu me, vec2 h, uint j) {
  vec3 other = placed(j);
  LabelGpu them = label_at(j);
  vec2 lo = vec2(other) - them.size * 0.5f, hi = vec2(other) + them.size * 0.5f;
  return shadow_region(me.anchor, lo, vec2(hi.x, lo.y), hi, vec2(lo.x, hi.y), 4u, h);
}
Region connector_shadow_region(LabelGpu me, vec2 h, uint j) {
  LabelGpu them = label_at(j);
  if ((them.flags & LABEL_INTERNAL) != 0u) {
    Region none;
    none.count = 0u;
    none.kind = REGION_NOWHERE;
    return none;
  }
  vec3 other = placed(j);
  return shadow_region(me.anchor, them.anchor, vec2(other), them.anchor, vec2(other), 2u, h);
}

// The label- and connector-shadow bits placed label j gives the new label `me` at centre c.
uint placed_bits(LabelGpu me, vec2 c, vec2 h, uint j, uint known) {
  if (placed(j).z < 0.5f) return 0u;
  uint bits = 0u;
  if ((known & CONSTRAINT_LABEL) == 0u && in_region(label_shadow_region(me, h, j), c)) {
    bits |= CONSTRAINT_LABEL;
  }
  if ((known & CONSTRAINT_CONNECTOR) == 0u && in_region(connector_shadow_region(me, h, j), c)) {
    bits |= CONSTRAINT_CONNECTOR;
  }
  return bits;
}

// The constraint bits of placing label i with its box centred at c. Kinds already in `known`
// are not tested again (a GPU tile may know them for all its candidates).
uint constraint_bits(uint i, vec2 c, uint known) {
  LabelGpu me = label_at(i);
  vec2 h = me.size * 0.5f + vec2(params.margin);
  const uint shadows = CONSTRAINT_LABEL | CONSTRAINT_CONNECTOR;
  uint bits = known;
  for (uint k = 0u; k < placed_count() && (bits & shadows) != shadows; ++k) {
    bits |= placed_bits(me, c, h, placed_label(k), bits);
  }
  if ((me.flags & LABEL_INTERNAL) == 0u && (bits & CONSTRAINT_ANCHOR) == 0u) {
    for (uint k = 0u; k < anchor_count(); ++k) {
      LabelGpu other = label_at(anchor_label(k));
      if ((other.flags & LABEL_ENABLED) == 0u) continue;
      vec2 d = abs(other.anchor - c);
      if (d.x <= h.x && d.y <= h.y) bits |= CONSTRAINT_ANCHOR;
    }
  }
  return bits;
}

// The sum of the layer's integral costs over the box of `size` pixels at `origin`.
float box_integral(uint layer, vec2 origin, vec2 size) {
  int x0 = int(origin.x), y0 = int(origin.y);
  int x1 = x0 + int(size.x) - 1, y1 = y0 + int(size.y) - 1;
  return table_at(layer, x1, y1) - table_at(layer, x0 - 1, y1) - table_at(layer, x1, y0 - 1) +
         table_at(layer, x0 - 1, y0 - 1);
}

// Whether pixel p may hold the label at all: its box lies on screen (internal labels: only the
// anchor's own pixel).
bool candidate_allowed(LabelGpu me, uvec2 p) {
  if ((me.flags & LABEL_INTERNAL) != 0u) return uvec2(me.anchor) == p;
  vec2 o = box_origin(p, me.size);
  return o.x >= 0.0f && o.y >= 0.0f && o.x + me.size.x <= float(params.width) &&
         o.y + me.size.y <= float(params.height);
}

// Eq. 3.1 at centre c with the given constraint bits.
float candidate_cost(LabelGpu me, vec2 origin, vec2 c, uint bits) {
  CostWeightsGpu w = params.weights;
  vec2 d = c - me.anchor;
  float distance = length(d);
  float direction = distance > 0.0f ? (abs(d.x) + abs(d.y)) / distance : 1.0f;
  float cost = w.distance_to_anchor * distance + w.connector_direction * direction;
  if ((bits & CONSTRAINT_LABEL) != 0u) cost += w.label_shadow;
  if ((bits & CONSTRAINT_CONNECTOR) != 0u) cost += w.connector_shadow;
  if ((bits & CONSTRAINT_ANCHOR) != 0u) cost += w.anchor_constraint;
  cost += w.integral_costs * max(box_integral(me.layer, origin, me.size), 0.0f);
  cost += w.previous_position * length(c - me.previous);
  return cost;
}
