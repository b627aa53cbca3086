// A labelled still's labels as vector shapes: the raster drawing's shapes
// (shaders/shared/label_drawing.h, label_draw_pixel.h) with its sizes and colours, each label a
// group at its opacity.
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "engine/core/error.h"
#include "frame/vector_picture.h"
#include "shared/label_drawing.h"

namespace strata {
namespace {

VectorShape line(glm::vec2 a, glm::vec2 b, glm::vec4 color, float width, glm::vec2 dash = {}) {
  VectorShape s{VectorShape::Kind::line, a, b};
  s.stroke = color;
  s.stroke_width = width;
  s.round_caps = dash.x <= 0.0f;  // (the raster's solid line is a capsule)
  s.dash = dash;
  return s;
}

VectorShape circle(glm::vec2 centre, float radius, glm::vec4 fill, glm::vec4 stroke = {},
                   float width = 0.0f) {
  VectorShape s{VectorShape::Kind::circle, centre, {radius, 0.0f}};
  s.fill = fill;
  s.stroke = stroke;
  s.stroke_width = width;
  return s;
}

// What lies in front of a rear label: the layers in front of its own, as the ghosting leaves
// them, and the boxes of labels on those layers.
struct FrontCover {
  std::span<const glm::vec4> layers;  // label-free, layer after layer; empty: none
  graph::Extent size;
  uint32_t layer_count = 0;
  std::span<const LabelLayout> labels;

