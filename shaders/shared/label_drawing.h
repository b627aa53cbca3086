// Drawing labels into the depth layers and compositing the layers: bindings, push constants and
// the shapes, written once in the common subset of GLSL and GLM so that the GPU passes
// (label_draw.comp, label_composite.comp) and their CPU reference (passes/label_drawing.cpp) run
// the same arithmetic. Every edge is a one-pixel linear ramp of coverage, never a step: CPU and
// GPU round differently, and a step at a pixel centre would flip between them.
// The per-pixel loop over the labels is in label_draw_pixel.h.
#ifndef STRATA_SHARED_LABEL_DRAWING_H
#define STRATA_SHARED_LABEL_DRAWING_H

#include "background.h"
#include "labels.h"

#define LABEL_DRAW_GROUP 16  // (8 x 8 culled the labels four times as often: docs/performance.md)
#define LABEL_DRAW_BINDING_LAYERS 0  // rgba16f 2D array, one premultiplied layer per depth layer
#define LABEL_DRAW_BINDING_LABELS 1  // LabelGpu[]
#define LABEL_DRAW_BINDING_PLACEMENTS 2  // PlacementGpu[], one per label
#define LABEL_DRAW_BINDING_GLYPHS 3      // GlyphGpu[]
#define LABEL_DRAW_BINDING_ATLAS 4       // R8 font coverage, sampled bilinearly
#define LABEL_DRAW_BINDING_FINAL 5       // rgba8, straight: the layers over the background
#define LABEL_DRAW_BINDING_IMAGES 6      // rgba8 label pictures, premultiplied, sampled bilinearly
#define LABEL_DRAW_BINDING_COVERS 7      // AnchorCoverGpu[], one per label

// labels.anchor_cover (labels_anchor_cover.comp): what hides each label's anchor.
#define ANCHOR_COVER_GROUP 64
#define ANCHOR_COVER_BINDING_LAYERS 0  // rgba16f 2D array, as the ghosting leaves it
#define ANCHOR_COVER_BINDING_LABELS 1  // LabelGpu[]
#define ANCHOR_COVER_BINDING_DEPTH 2   // r32f: the renderer's depth image
#define ANCHOR_COVER_BINDING_FRAME 3   // FrameGpu (uniform): layer splits, step, depth_alpha
#define ANCHOR_COVER_BINDING_COVERS 4  // AnchorCoverGpu[], written

STRATA_BEGIN

struct LabelDrawParams {
  uint width;
  uint height;
  uint layer_count;
  uint label_count;   // labels to consider (the shader also stops at the buffer's end)
  vec4 background;    // where every layer is transparent: shared/background.h
  uint layer_frames;  // 1: a box's border (and leader) in its layer's colour (a depth cue)
  // 1: solid connectors with the dashed ones' dark halo (a white line alone is lost on a light
  // background)
  uint connector_halos;
  uint pad1;
  uint pad2;
};

// What hides a label's anchor, measured after the ghosting and before the labels are drawn.
struct AnchorCoverGpu {
  float front_alpha;  // the layers in front of the label's own, composited, at the anchor's pixel
  float hidden;       // 0 (seen) to 1 (hidden): anchor_hidden; hidden from LABEL_HIDDEN_AT on
};

// The look of a label. Colours are straight alpha.
const vec4 LABEL_LINE_COLOR = vec4(0.95f, 0.95f, 0.95f, 0.9f);
const float LABEL_LINE_HALF_WIDTH = 0.75f;
const vec4 LABEL_BOX_COLOR = vec4(0.05f, 0.06f, 0.08f, 0.7f);
const vec4 LABEL_BORDER_COLOR = vec4(0.85f, 0.88f, 0.92f, 0.95f);
// Border colours per layer, front to back, with --layer-colors (the thesis coloured labels by
// layer): distinguishable with the common colour-vision deficiencies, and bright enough on the
// box's dark fill.
const vec4 LABEL_LAYER_COLORS[8] = {
    vec4(0.95f, 0.62f, 0.15f, 0.95f), vec4(0.35f, 0.72f, 0.95f, 0.95f),
    vec4(0.35f, 0.85f, 0.55f, 0.95f), vec4(0.92f, 0.45f, 0.75f, 0.95f),
    vec4(0.95f, 0.92f, 0.35f, 0.95f), vec4(0.85f, 0.4f, 0.25f, 0.95f),
    vec4(0.55f, 0.55f, 0.95f, 0.95f), vec4(0.75f, 0.75f, 0.75f, 0.95f)};

