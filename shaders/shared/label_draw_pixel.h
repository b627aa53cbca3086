// One pixel of one depth layer with its labels drawn over it, written once for the GPU
// (label_draw.comp) and the CPU reference (passes/label_drawing.cpp, which includes this file
// inside a struct). What the includer provides (the labels, their placements and glyphs, the
// atlases) is label_draw_pixel_access.h.

#ifndef __cplusplus
#include "label_draw_pixel_access.h"  // (C++: the reference's struct is checked against it)
#endif

// Text coverage of a label at p. Glyph quads overlap only in their zero-coverage borders, so the
// largest coverage is the text's.
float text_coverage(vec2 p, vec2 top_left, LabelGpu label) {
  vec2 q = p - top_left;
  if (q.x < 0.0f || q.y < 0.0f || q.x > label.size.x || q.y > label.size.y) return 0.0f;
  float coverage = 0.0f;
  for (uint g = label.glyph_first; g < label.glyph_first + label.glyph_count; ++g) {
    GlyphGpu glyph = glyph_at(g);
    vec2 lo = vec2(glyph.box);
    vec2 hi = vec2(glyph.box.z, glyph.box.w);
    if (q.x < lo.x || q.y < lo.y || q.x >= hi.x || q.y >= hi.y) continue;
    vec2 uv = mix(vec2(glyph.atlas), vec2(glyph.atlas.z, glyph.atlas.w), (q - lo) / (hi - lo));
    coverage = max(coverage, atlas_coverage(uv));
  }
  return coverage;
}

// The label's picture at p, premultiplied, times the pixel's share of the picture's rectangle (a
// one-pixel ramp at its edges, as at every edge here). The atlas keeps a border of edge texels
// around each picture, so the ramp outside the rectangle reads the picture's own edge.
vec4 image_color(vec2 p, vec2 top_left, LabelGpu label) {
  if (label.image_quads == 0u) return vec4(0.0f);
  GlyphGpu quad = glyph_at(label.glyph_first + label.glyph_count);
  vec2 q = p - top_left;
  vec2 lo = vec2(quad.box);
  vec2 hi = vec2(quad.box.z, quad.box.w);
  vec2 inside = min(q - lo, hi - q);  // distance to the nearer edge, per axis
  float coverage = label_edge_coverage(-inside.x) * label_edge_coverage(-inside.y);
  if (coverage <= 0.0f) return vec4(0.0f);
  vec2 uv = mix(vec2(quad.atlas), vec2(quad.atlas.z, quad.atlas.w), (q - lo) / (hi - lo));
  return image_texel(uv) * coverage;
}

// Label i drawn over `content` (premultiplied) at pixel centre p if it is shown on `layer`, as
// opaque as its placement says. External labels: connector, box, picture, text, then the anchor's
// mark on top (the connector dashed and the mark hollow where the anchor is hidden). Internal
// labels: the box centred on the anchor, no connector or mark.
vec4 draw_label_at(uint i, vec2 p, uint layer, vec4 content) {
  LabelGpu label = label_at(i);
  if ((label.flags & LABEL_ENABLED) == 0u || label.layer != layer) return content;
  PlacementGpu placement = placement_at(i);
  if (placement.shown != PLACEMENT_SHOWN) return content;
  bool is_internal = (label.flags & LABEL_INTERNAL) != 0u;
  vec2 centre = is_internal ? label.anchor : placement.position;
  if (label_far_from(p, label.anchor, centre, label.size)) return content;
  float hidden = is_internal ? 0.0f : anchor_hidden_at(i);
  vec4 color = label_frame(p, label.anchor, centre, label.size, !is_internal,
                           label_border_color(label.layer, layer_frames()), hidden,
                           connector_halos());
  vec2 top_left = centre - 0.5f * label.size;
  color = label_over(image_color(p, top_left, label), color);
  float text = text_coverage(p, top_left, label);
  color = label_over(label_premultiplied(LABEL_TEXT_COLOR, text), color);
  if (!is_internal) color = label_over(label_anchor_mark(p, label.anchor, hidden), color);
  return label_over(color * placement.opacity, content);  // (premultiplied: a fade)
}

// Every label in label order: a later label covers an earlier one.
vec4 draw_labels_at(vec2 p, uint layer, vec4 content) {
  for (uint i = 0u; i < label_count(); ++i) content = draw_label_at(i, p, layer, content);
  return content;
}
