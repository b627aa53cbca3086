// Ghosting: the layers in front of a shown rear label's anchor made more transparent around it
// (a lens), so that what the label names is seen through what hides it. Written once for GLSL and
// C++: the GPU pass (labels_ghost.comp) and its CPU reference (ghost_reference in
// passes/label_drawing.cpp) evaluate the same expressions.
//
// A label on layer L opens every layer k < L at p by its lens: 1 within a third of the radius of
// its anchor, falling smoothly to 0 at the radius (and, with a leader radius, the same around its
// connector), and 1 over its drawn box, falling to 0 a box radius (GHOST_BOX_SHARE of the radius)
// outside it, so that a label is readable wherever it is drawn, also on its way behind content
// while the camera moves; times the label's opacity (a fading label's lens fades with it), and a
// lens (not a box) times how much layer L and the layers behind it hold at p
// (ghost_behind_weight). Layer k keeps 1 - strength * (the largest opening at p) of its colour
// and alpha; nothing changes beyond every lens. Labels are drawn after, so a box is never made
// harder to read. The placement counts the anchors' lenses (ghost_placement_opening): a box they
// let through is legible. Picking (shared/pick.h) walks the picture as drawn, with the same shares
// kept (ghost_keeps) but for the boxes' openings: under a box, the box is what is drawn.
#ifndef STRATA_SHARED_GHOST_H
#define STRATA_SHARED_GHOST_H

#include "label_drawing.h"
#include "volume_render.h"  // VR_MAX_LAYERS

#define GHOST_GROUP 16
#define GHOST_BINDING_LAYERS 0      // rgba16f 2D array, premultiplied, changed in place
#define GHOST_BINDING_LABELS 1      // LabelGpu[]
#define GHOST_BINDING_PLACEMENTS 2  // PlacementGpu[]: where the labels are drawn, their opacity
#define GHOST_BOX_SHARE 0.05f       // the lens around a box, as a share of the anchor's

STRATA_BEGIN

struct GhostParams {
  uint width;
  uint height;
  uint layer_count;
  uint label_count;
  float strength;       // 0: no ghosting, 1: the layers in front fully open at an anchor
  float radius;         // pixels: the lens around an anchor
  float leader_radius;  // pixels: the lens along a connector (0: none)
  float box_radius;     // pixels: the lens around a box
};

// A lens's opening at distance d from its centre (or line): full within a third of the radius,
// then a smooth falloff to nothing at the radius.
STRATA_INLINE float ghost_lens(float d, float radius) {
  return radius > 0.0f ? 1.0f - smoothstep(radius / 3.0f, radius, d) : 0.0f;
}

// How much of an opening the content behind lets through, from the composited alpha of the
// label's own layer and every layer behind it: the layers in front open only where there is
// something behind them to see (no hole to the background at an object's edge).
STRATA_INLINE float ghost_behind_weight(float behind_alpha) {
  return smoothstep(0.05f, 0.35f, behind_alpha);
}

// The composited alpha of layer k and every layer behind it, from that of the layers behind k.
STRATA_INLINE float ghost_behind_alpha(float layer_alpha, float behind_alpha) {
  return layer_alpha + (1.0f - layer_alpha) * behind_alpha;
}

// How far label `label`, drawn as `drawn`, opens the layers in front of its own at p (0 to 1):
// x by its anchor's and connector's lenses, y by its box's; 0 for a front, internal, disabled or
// hidden label.
STRATA_INLINE vec2 ghost_opening(LabelGpu label, PlacementGpu drawn, vec2 p, GhostParams g) {
  if ((label.flags & LABEL_ENABLED) == 0u || (label.flags & LABEL_INTERNAL) != 0u ||
      label.layer == 0u || drawn.shown != PLACEMENT_SHOWN) {
    return vec2(0.0f);
  }
  float open = ghost_lens(length(p - label.anchor), g.radius);
  vec2 half_size = 0.5f * label.size;
  if (g.leader_radius > 0.0f) {
    vec2 end = clamp(label.anchor, drawn.position - half_size, drawn.position + half_size);
    open = max(open, ghost_lens(label_segment_distance(p, label.anchor, end), g.leader_radius));
  }
  vec2 outside = max(abs(p - drawn.position) - half_size, vec2(0.0f));
  float box = ghost_lens(length(outside), g.box_radius);
  return vec2(open, box) * clamp(drawn.opacity, 0.0f, 1.0f);
}

