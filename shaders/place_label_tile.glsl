// Included by place_label.comp (after shared/placement_cost.h): what all candidates of a 32x32
// tile share, the rectangle of their box centres, and the tests of a constraint region or an
// anchor against all of them at once.

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
