// A picture's title and legend, laid out in pixels by one pure function: the boxes they are
// drawn in, their text runs and colour swatches, and the keep-out rectangles the label placement
// and the label motion keep free of labels (PlacementSettings::keep_out). The raster drawing
// (labeling/annotation_drawing.h) and any vector output draw the same AnnotationLayout: a box
// looks like a label's box (shaders/shared/label_drawing.h: LABEL_BOX_COLOR, LABEL_BORDER_COLOR,
// LABEL_BORDER_WIDTH, LABEL_BOX_RADIUS), its text is white label text (LABEL_TEXT_COLOR), so it
// reads the same on any background.
//
// A swatch is its colour, opaque, with a one-pixel rim of LABEL_BORDER_COLOR. Text runs are
// single lines in the label font (engine/core/font.h), shaped left to right from their origin.
//
// Where they go: the title centred along the top edge, the legend in a corner (the bottom-right
// one unless the settings say), both a gap (AnnotationSettings::gap_em) inside the image.
// Pixels, x right, y down; rectangles are x0, y0, x1, y1 with [x0, x1) x [y0, y1).
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "engine/core/font.h"
#include "labeling/text_layout.h"

namespace strata {

// One legend row: a label's text, and its colour where it has one (a segmentation region's, or
// its layer's with --layer-colors).
struct LegendEntry {
  std::string text;
  std::optional<glm::vec3> colour;  // RGB 0..1; none: the row has no swatch
};

enum class LegendCorner { bottom_right, bottom_left, top_right, top_left };

struct AnnotationSettings {
  std::string title;    // empty: none
  bool legend = false;  // the legend of the entries given to layout_annotations
  TextStyle style;      // the label boxes' padding (at the label scale)
  // Room between the image's edges and the boxes, and between the boxes and the labels (the
  // keep-out rectangles are the boxes grown by it), in ems (the label font's size).
  float gap_em = 6.0f / 14.0f;
  float title_scale = 1.5f;           // the title's text size in ems
  float legend_width_share = 0.5f;    // the legend's box is at most this share of the image wide
  float legend_height_share = 0.75f;  // ... and high (rows past it: a last row "+N more")
  LegendCorner corner = LegendCorner::bottom_right;  // (the top ones: below the title)
};

// The two fonts the annotations are set in: the label font (legend) and a larger one (title).
// Made once per text size.
struct AnnotationFonts {
  const Font& text;   // the label font
  const Font& title;  // at AnnotationSettings::title_scale times its size
};

// One line of text: drawn from `origin`, the left end of its baseline, in `font_pixels` (the
// Font's pixel_height) and `colour`. `width` is its advance (the shaped line's).
struct TextRun {
  std::string text;  // UTF-8; shortened with "…" where the box would be too wide
  glm::vec2 origin{0.0f};
  float font_pixels = 0.0f;
  float width = 0.0f;
  glm::vec4 colour{1.0f};  // straight RGBA 0..1 (LABEL_TEXT_COLOR)
};

struct LegendRow {
  TextRun text;
  std::optional<glm::vec4> swatch;  // the colour square's rectangle; none: no colour
  glm::vec3 colour{0.0f};           // its RGB
};

// A box drawn like a label's box.
struct AnnotationBox {
  glm::vec4 rect{0.0f};  // whole pixels
};

struct TitleLayout {
  AnnotationBox box;
  TextRun text;
};

struct LegendLayout {
  AnnotationBox box;
  std::vector<LegendRow> rows;  // top to bottom; the last may be "+N more" without a swatch
  size_t listed = 0;            // entries with a row of their own
};

// A drawn annotation's box by name ("title", "legend"), as layout files record it.
struct NamedBox {
  std::string name;
  glm::vec4 rect{0.0f};
};

struct AnnotationLayout {
  std::optional<TitleLayout> title;
  std::optional<LegendLayout> legend;
  // What the labels keep free: each box grown by the gap, clipped to the image (whole pixels).
  std::vector<glm::uvec4> keep_out;
  // The box of each drawn annotation (layout files, `strata eval`).
  std::vector<NamedBox> boxes() const;
};

// The layout of `settings` in an image of `image` pixels, with a legend row per entry that fits.
// `legend_room`: the legend is laid out inside this rectangle (in its corner of it) and
// it, grown by the gap, is the legend's keep-out rectangle, whatever the entries; a still reserves
// room for one set of entries and lists another in it (app/annotation_options.cpp). Without it
// the legend's box is its room. A legend without entries, or without room for one row, is none.
AnnotationLayout layout_annotations(const AnnotationFonts& fonts,
                                    const AnnotationSettings& settings, glm::uvec2 image,
                                    std::span<const LegendEntry> entries = {},
                                    std::optional<glm::vec4> legend_room = std::nullopt);

}  // namespace strata
