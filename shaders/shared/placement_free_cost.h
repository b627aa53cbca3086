// Eq. 3.1 without its constraint terms, and where a label may go at all: written once for the
// label loop (place_label.comp, through placement_cost.h), the tidy-up
// (placement_tidy.comp, through tidy.h) and their CPU references. What the includer provides
// (params, table_at) is placement_free_cost_access.h.

#ifndef __cplusplus
#include "placement_free_cost_access.h"  // (C++: the reference's struct is checked against it)
#endif

// The sum of a table's layer over the box of `size` pixels at `origin`, the part on screen (an
// internal label's box may reach past the image's right or bottom edge; left of it and above,
// table_at gives 0).
float box_integral(uint layer, vec2 origin, vec2 size) {
  int x0 = int(origin.x), y0 = int(origin.y);
  int x1 = min(x0 + int(size.x), int(params.width)) - 1;
  int y1 = min(y0 + int(size.y), int(params.height)) - 1;
  return table_at(layer, x1, y1) - table_at(layer, x0 - 1, y1) - table_at(layer, x1, y0 - 1) +
         table_at(layer, x0 - 1, y0 - 1);
}

// Whether a viewer can read the label's box at `origin`: at least LEGIBLE_SHARE of its pixels on
// screen and not hidden by the layers in front of the label's (the counts are whole numbers,
// exact in the float tables).
bool box_legible(LabelGpu me, vec2 origin) {
  ivec2 lo = max(ivec2(origin), ivec2(0));
  ivec2 hi = min(ivec2(origin) + ivec2(me.size), ivec2(params.width, params.height));
  float on_screen = float(max(hi.x - lo.x, 0) * max(hi.y - lo.y, 0));
  float hidden = box_integral(params.layer_count + me.layer, origin, me.size);
  return on_screen - hidden >= LEGIBLE_SHARE * float(int(me.size.x) * int(me.size.y));
}

// Whether the box at origin o touches a keep-out rectangle (keep_out_at, [lo, hi) pixels).
bool box_kept_out(LabelGpu me, vec2 o) {
  for (uint i = 0u; i < params.keep_out_count; ++i) {
    uvec4 k = keep_out_at(i);
    vec2 lo = vec2(float(k.x), float(k.y));
    vec2 hi = vec2(float(k.z), float(k.w));
    if (all(lessThan(o, hi)) && all(lessThan(lo, o + me.size))) return true;
  }
  return false;
}

// Whether pixel p may hold the label at all: its box lies on screen, params.edge clear of its
// edges (internal labels: only the anchor's own pixel), off the keep-out rectangles and, in hard
// mode, is legible.
bool candidate_allowed(LabelGpu me, uvec2 p) {
  if (box_kept_out(me, box_origin(p, me.size))) return false;
  if ((me.flags & LABEL_INTERNAL) != 0u) {
    if (uvec2(me.anchor) != p) return false;
  } else {
    vec2 o = box_origin(p, me.size);
    float m = params.edge;
    if (o.x < m || o.y < m || o.x + me.size.x > float(params.width) - m ||
        o.y + me.size.y > float(params.height) - m) {
      return false;
    }
  }
  return params.hard == 0u || box_legible(me, box_origin(p, me.size));
}

// Eq. 3.1 at centre c without its constraint terms: distance, direction, integral costs,
// previous position; and strata's own term for a box the front layers hide.
float free_cost(LabelGpu me, vec2 origin, vec2 c) {
  CostWeightsGpu w = params.weights;
  vec2 d = c - me.anchor;
  float distance = length(d);
  float direction = distance > 0.0f ? (abs(d.x) + abs(d.y)) / distance : 1.0f;
  float cost = w.distance_to_anchor * distance + w.connector_direction * direction;
  cost += w.integral_costs * max(box_integral(me.layer, origin, me.size), 0.0f);
  cost += w.previous_position * length(c - me.previous);
  if (!holds(me, c)) cost += me.hold;
  if (w.illegible > 0.0f && !box_legible(me, origin)) cost += w.illegible;
  return cost;
}
