// Eq. 3.1 without its constraint terms, and where a label may go at all: written once for the
// label loop (place_label.comp, through placement_cost.h), the layout tidy-up
// (placement_finalize.comp, through layout_tidy.h) and their CPU references. The includer
// provides params (PlacementParams) and
//   float table_at(uint layer, int x, int y)   summed-area table of the layer's integral costs

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

// Eq. 3.1 at centre c without its constraint terms: distance, direction, integral costs,
// previous position.
float free_cost(LabelGpu me, vec2 origin, vec2 c) {
  CostWeightsGpu w = params.weights;
  vec2 d = c - me.anchor;
  float distance = length(d);
  float direction = distance > 0.0f ? (abs(d.x) + abs(d.y)) / distance : 1.0f;
  float cost = w.distance_to_anchor * distance + w.connector_direction * direction;
  cost += w.integral_costs * max(box_integral(me.layer, origin, me.size), 0.0f);
  cost += w.previous_position * length(c - me.previous);
  if (!holds(me, c)) cost += me.hold;
  return cost;
}