// The border colour of a label on `layer`.
STRATA_INLINE vec4 label_border_color(uint layer, bool layer_frames) {
  return layer_frames ? LABEL_LAYER_COLORS[min(layer, 7u)] : LABEL_BORDER_COLOR;
}
const float LABEL_BORDER_WIDTH = 1.0f;
const float LABEL_BOX_RADIUS = 3.0f;
const vec4 LABEL_TEXT_COLOR = vec4(1.0f, 1.0f, 1.0f, 1.0f);
const vec4 LABEL_MARKER_COLOR = vec4(1.0f, 1.0f, 1.0f, 1.0f);
const vec4 LABEL_MARKER_OUTLINE_COLOR = vec4(0.05f, 0.05f, 0.05f, 1.0f);
const float LABEL_MARKER_RADIUS = 4.0f;
const float LABEL_MARKER_OUTLINE = 1.5f;
// A hidden anchor's mark is hollow, as medical illustration marks what lies behind a surface: a
// white band LABEL_RING_BAND wide around a circle of LABEL_RING_RADIUS, outlined dark on both
// sides, the content seen through its middle.
const float LABEL_RING_RADIUS = 3.5f;
const float LABEL_RING_BAND = 1.5f;
const float LABEL_RING_OUTLINE = 0.75f;
// How far from its anchor a mark reaches, filled or hollow (the ring is the larger).
const float LABEL_ANCHOR_REACH = LABEL_RING_RADIUS + 0.5f * LABEL_RING_BAND + LABEL_RING_OUTLINE;
// A dashed connector: white dashes LABEL_DASH_ON long every LABEL_DASH pixels from the anchor's
// mark on, with a dark halo. A label whose anchor is hidden (anchor_hidden) draws its connector
// so in its own layer, and its anchor's mark hollow. Where a rear label's connector or anchor
// lies behind content of the layers in front of its own, the composite draws them again on top,
// fading in as that content gets opaque (front alpha from LABEL_BEHIND_FROM to LABEL_BEHIND_TO)
// up to LABEL_BEHIND_OPACITY.
const vec4 LABEL_HALO_COLOR = vec4(0.0f, 0.0f, 0.0f, 0.8f);
const float LABEL_HALO_WIDTH = 1.0f;
const float LABEL_DASH = 7.0f;
const float LABEL_DASH_ON = 4.0f;
const float LABEL_BEHIND_FROM = 0.15f;
const float LABEL_BEHIND_TO = 0.6f;
const float LABEL_BEHIND_OPACITY = 0.85f;
// An anchor counts as hidden (a layout's anchor_hidden) from AnchorCoverGpu::hidden
// LABEL_HIDDEN_AT on: where the picture as drawn is at least the renderer's depth_alpha opaque in
// front of it (anchor_hidden). The drawing changes over ramps around that threshold, so a label
// turns dashed smoothly as the camera moves: front alpha within LABEL_HIDDEN_ALPHA_RAMP of
// depth_alpha; an opaque depth from LABEL_HIDDEN_DEPTH_STEPS to twice as many ray steps in front
// of the anchor (less is the anchor's own surface: an anchor picked on a surface is seen).
const float LABEL_HIDDEN_AT = 0.5f;
const float LABEL_HIDDEN_ALPHA_RAMP = 0.1f;
const float LABEL_HIDDEN_DEPTH_STEPS = 2.0f;

// Eq. 3.9's "over" for premultiplied colours, front to back.
STRATA_INLINE vec4 label_over(vec4 front, vec4 back) {
  return front + (1.0f - front.a) * back;
}

