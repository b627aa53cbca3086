// Label text as boxes and glyphs: the lines of a text (split at "\n", wrapped at a maximum width,
// shaped by the font), the label box they need plus padding, and each glyph's quad in that box
// with its rectangle in the font atlas, as the label drawing pass (passes/label_drawing.h) reads
// them. A label's picture, when it has one, takes a strip of the box above or left of the text.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "engine/core/font.h"
#include "engine/core/image_atlas.h"
#include "engine/scene/scene.h"
#include "shared/labels.h"

namespace strata {

struct TextStyle {
  float padding_x = 5.0f;   // pixels between the text and the box's left and right edges
  float padding_y = 3.0f;   // ... and its top and bottom edges
  float min_width = 24.0f;  // so that a one-letter label still has a box to see
  float max_width = 0.0f;   // a line wider than this (pixels, padding excluded) wraps at a space;
                            // 0: lines break at "\n" only

  // The style with every length times `s` (the label scale).
  TextStyle scaled(float s) const;
};

// A label's picture as the layout places it.
struct LabelImageBlock {
  glm::vec2 size{0.0f};   // drawn size, whole pixels
  bool left = false;      // left of the text; else above it
  glm::vec4 atlas{0.0f};  // u0, v0, u1, v1 in the image atlas
};

struct LabelTextLayout {
  glm::vec2 size{0.0f};               // the label box, whole pixels
  std::vector<gpu::GlyphGpu> glyphs;  // quads relative to the box's top-left corner; glyphs
                                      // without ink (spaces) have none
  size_t lines = 0;
  std::optional<gpu::GlyphGpu> image;  // the picture's quad, in the image atlas
};

// The pictures of `labels` (none for a label without one) at `scale` times their height, in one
// atlas, and where each lies in it.
struct LabelImages {
  ImageAtlas atlas;
  std::vector<std::optional<LabelImageBlock>> blocks;  // one per label
};
LabelImages bake_label_images(std::span<const Label> labels, float scale);

// The lines of `text` (UTF-8), shaped: split at "\n" into paragraphs, each wrapped at
// style.max_width at spaces (a word wider than that keeps a line of its own), every line in its
// paragraph's direction (paragraph_direction) and in visual order.
std::vector<ShapedLine> shape_label_text(const Font& font, std::string_view text,
                                         const TextStyle& style = {});

// One warning per label whose text has characters no face of `font` has (an emoji without an
// emoji font, say): the label's id and text, and each such character as U+XXXX with the
// character itself.
std::vector<std::string> missing_glyph_warnings(const Font& font, std::span<const Label> labels);

// Shaped lines by text for one font and style, each text shaped once: the viewer's label edits
// shape only the texts they bring. clear() when the font or style changes.
class ShapedTexts {
 public:
  const std::vector<ShapedLine>& lines(const Font& font, const std::string& text,
                                       const TextStyle& style);
  void clear() { lines_.clear(); }

 private:
  std::unordered_map<std::string, std::vector<ShapedLine>> lines_;
};

// The glyphs `texts` are drawn with (shaped as shape_label_text shapes them; by `shaped` where
// given).
std::vector<GlyphKey> label_glyph_keys(const Font& font, std::span<const std::string> texts,
                                       const TextStyle& style = {}, ShapedTexts* shaped = nullptr);

// The atlas with every glyph of `texts`.
FontAtlas bake_label_texts(const Font& font, std::span<const std::string> texts,
                           const TextStyle& style = {});

// Where a label's text and picture lie in its box, before its glyphs are looked up in an atlas:
// what the raster drawing (layout_label_text) and the vector writer (frame/vector_picture.h) share.
struct LabelBoxLayout {
  glm::vec2 size{0.0f};                 // the label box, whole pixels
  std::vector<glm::vec2> line_origins;  // each line's start on its baseline, from the box's corner
  std::optional<glm::vec4> image;       // the picture's rectangle: x0, y0, x1, y1
};
LabelBoxLayout place_label_text(const Font& font, const std::vector<ShapedLine>& lines,
                                bool empty_text, const TextStyle& style, glm::vec2 min_size,
                                const std::optional<LabelImageBlock>& image);

// Where a glyph's pen lies in the box: on whole pixels, so that with quads aligned to the texel
// grid a box at a whole-pixel position samples texel centres and the text stays sharp.
inline glm::vec2 glyph_origin(glm::vec2 line_origin, const ShapedGlyph& glyph) {
  return line_origin + glm::round(glyph.pen);
}

// The box for `text` and its glyphs (from `atlas`, which holds them: bake_label_texts), each line
// centred in the box. The box is at least `min_size` (zero: from the text alone), so a label's
// given size is kept. With an image, the box holds it (padding around it, centred across the
// box) above or left of the text, and the text is centred in the rest.
// `lines`: the text shaped already (shape_label_text's), where given.
LabelTextLayout layout_label_text(const Font& font, const FontAtlas& atlas, std::string_view text,
                                  const TextStyle& style = {}, glm::vec2 min_size = glm::vec2(0),
                                  const std::optional<LabelImageBlock>& image = std::nullopt,
                                  const std::vector<ShapedLine>* lines = nullptr);

// The glyph buffer for labels[i] showing texts[i] (and images[i], when images is not empty):
// every label's glyphs one after the other, then its picture's quad. Sets each label's
// glyph_first, glyph_count, image_quads and size (its size on entry is kept as a minimum, so 0
// means "from the text"). texts, labels and a non-empty images have the same length.
std::vector<gpu::GlyphGpu> build_glyph_buffer(
    const Font& font, const FontAtlas& atlas, std::span<const std::string> texts,
    std::span<gpu::LabelGpu> labels, const TextStyle& style = {},
    std::span<const std::optional<LabelImageBlock>> images = {}, ShapedTexts* shaped = nullptr);

}  // namespace strata