  // Their composite's alpha at p over a label on `layer`.
  float alpha(glm::vec2 p, uint32_t layer) const {
    float a = 0.0f;
    const glm::ivec2 q(glm::floor(p));
    const size_t pixels = size_t{size.width} * size.height;
    if (q.x >= 0 && q.y >= 0 && q.x < int(size.width) && q.y < int(size.height) &&
        layers.size() == pixels * layer_count) {
      const size_t at = size_t(q.y) * size.width + size_t(q.x);
      for (uint32_t k = 0; k < std::min(layer, layer_count); ++k)
        a += (1.0f - a) * layers[k * pixels + at].a;
    }
    for (const LabelLayout& l : labels) {
      const glm::vec2 from = p - l.box_origin;
      if (l.layer < layer && l.placed && from.x >= 0.0f && from.y >= 0.0f &&
          from.x <= l.box_size.x && from.y <= l.box_size.y) {
        a += (1.0f - a) * gpu::LABEL_BOX_COLOR.a * l.opacity;
      }
    }
    return a;
  }
};

// A stretch of a connector, in distances from the anchor, and the alpha in front of it there
// (in eighths: a stretch ends where that changes).
struct Stretch {
  float from = 0.0f, to = 0.0f;
  float front = 0.0f;
};

std::vector<Stretch> connector_stretches(const FrontCover& cover, glm::vec2 anchor, glm::vec2 end,
                                         uint32_t layer) {
  constexpr float kStep = 0.5f, kLevels = 8.0f;
  const float length = glm::length(end - anchor);
  const auto front = [&](float s) {
    if (layer == 0) return 0.0f;
    const glm::vec2 p = length > 0.0f ? anchor + (end - anchor) * (s / length) : anchor;
    return std::round(cover.alpha(p, layer) * kLevels) / kLevels;
  };
  std::vector<Stretch> out{{0.0f, length, front(0.0f)}};
  for (float s = kStep; s < length; s += kStep) {
    const float here = front(s);
    if (here == out.back().front) continue;
    out.back().to = s;
    out.push_back({s, length, here});
  }
  return out;
}

VectorShape faded(VectorShape shape, float share) {
  shape.fill.a *= share;
  shape.stroke.a *= share;
  return shape;
}

// A stretch of the connector solid (label_frame) or dashed with a dark halo under the dashes,
// the dashes counted from the anchor's mark's reach (label_dashed_connector), `share` as opaque.
void add_leader(std::vector<VectorItem>& items, glm::vec2 anchor, glm::vec2 end, Stretch stretch,
                bool dashed, float share, bool halo) {
  const float length = glm::length(end - anchor);
  const float from = dashed ? std::max(stretch.from, gpu::LABEL_ANCHOR_REACH) : stretch.from;
  if (share <= 1.0f / 512.0f || length <= 0.0f || stretch.to <= from) return;
  const glm::vec2 a = anchor + (end - anchor) * (from / length);
  const glm::vec2 b = anchor + (end - anchor) * (stretch.to / length);
  const float half = gpu::LABEL_LINE_HALF_WIDTH;
  if (!dashed) {
    if (halo) {
      items.push_back(
          faded(line(a, b, gpu::LABEL_HALO_COLOR, 2.0f * (half + gpu::LABEL_HALO_WIDTH)), share));
    }
    items.push_back(faded(line(a, b, gpu::LABEL_LINE_COLOR, 2.0f * half), share));
    return;
  }
  const glm::vec2 dash(gpu::LABEL_DASH_ON, gpu::LABEL_DASH - gpu::LABEL_DASH_ON);
  for (const VectorShape& s :
       {line(a, b, gpu::LABEL_HALO_COLOR, 2.0f * (half + gpu::LABEL_HALO_WIDTH), dash),
        line(a, b, gpu::LABEL_LINE_COLOR, 2.0f * half, dash)}) {
    VectorShape shape = faded(s, share);
    shape.dash_offset = from - gpu::LABEL_ANCHOR_REACH;
    items.push_back(shape);
  }
}

// The anchor's mark, `share` as opaque: a white disc in a dark rim, becoming (as far as the anchor
// is hidden) a white ring outlined dark on both sides.
void add_anchor_mark(std::vector<VectorItem>& items, glm::vec2 anchor, float hidden, float share) {
  const glm::vec4 none(0.0f);
  if (share * (1.0f - hidden) > 1.0f / 512.0f) {
    const float f = share * (1.0f - hidden);
    items.push_back(
        faded(circle(anchor, gpu::LABEL_MARKER_RADIUS, gpu::LABEL_MARKER_OUTLINE_COLOR), f));
    items.push_back(faded(circle(anchor, gpu::LABEL_MARKER_RADIUS - gpu::LABEL_MARKER_OUTLINE,
                                 gpu::LABEL_MARKER_COLOR),
                          f));
  }
  if (share * hidden > 1.0f / 512.0f) {
    const float f = share * hidden;
    items.push_back(
        faded(circle(anchor, gpu::LABEL_RING_RADIUS, none, gpu::LABEL_MARKER_OUTLINE_COLOR,
                     gpu::LABEL_RING_BAND + 2.0f * gpu::LABEL_RING_OUTLINE),
              f));
    items.push_back(faded(
        circle(anchor, gpu::LABEL_RING_RADIUS, none, gpu::LABEL_MARKER_COLOR, gpu::LABEL_RING_BAND),
        f));
  }
}

// How much the composite draws again on top where `front` lies in front (label_behind).
float behind_share(float front) {
  return gpu::LABEL_BEHIND_OPACITY *
         glm::smoothstep(gpu::LABEL_BEHIND_FROM, gpu::LABEL_BEHIND_TO, front);
}

// A label's connector and anchor mark, in its layer (`own`, seen as far as the front lets it
// through: solid, dashed as far as the anchor is hidden) and on top (`on_top`, label_behind).
void add_connector(std::vector<VectorItem>& own, std::vector<VectorItem>& on_top,
                   const LabelLayout& l, glm::vec2 end, float hidden, const FrontCover& cover,
                   bool halo) {
  for (const Stretch& s : connector_stretches(cover, l.anchor, end, l.layer)) {
    add_leader(own, l.anchor, end, s, false, (1.0f - s.front) * (1.0f - hidden), halo);
    add_leader(own, l.anchor, end, s, true, (1.0f - s.front) * hidden, halo);
    if (l.layer > 0) add_leader(on_top, l.anchor, end, s, true, behind_share(s.front), halo);
  }
}

// The box's fill over its whole shape, then its border: the ring of one border width inside the
// shape, as a stroke along the middle of that ring.
void add_box(std::vector<VectorItem>& items, glm::vec2 top_left, glm::vec2 size, glm::vec4 border) {
  VectorShape fill{VectorShape::Kind::box, top_left, size, gpu::LABEL_BOX_RADIUS};
  fill.fill = gpu::LABEL_BOX_COLOR;
  items.push_back(fill);
  const float inset = 0.5f * gpu::LABEL_BORDER_WIDTH;
  VectorShape ring{VectorShape::Kind::box, top_left + inset, size - 2.0f * inset,
                   gpu::LABEL_BOX_RADIUS - inset};
  ring.stroke = border;
  ring.stroke_width = gpu::LABEL_BORDER_WIDTH;
  items.push_back(ring);
}

// The share of a box that the front lets through, over its pixels: where labels lie on the
// content (internal labelling) the layers in front hide rear ones as they hide their layers.
float box_seen(const FrontCover& cover, glm::vec2 top_left, glm::vec2 size, uint32_t layer) {
  if (layer == 0) return 1.0f;
  float seen = 0.0f;
  int count = 0;
  for (float y = 0.5f; y < size.y; y += 1.0f) {
    for (float x = 0.5f; x < size.x; x += 1.0f, ++count)
      seen += 1.0f - cover.alpha(top_left + glm::vec2(x, y), layer);
  }
  return count > 0 ? seen / float(count) : 1.0f;
}

struct LabelLook {
  std::shared_ptr<const Font> font;
  TextStyle style;
  const LabellingSettings& settings;
  const LabelImages& images;
  FrontCover front;
};

// How hidden the label's anchor is, 0 to 1, as the drawing mixes its solid and dashed leader.
float hidden_amount(const LabelLayout& l) {
  if (!std::isnan(l.hidden)) return l.hidden;
  return l.anchor_hidden.value_or(false) ? 1.0f : 0.0f;
}

// One label as label_draw_pixel.h draws it, in three groups: its connector; its box, picture and
// text, seen as far as the front lets them through; its anchor mark. Then what the composite
// draws of it on top (label_behind).
std::vector<VectorGroup> label_groups(const LabelLayout& l, const Label& label, size_t index,
                                      const LabelLook& look, VectorGroup& behind) {
  const Font& font = *look.font;
  const std::vector<ShapedLine> lines = shape_label_text(font, label.text, look.style);
  const LabelBoxLayout box = place_label_text(font, lines, label.text.empty(), look.style,
                                              l.box_size, look.images.blocks[index]);
  const bool internal = look.settings.internal;
  const glm::vec2 centre = internal ? l.anchor : l.box_origin + 0.5f * l.box_size;
  const glm::vec2 top_left = centre - 0.5f * box.size;
  const float hidden = hidden_amount(l);
  behind = {l.opacity, {}};
  std::vector<VectorGroup> groups(3, VectorGroup{l.opacity, {}});
  groups[1].opacity *= box_seen(look.front, top_left, box.size, l.layer);
  if (!internal) {
    const glm::vec2 end = glm::clamp(l.anchor, top_left, top_left + box.size);
    add_connector(groups[0].items, behind.items, l, end, hidden, look.front,
                  connector_halos(look.settings.background));
  }
  add_box(groups[1].items, top_left, box.size,
          gpu::label_border_color(l.layer, look.settings.layer_colors));
  if (box.image && label.image) {
    const glm::vec4 r = *box.image;
    groups[1].items.push_back(
        VectorImage{top_left + glm::vec2(r.x, r.y), {r.z - r.x, r.w - r.y}, label.image->pixels});
  }
  for (size_t i = 0; i < lines.size(); ++i) {
    groups[1].items.push_back(
        VectorText{look.font, lines[i], top_left + box.line_origins[i], gpu::LABEL_TEXT_COLOR});
  }
  if (!internal) {
    const float front = l.layer > 0 ? look.front.alpha(l.anchor, l.layer) : 0.0f;
    add_anchor_mark(groups[2].items, l.anchor, hidden, 1.0f - front);
    if (l.layer > 0) add_anchor_mark(behind.items, l.anchor, hidden, behind_share(front));
  }
  std::erase_if(groups, [](const VectorGroup& g) { return g.items.empty(); });
  return groups;
}

}  // namespace

VectorPicture labelled_picture(const LabelledFrame& frame, const Scene& scene,
                               const LabellingSettings& settings,
                               std::span<const glm::vec4> layers) {
  VectorPicture picture = image_picture(frame.size.width, frame.size.height, frame.image);
  if (frame.labels.size() != scene.labels.size()) {
    throw Error("vector picture: " + std::to_string(frame.labels.size()) + " laid out labels for " +
                std::to_string(scene.labels.size()) + " scene labels");
  }
  const float scale = settings.label_scale;
  const LabelImages images = bake_label_images(scene.labels, scale);
  const LabelLook look{std::make_shared<const Font>(settings.font_pixels * scale),
                       label_text_style(settings),
                       settings,
                       images,
                       {layers, frame.size, frame.layering.layer_count, frame.labels}};
  // The layers are composited front over back: a rear layer's labels lie under a front one's.
  std::vector<size_t> order(frame.labels.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return frame.labels[a].layer > frame.labels[b].layer;
  });
  std::vector<VectorGroup> behind(frame.labels.size());
  for (const size_t i : order) {
    const LabelLayout& l = frame.labels[i];
    if (!l.placed || !(l.opacity > 0.0f)) continue;
    for (VectorGroup& group : label_groups(l, scene.labels[i], i, look, behind[i]))
      picture.groups.push_back(std::move(group));
  }
  for (VectorGroup& group : behind) {  // (the composite's, in label order)
    if (!group.items.empty()) picture.groups.push_back(std::move(group));
  }
  return picture;
}