STRATA_INLINE vec4 label_premultiplied(vec4 color, float coverage) {
  float a = color.a * coverage;
  return vec4(vec3(color) * a, a);
}

// Coverage of a pixel whose centre is `signed_distance` outside a shape (negative: inside).
STRATA_INLINE float label_edge_coverage(float signed_distance) {
  return clamp(0.5f - signed_distance, 0.0f, 1.0f);
}

STRATA_INLINE float label_segment_distance(vec2 p, vec2 a, vec2 b) {
  vec2 ab = b - a;
  float length2 = dot(ab, ab);
  float t = length2 > 0.0f ? clamp(dot(p - a, ab) / length2, 0.0f, 1.0f) : 0.0f;
  return length(p - (a + t * ab));
}

// Signed distance from p to a box with rounded corners (negative inside).
STRATA_INLINE float label_box_distance(vec2 p, vec2 centre, vec2 half_size, float radius) {
  vec2 q = abs(p - centre) - half_size + radius;
  return length(max(q, vec2(0.0f))) + min(max(q.x, q.y), 0.0f) - radius;
}

// How much of a dash covers p, `along` pixels from the anchor along the connector: none within
// the anchor's mark, then a dash from its edge on; a ramp at each end (no step for CPU and GPU
// rounding to land on).
STRATA_INLINE float label_dash(float along) {
  float s = along - LABEL_ANCHOR_REACH;
  float phase = s - LABEL_DASH * floor(s / LABEL_DASH) - 0.5f * LABEL_DASH_ON;
  if (phase > 0.5f * LABEL_DASH) phase -= LABEL_DASH;
  float dash = clamp(0.5f * LABEL_DASH_ON + 0.5f - abs(phase), 0.0f, 1.0f);
  return min(dash, clamp(s + 0.5f, 0.0f, 1.0f));
}

// The connector from the anchor to `end` at p, dashed, with a halo, premultiplied.
STRATA_INLINE vec4 label_dashed_connector(vec2 p, vec2 anchor, vec2 end) {
  vec2 ab = end - anchor;
  float length2 = dot(ab, ab);
  float along = length2 > 0.0f ? dot(p - anchor, ab) / sqrt(length2) : 0.0f;
  float dash = label_dash(along);
  float d = label_segment_distance(p, anchor, end);
  vec4 color = label_premultiplied(
      LABEL_HALO_COLOR, dash * label_edge_coverage(d - LABEL_LINE_HALF_WIDTH - LABEL_HALO_WIDTH));
  return label_over(
      label_premultiplied(LABEL_LINE_COLOR, dash * label_edge_coverage(d - LABEL_LINE_HALF_WIDTH)),
      color);
}

// The connector (from the anchor to the nearest point of the box), the box and its border at p,
// premultiplied: everything of a label but its text and anchor mark. The connector is solid (with
// a halo if asked), dashed as far as the anchor is hidden (anchor_hidden: 0 to 1).
STRATA_INLINE vec4 label_frame(vec2 p, vec2 anchor, vec2 centre, vec2 size, bool connector,
                               vec4 border, float anchor_hidden, bool halo) {
  vec2 half_size = 0.5f * size;
  vec4 color = vec4(0.0f);
  if (connector) {
    vec2 end = clamp(anchor, centre - half_size, centre + half_size);
    float d = label_segment_distance(p, anchor, end);
    color = label_premultiplied(LABEL_LINE_COLOR, label_edge_coverage(d - LABEL_LINE_HALF_WIDTH));
    if (halo) {
      color = label_over(color, label_premultiplied(LABEL_HALO_COLOR,
                                                    label_edge_coverage(d - LABEL_LINE_HALF_WIDTH -
                                                                        LABEL_HALO_WIDTH)));
    }
    if (anchor_hidden > 0.0f) {
      color = mix(color, label_dashed_connector(p, anchor, end), anchor_hidden);
    }
  }
  float d = label_box_distance(p, centre, half_size, LABEL_BOX_RADIUS);
  float outer = label_edge_coverage(d);
  float inner = label_edge_coverage(d + LABEL_BORDER_WIDTH);
  color = label_over(label_premultiplied(LABEL_BOX_COLOR, outer), color);
  return label_over(label_premultiplied(border, outer - inner), color);
}

