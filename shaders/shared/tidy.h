// The tidy-up after the greedy placement: a local search that swaps two labels' boxes,
// moves one label's box to a nearby position, or hides a label whose box overlaps an earlier
// one's, each only when it lowers the layout's cost
//   J = sum over the placed labels of eq. 3.1 without its constraint terms (free_cost)
//     + leader_crossing x (leader pairs that cross + leaders entering another label's box)
//     + label_shadow x (box pairs sharing area) + anchor_constraint x (anchors inside a box)
//     + label_shadow per label the tidy-up hides.
// The greedy placement only sees the labels placed before each one, as shadows, and in soft
// mode takes a violation when it is cheaper than the free positions, so crossings that come from
// the insertion order stay; J sees the finished layout. Written once for the GPU
// (placement_tidy.comp, one workgroup) and the CPU reference (passes/placement_reference.cpp),
// which apply the same rounds in the same order.
//
// Geometry is exact: positions in fixed point (1/TIDY_SUBPIXEL pixel, anchors rounded to it;
// boxes lie on whole pixels), the predicates in 64-bit integers, so the GPU and the CPU decide
// alike. The definitions are those of `strata eval` (labeling/layout_metrics.h).
//
// Its constants and TidyLabel are in shared/placement.h. The includer provides params and
// table_at (placement_free_cost_access.h).

#include "placement_free_cost.h"

int64_t tidy_orient(ivec2 a, ivec2 b, ivec2 c) {
  return int64_t(b.x - a.x) * int64_t(c.y - a.y) - int64_t(b.y - a.y) * int64_t(c.x - a.x);
}

int tidy_sign(int64_t v) {
  return v > int64_t(0) ? 1 : v < int64_t(0) ? -1 : 0;
}

// The leader's far end: the box's point closest to the anchor (the anchor itself when it lies in
// the closed box: no leader).
ivec2 tidy_leader_end(TidyLabel l) {
  return clamp(l.anchor, l.lo, l.hi);
}

bool tidy_has_leader(TidyLabel l) {
  return (l.flags & TIDY_PLACED) != 0u && tidy_leader_end(l) != l.anchor;
}

// Segments crossing at one point inside both (touching and collinear are not crossings).
bool tidy_segments_cross(ivec2 a, ivec2 b, ivec2 c, ivec2 d) {
  return tidy_sign(tidy_orient(a, b, c)) * tidy_sign(tidy_orient(a, b, d)) < 0 &&
         tidy_sign(tidy_orient(c, d, a)) * tidy_sign(tidy_orient(c, d, b)) < 0;
}

// Some point of segment ab strictly inside the box: the open box and the segment overlap along
// both axes and the segment's line has box corners strictly on both sides (separating axes).
bool tidy_segment_enters(ivec2 a, ivec2 b, ivec2 lo, ivec2 hi) {
  if (min(a.x, b.x) >= hi.x || max(a.x, b.x) <= lo.x) return false;
  if (min(a.y, b.y) >= hi.y || max(a.y, b.y) <= lo.y) return false;
  int s0 = tidy_sign(tidy_orient(a, b, lo));
  int s1 = tidy_sign(tidy_orient(a, b, ivec2(hi.x, lo.y)));
  int s2 = tidy_sign(tidy_orient(a, b, hi));
  int s3 = tidy_sign(tidy_orient(a, b, ivec2(lo.x, hi.y)));
  return min(min(s0, s1), min(s2, s3)) < 0 && max(max(s0, s1), max(s2, s3)) > 0;
}

bool tidy_strictly_inside(ivec2 p, ivec2 lo, ivec2 hi) {
  return p.x > lo.x && p.x < hi.x && p.y > lo.y && p.y < hi.y;
}

// Does label a's box cover b's anchor?
bool tidy_covers(TidyLabel a, TidyLabel b) {
  return (b.flags & TIDY_ANCHOR) != 0u && tidy_strictly_inside(b.anchor, a.lo, a.hi);
}

// What two labels do to each other: x leader crossings, y leaders entering the other's box,
// z boxes sharing area, w anchors inside the other's box.
ivec4 tidy_conflicts(TidyLabel a, TidyLabel b) {
  ivec4 c = ivec4(0);
  bool a_box = (a.flags & TIDY_PLACED) != 0u, b_box = (b.flags & TIDY_PLACED) != 0u;
  if (a_box && tidy_covers(a, b)) c.w += 1;
  if (b_box && tidy_covers(b, a)) c.w += 1;
  if (!a_box || !b_box) return c;
  if (min(a.hi.x, b.hi.x) > max(a.lo.x, b.lo.x) && min(a.hi.y, b.hi.y) > max(a.lo.y, b.lo.y)) {
    c.z = 1;
  }
  bool a_leader = tidy_has_leader(a), b_leader = tidy_has_leader(b);
  ivec2 a_end = tidy_leader_end(a), b_end = tidy_leader_end(b);
  if (a_leader && b_leader && tidy_segments_cross(a.anchor, a_end, b.anchor, b_end)) c.x = 1;
  if (a_leader && tidy_segment_enters(a.anchor, a_end, b.lo, b.hi)) c.y += 1;
  if (b_leader && tidy_segment_enters(b.anchor, b_end, a.lo, a.hi)) c.y += 1;
  return c;
}

// J's weight of conflict counts (small integers: exact in float).
float tidy_weight(ivec4 c) {
  return float(c.x + c.y) * params.weights.leader_crossing +
         float(c.z) * params.weights.label_shadow + float(c.w) * params.weights.anchor_constraint;
}