void add_annotations(VectorPicture& picture, const AnnotationLayout& layout) {
  VectorGroup group;
  std::map<float, std::shared_ptr<const Font>> fonts;  // by size: the title's, the legend's
  const auto add_text = [&](const TextRun& run) {
    std::shared_ptr<const Font>& font = fonts[run.font_pixels];
    if (!font) font = std::make_shared<const Font>(run.font_pixels);
    group.items.push_back(VectorText{font, font->shape(run.text), run.origin, run.colour});
  };
  const auto add_rect_box = [&](glm::vec4 r) {
    add_box(group.items, {r.x, r.y}, {r.z - r.x, r.w - r.y}, gpu::LABEL_BORDER_COLOR);
  };
  if (layout.title) {
    add_rect_box(layout.title->box.rect);
    add_text(layout.title->text);
  }
  if (layout.legend) {
    add_rect_box(layout.legend->box.rect);
    for (const LegendRow& row : layout.legend->rows) {
      if (row.swatch) {
        const glm::vec4 r = *row.swatch;  // (its one-pixel rim a stroke along the rim's middle)
        VectorShape swatch{
            VectorShape::Kind::box, {r.x + 0.5f, r.y + 0.5f}, {r.z - r.x - 1.0f, r.w - r.y - 1.0f}};
        swatch.fill = glm::vec4(row.colour, 1.0f);
        swatch.stroke = gpu::LABEL_BORDER_COLOR;
        swatch.stroke_width = 1.0f;
        group.items.push_back(swatch);
      }
      add_text(row.text);
    }
  }
  if (!group.items.empty()) picture.groups.push_back(std::move(group));
}

}  // namespace strata