// A filled disc with a dark rim on the anchor, premultiplied.
STRATA_INLINE vec4 label_anchor_marker(vec2 p, vec2 anchor) {
  float d = length(p - anchor);
  vec4 rim =
      label_premultiplied(LABEL_MARKER_OUTLINE_COLOR, label_edge_coverage(d - LABEL_MARKER_RADIUS));
  float inner_radius = LABEL_MARKER_RADIUS - LABEL_MARKER_OUTLINE;
  return label_over(label_premultiplied(LABEL_MARKER_COLOR, label_edge_coverage(d - inner_radius)),
                    rim);
}

// A hidden anchor's ring, premultiplied.
STRATA_INLINE vec4 label_anchor_ring(vec2 p, vec2 anchor) {
  float band = abs(length(p - anchor) - LABEL_RING_RADIUS);  // (from the ring's middle)
  vec4 outline =
      label_premultiplied(LABEL_MARKER_OUTLINE_COLOR,
                          label_edge_coverage(band - 0.5f * LABEL_RING_BAND - LABEL_RING_OUTLINE));
  return label_over(
      label_premultiplied(LABEL_MARKER_COLOR, label_edge_coverage(band - 0.5f * LABEL_RING_BAND)),
      outline);
}

// The anchor's mark: filled, hollow as far as the anchor is hidden (0 to 1).
STRATA_INLINE vec4 label_anchor_mark(vec2 p, vec2 anchor, float anchor_hidden) {
  vec4 filled = label_anchor_marker(p, anchor);
  return anchor_hidden > 0.0f ? mix(filled, label_anchor_ring(p, anchor), anchor_hidden) : filled;
}

// How hidden an anchor is, 0 to 1 (hidden from LABEL_HIDDEN_AT on), by two measures, the larger:
// the layers in front of the label's own as the ghosting leaves them (`front_alpha`), against
// depth_alpha; and the depth image (`depth`: where the picture before ghosting first reaches
// depth_alpha, 0 where it never does), where that depth lies in the label's own layer (from
// `layer_near` on: ghosting opens only the layers in front of it) and in front of the anchor.
// The second counts what lies in front before ghosting: where a lens opens layers in front that
// helped the depth image's sum reach depth_alpha in the label's own layer, it may call hidden an
// anchor that the opened picture shows through a thinner own layer (the frame has no depth image
// of the ghosted picture).
STRATA_INLINE float anchor_hidden(float front_alpha, float depth, float anchor_depth,
                                  float layer_near, float depth_alpha, float step) {
  float by_front = smoothstep(depth_alpha - LABEL_HIDDEN_ALPHA_RAMP,
                              depth_alpha + LABEL_HIDDEN_ALPHA_RAMP, front_alpha);
  float by_own_layer = 0.0f;
  if (depth > 0.0f && depth >= layer_near && step > 0.0f) {
    float steps = (anchor_depth - depth) / step;
    by_own_layer = clamp(steps / LABEL_HIDDEN_DEPTH_STEPS - 1.0f, 0.0f, 1.0f);
  }
  return max(by_front, by_own_layer);
}

// What the composite draws over the final image for a label on a rear layer (layer > 0) at p,
// premultiplied: its connector dashed with a halo, and its anchor's mark, as far as the layers in
// front of its own hide them there (`front_alpha`: their composite alpha at p). Nothing for front,
// internal, disabled or hidden labels.
STRATA_INLINE vec4 label_behind(LabelGpu label, PlacementGpu placement, vec2 p, float front_alpha,
                                float anchor_hidden) {
  if ((label.flags & LABEL_ENABLED) == 0u || (label.flags & LABEL_INTERNAL) != 0u ||
      label.layer == 0u || placement.shown != PLACEMENT_SHOWN) {
    return vec4(0.0f);
  }
  float hidden = smoothstep(LABEL_BEHIND_FROM, LABEL_BEHIND_TO, front_alpha);
  if (hidden <= 0.0f) return vec4(0.0f);
  vec2 half_size = 0.5f * label.size;
  vec2 end = clamp(label.anchor, placement.position - half_size, placement.position + half_size);
  vec4 color = label_dashed_connector(p, label.anchor, end);
  color = label_over(label_anchor_mark(p, label.anchor, anchor_hidden), color);
  return color * (hidden * LABEL_BEHIND_OPACITY * placement.opacity);
}