// Whether a rectangle around everything a label's box and leader cover (old or new) can touch
// another's: when not, the two cannot conflict.
bool tidy_rects_touch(ivec4 r, ivec4 s) {
  return r.x <= s.z && s.x <= r.z && r.y <= s.w && s.y <= r.w;
}

ivec4 tidy_extent(TidyLabel l) {
  ivec2 lo = l.anchor, hi = l.anchor;
  if ((l.flags & TIDY_PLACED) != 0u) {
    lo = min(lo, l.lo);
    hi = max(hi, l.hi);
  }
  return ivec4(lo.x, lo.y, hi.x, hi.y);
}

ivec4 tidy_union(ivec4 r, ivec4 s) {
  return ivec4(min(r.x, s.x), min(r.y, s.y), max(r.z, s.z), max(r.w, s.w));
}

// The label at candidate pixel p (placement's convention: box_origin), placed.
TidyLabel tidy_at_pixel(TidyLabel l, LabelGpu me, uvec2 p) {
  vec2 origin = box_origin(p, me.size);
  l.lo = ivec2(origin * TIDY_SUBPIXEL);
  l.hi = ivec2((origin + me.size) * TIDY_SUBPIXEL);
  l.flags |= TIDY_PLACED;
  l.pixel = p.y * params.width + p.x;
  return l;
}

// A label as the placement left it.
TidyLabel tidy_label(LabelGpu me, uint64_t result) {
  TidyLabel l;
  l.anchor = ivec2(floor(me.anchor * TIDY_SUBPIXEL + 0.5f));
  l.lo = ivec2(0);
  l.hi = ivec2(0);
  l.flags = 0u;
  l.pixel = 0u;
  if ((me.flags & LABEL_ENABLED) == 0u) return l;
  l.flags = TIDY_ANCHOR;
  if (result == PLACEMENT_NONE) return l;
  uint pixel = uint(result & 0xFFFFFFFFul);
  l = tidy_at_pixel(l, me, uvec2(pixel % params.width, pixel / params.width));
  if ((me.flags & LABEL_INTERNAL) == 0u) l.flags |= TIDY_MOVABLE;
  return l;
}

// Eq. 3.1 without constraints at the label's box; without a box, the hold (hiding leaves the
// held position as any move does; J adds the hiding's own cost).
float tidy_free_cost(TidyLabel l, LabelGpu me) {
  if ((l.flags & TIDY_PLACED) == 0u) return me.hold;
  vec2 origin = vec2(l.lo) / TIDY_SUBPIXEL;
  return free_cost(me, origin, origin + me.size * 0.5f);
}

// cos(k x 15 degrees), k = 0..6.
float tidy_cos_step(uint k) {
  return k == 0u   ? 1.0f
         : k == 1u ? 0.96592583f
         : k == 2u ? 0.86602540f
         : k == 3u ? 0.70710678f
         : k == 4u ? 0.5f
         : k == 5u ? 0.25881905f
                   : 0.0f;
}

// The unit vector at k x 15 degrees (k = 0..23), built from the quadrant's first six.
vec2 tidy_direction(uint k) {
  uint r = k % 6u;
  vec2 d = vec2(tidy_cos_step(r), tidy_cos_step(6u - r));
  uint q = k / 6u;
  return q == 0u ? d : q == 1u ? vec2(-d.y, d.x) : q == 2u ? -d : vec2(d.y, -d.x);
}

// Move candidates lie at 0.6 to 1.6 times the box's current distance from the anchor (largest
// axis; at least 32 pixels).
float tidy_radius(uint k) {
  return k == 0u ? 0.6f : k == 1u ? 0.8f : k == 2u ? 1.0f : k == 3u ? 1.25f : 1.6f;
}

// The label with its box centred as near c as a candidate pixel puts it, moved into the image
// where it would stick out (boxes along the image's edges swap and move along it); the label
// itself (same pixel) when the box does not fit.
TidyLabel tidy_centred(TidyLabel l, LabelGpu me, vec2 c) {
  vec2 room = vec2(float(params.width), float(params.height)) - me.size;
  if (room.x < 0.0f || room.y < 0.0f) return l;
  vec2 origin = clamp(floor(c - me.size * 0.5f + 0.5f), vec2(0.0f), room);
  uvec2 pixel = uvec2(origin + floor(me.size * 0.5f));
  return candidate_allowed(me, pixel) ? tidy_at_pixel(l, me, pixel) : l;
}

vec2 tidy_centre(TidyLabel l) {
  return vec2(l.lo + l.hi) * (0.5f / TIDY_SUBPIXEL);
}

// Move candidate m of a placed label: its box centred near anchor + reach x direction.
TidyLabel tidy_move(TidyLabel l, LabelGpu me, uint m) {
  vec2 offset = tidy_centre(l) - me.anchor;
  float reach = max(max(abs(offset.x), abs(offset.y)), 32.0f) * tidy_radius(m / TIDY_DIRECTIONS);
  return tidy_centred(l, me, me.anchor + tidy_direction(m % TIDY_DIRECTIONS) * reach);
}

// The key of a change that lowers J by -delta (delta < 0): smaller keys are better changes; ties
// go to the lower change id.
uint64_t tidy_key(float delta, uint change) {
  uint bits = floatBitsToUint(delta);
  uint ordered = (bits & 0x80000000u) != 0u ? ~bits : bits | 0x80000000u;
  return (uint64_t(ordered) << 32) | uint64_t(change);
}