// The largest openings of the labels on each layer at a pixel: by lenses and by boxes.
struct GhostOpenings {
  float lens[VR_MAX_LAYERS];
  float box[VR_MAX_LAYERS];
};

STRATA_INLINE GhostOpenings ghost_no_openings() {
  GhostOpenings o;
  for (uint k = 0u; k < uint(VR_MAX_LAYERS); ++k) {
    o.lens[k] = 0.0f;
    o.box[k] = 0.0f;
  }
  return o;
}

// `o` with a label on `layer` opening by `open` (ghost_opening's).
STRATA_INLINE GhostOpenings ghost_with(GhostOpenings o, uint layer, vec2 open) {
  o.lens[layer] = max(o.lens[layer], open.x);
  o.box[layer] = max(o.box[layer], open.y);
  return o;
}

// The placement's view of a label's lens (the hidden pixels legibility counts,
// integral_costs.comp): before it places the labels the placement cannot know which will be shown,
// so every enabled external rear label opens as if shown at full opacity, around its anchor (a
// connector's lens depends on where the box goes).
STRATA_INLINE float ghost_placement_opening(LabelGpu label, vec2 p, float radius) {
  if ((label.flags & LABEL_ENABLED) == 0u || (label.flags & LABEL_INTERNAL) != 0u ||
      label.layer == 0u) {
    return 0.0f;
  }
  return ghost_lens(length(p - label.anchor), radius);
}

// Whether no pixel centre in [tile_lo, tile_hi] lies within `radius` of the anchor (with a pixel
// to spare).
STRATA_INLINE bool ghost_anchor_far_from_tile(vec2 tile_lo, vec2 tile_hi, vec2 anchor,
                                              float radius) {
  float r = radius + 1.0f;
  return tile_hi.x < anchor.x - r || tile_lo.x > anchor.x + r || tile_hi.y < anchor.y - r ||
         tile_lo.y > anchor.y + r;
}

// Whether no pixel centre in [tile_lo, tile_hi] lies within the label's lenses (with a pixel to
// spare): a workgroup's tile can leave the label out.
STRATA_INLINE bool ghost_far_from_tile(vec2 tile_lo, vec2 tile_hi, LabelGpu label,
                                       PlacementGpu drawn, GhostParams g) {
  if (!ghost_anchor_far_from_tile(tile_lo, tile_hi, label.anchor, g.radius)) return false;
  vec2 half_size = 0.5f * label.size;
  vec2 reach = half_size + g.box_radius + 1.0f;
  if (all(lessThanEqual(tile_lo, drawn.position + reach)) &&
      all(greaterThanEqual(tile_hi, drawn.position - reach))) {
    return false;
  }
  if (g.leader_radius <= 0.0f) return true;
  vec2 end = clamp(label.anchor, drawn.position - half_size, drawn.position + half_size);
  float m = g.leader_radius + 1.0f;
  return label_segment_misses_box(label.anchor, end, tile_lo - m, tile_hi + m);
}

// The share of its colour and alpha a layer keeps where the largest opening of the labels on
// the layers behind it is `largest_behind`.
STRATA_INLINE float ghost_keep(float largest_behind, float strength) {
  return 1.0f - clamp(strength, 0.0f, 1.0f) * largest_behind;
}

// The share each of a pixel's layers keeps (layer[k]; 1 past layer_count), from the largest
// openings of the labels on each layer and the layers' own alphas at the pixel. Back to front:
// layer k opens by the largest opening of the labels behind it, a lens as far as what lies at and
// behind its own layer lets it, a box fully (the box itself is behind).
struct GhostKeeps {
  float layer[VR_MAX_LAYERS];
};

STRATA_INLINE GhostKeeps ghost_keeps(GhostOpenings open, float alpha[VR_MAX_LAYERS],
                                     uint layer_count, float strength) {
  GhostKeeps keeps;
  for (uint k = 0u; k < uint(VR_MAX_LAYERS); ++k) keeps.layer[k] = 1.0f;
  float behind = 0.0f;
  float behind_alpha = 0.0f;
  for (int k = int(min(layer_count, uint(VR_MAX_LAYERS))) - 1; k >= 0; --k) {
    if (behind > 0.0f) keeps.layer[k] = ghost_keep(behind, strength);
    behind_alpha = ghost_behind_alpha(alpha[k], behind_alpha);
    if (k > 0) {
      behind = max(behind, max(open.lens[k] * ghost_behind_weight(behind_alpha), open.box[k]));
    }
  }
  return keeps;
}

STRATA_END

#endif
