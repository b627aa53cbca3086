// Label text as boxes and glyphs: the label box a text needs (its advance and one line, plus
// padding) and each character's quad in that box with its rectangle in the font atlas, as the
// label drawing pass (passes/label_drawing.h) reads them.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "engine/core/font.h"
#include "shared/labels.h"

namespace strata {

struct TextStyle {
  float padding_x = 5.0f;   // pixels between the text and the box's left and right edges
  float padding_y = 3.0f;   // ... and its top and bottom edges
  float min_width = 24.0f;  // so that a one-letter label still has a box to see
};

struct LabelTextLayout {
  glm::vec2 size{0.0f};               // the label box, whole pixels
  std::vector<gpu::GlyphGpu> glyphs;  // quads relative to the box's top-left corner; characters
                                      // without ink (spaces) have none
};

// The box for `text` (UTF-8; see printable_ascii) and its glyphs, the text centred in the box.
// The box is at least `min_size` (zero: from the text alone), so a label's given size is kept.
LabelTextLayout layout_label_text(const FontAtlas& font, std::string_view text,
                                  const TextStyle& style = {}, glm::vec2 min_size = glm::vec2(0));

// The glyph buffer for labels[i] showing texts[i]: every label's glyphs one after the other.
// Sets each label's glyph_first, glyph_count and size (its size on entry is kept as a minimum, so
// 0 means "from the text"). texts and labels have the same length.
std::vector<gpu::GlyphGpu> build_glyph_buffer(const FontAtlas& font,
                                              std::span<const std::string> texts,
                                              std::span<gpu::LabelGpu> labels,
                                              const TextStyle& style = {});

}  // namespace strata