// True when p lies outside everything a label draws (box, connector, marker and their ramps), so
// the label's shapes need not be evaluated there: they would all be exactly zero.
STRATA_INLINE bool label_far_from(vec2 p, vec2 anchor, vec2 centre, vec2 size) {
  float margin = LABEL_ANCHOR_REACH + 1.0f;
  vec2 lo = min(centre - 0.5f * size, anchor) - margin;
  vec2 hi = max(centre + 0.5f * size, anchor) + margin;
  return p.x < lo.x || p.y < lo.y || p.x > hi.x || p.y > hi.y;
}

// Whether the segment a-b misses the box [lo, hi] (Liang and Barsky's clipping).
STRATA_INLINE bool label_segment_misses_box(vec2 a, vec2 b, vec2 lo, vec2 hi) {
  float t0 = 0.0f;
  float t1 = 1.0f;
  for (int k = 0; k < 2; ++k) {
    float d = b[k] - a[k];
    if (d == 0.0f) {
      if (a[k] < lo[k] || a[k] > hi[k]) return true;
      continue;
    }
    float ta = (lo[k] - a[k]) / d;
    float tb = (hi[k] - a[k]) / d;
    t0 = max(t0, min(ta, tb));
    t1 = min(t1, max(ta, tb));
  }
  return t0 > t1;
}

// Whether every pixel centre in [tile_lo, tile_hi] lies outside everything a label draws (a
// workgroup's tile can leave the label out): its box, picture and text (inside the box), its
// anchor marker and its connector, with the composite's halo, each with a pixel to spare beyond
// its ramp. Tighter than label_far_from's rectangle: a long connector's rectangle covers tiles
// the connector never comes near.
STRATA_INLINE bool label_far_from_tile(vec2 tile_lo, vec2 tile_hi, vec2 anchor, vec2 centre,
                                       vec2 size) {
  float margin = LABEL_ANCHOR_REACH + 1.0f;  // (label_far_from's rectangle first)
  vec2 lo = min(centre - 0.5f * size, anchor) - margin;
  vec2 hi = max(centre + 0.5f * size, anchor) + margin;
  if (tile_hi.x < lo.x || tile_hi.y < lo.y || tile_lo.x > hi.x || tile_lo.y > hi.y) return true;
  vec2 half_size = 0.5f * size;
  float box_margin = 2.0f;
  if (!(tile_hi.x < centre.x - half_size.x - box_margin ||
        tile_lo.x > centre.x + half_size.x + box_margin ||
        tile_hi.y < centre.y - half_size.y - box_margin ||
        tile_lo.y > centre.y + half_size.y + box_margin)) {
    return false;
  }
  float marker_margin = LABEL_ANCHOR_REACH + 1.5f;
  if (!(tile_hi.x < anchor.x - marker_margin || tile_lo.x > anchor.x + marker_margin ||
        tile_hi.y < anchor.y - marker_margin || tile_lo.y > anchor.y + marker_margin)) {
    return false;
  }
  vec2 end = clamp(anchor, centre - half_size, centre + half_size);
  float line_margin = LABEL_LINE_HALF_WIDTH + LABEL_HALO_WIDTH + 1.5f;
  return label_segment_misses_box(anchor, end, tile_lo - line_margin, tile_hi + line_margin);
}

// A rear label's connector or mark (label_behind) over the composite, premultiplied: a composite
// over an opaque background stays exactly opaque.
STRATA_INLINE vec4 label_over_composite(vec4 behind, vec4 composite) {
  vec4 c = label_over(behind, composite);
  return vec4(vec3(c), composite.a == 1.0f ? 1.0f : c.a);
}
STRATA_END

#endif
