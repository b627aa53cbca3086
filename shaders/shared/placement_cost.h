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

// Does the hull of the new label's anchor a and its box (centre c, half size h) touch the
// axis-aligned box [lo, hi]? The hull is what the new label and its connector cover; a placed
// box touching it lies in the new anchor's "shadow" dilated by the new box (Stein & Decoret).
// Separating axes: x, y and the normals of the four lines from a to the box corners (a superset
// of the hull's edge normals, so the test is exact).
float project_min(vec2 n, vec2 a, vec2 c, vec2 h) {
  float m = dot(n, a);
  m = min(m, dot(n, c + vec2(-h.x, -h.y)));
  m = min(m, dot(n, c + vec2(h.x, -h.y)));
  m = min(m, dot(n, c + vec2(h.x, h.y)));
  return min(m, dot(n, c + vec2(-h.x, h.y)));
}
float project_max(vec2 n, vec2 a, vec2 c, vec2 h) {
  float m = dot(n, a);
  m = max(m, dot(n, c + vec2(-h.x, -h.y)));
  m = max(m, dot(n, c + vec2(h.x, -h.y)));
  m = max(m, dot(n, c + vec2(h.x, h.y)));
  return max(m, dot(n, c + vec2(-h.x, h.y)));
}

// True when axis n separates the hull from the segment p0-p1 (a box is handled as its two
// diagonals' end points: its projection is the projection of its corners).
bool separates(vec2 n, vec2 a, vec2 c, vec2 h, vec2 q0, vec2 q1, vec2 q2, vec2 q3) {
  float lo = min(min(dot(n, q0), dot(n, q1)), min(dot(n, q2), dot(n, q3)));
  float hi = max(max(dot(n, q0), dot(n, q1)), max(dot(n, q2), dot(n, q3)));
  return project_max(n, a, c, h) < lo || hi < project_min(n, a, c, h);
}

// Does the hull of a and box(c, h) touch the convex set with corners q0..q3 (a box, or a segment
// given as q0 = q2, q1 = q3)? `extra` is one more axis to try (the segment's normal).
bool hull_touches(vec2 a, vec2 c, vec2 h, vec2 q0, vec2 q1, vec2 q2, vec2 q3, vec2 extra) {
  if (separates(vec2(1.0f, 0.0f), a, c, h, q0, q1, q2, q3)) return false;
  if (separates(vec2(0.0f, 1.0f), a, c, h, q0, q1, q2, q3)) return false;
  if (separates(extra, a, c, h, q0, q1, q2, q3)) return false;
  vec2 corners[4] = {c + vec2(-h.x, -h.y), c + vec2(h.x, -h.y), c + vec2(h.x, h.y), c + vec2(-h.x, h.y)};
  for (int k = 0; k < 4; ++k) {
    vec2 d = corners[k] - a;
    if (abs(d.x) + abs(d.y) < 1e-6f) continue;
    if (separates(vec2(-d.y, d.x), a, c, h, q0, q1, q2, q3)) return false;
  }
  return true;
}

// The label- and connector-shadow bits placed label j gives the new label `me` at centre c
// (its box's half size h includes the margin).
uint placed_bits(LabelGpu me, vec2 c, vec2 h, uint j, uint known) {
  vec3 other = placed(j);
  if (other.z < 0.5f) return 0u;
  LabelGpu them = label_at(j);
  uint bits = 0u;
  vec2 lo = vec2(other) - them.size * 0.5f, hi = vec2(other) + them.size * 0.5f;
  if ((known & CONSTRAINT_LABEL) == 0u &&
      hull_touches(me.anchor, c, h, lo, vec2(hi.x, lo.y), hi, vec2(lo.x, hi.y), vec2(1.0f, 0.0f))) {
    bits |= CONSTRAINT_LABEL;
  }
  if ((known & CONSTRAINT_CONNECTOR) == 0u && (them.flags & LABEL_INTERNAL) == 0u) {
    vec2 p0 = them.anchor, p1 = vec2(other), d = p1 - p0;
    if (hull_touches(me.anchor, c, h, p0, p1, p0, p1, vec2(-d.y, d.x))) bits |= CONSTRAINT_CONNECTOR;
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

// Could label j (placed) or its connector constrain any candidate whose box, half size h, is
// centred in the rectangle around `centre` of half size `extent`? The hull of the anchor and
// that whole region contains every candidate's hull, so "no" is exact: a GPU tile skips j.
bool may_constrain(LabelGpu me, vec2 centre, vec2 extent, uint j) {
  vec3 other = placed(j);
  if (other.z < 0.5f) return false;
  LabelGpu them = label_at(j);
  vec2 h = extent + me.size * 0.5f + vec2(params.margin);
  vec2 lo = vec2(other) - them.size * 0.5f, hi = vec2(other) + them.size * 0.5f;
  if (hull_touches(me.anchor, centre, h, lo, vec2(hi.x, lo.y), hi, vec2(lo.x, hi.y), vec2(1.0f, 0.0f))) {
    return true;
  }
  if ((them.flags & LABEL_INTERNAL) != 0u) return false;
  vec2 p0 = them.anchor, p1 = vec2(other), d = p1 - p0;
  return hull_touches(me.anchor, centre, h, p0, p1, p0, p1, vec2(-d.y, d.x));
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
