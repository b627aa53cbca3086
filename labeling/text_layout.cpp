#include "labeling/text_layout.h"

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"

namespace strata {

TextStyle TextStyle::scaled(float s) const {
  return {padding_x * s, padding_y * s, min_width * s, max_width * s};
}

std::vector<ShapedLine> shape_label_text(const Font& font, std::string_view text,
                                         const TextStyle& style) {
  std::vector<ShapedLine> lines;
  size_t start = 0;
  while (true) {
    const size_t end = std::min(text.find('\n', start), text.size());
    const std::string_view paragraph = text.substr(start, end - start);
    if (style.max_width <= 0.0f) {
      lines.push_back(font.shape(paragraph));
    } else {
      // Greedy: as many words as fit, each line shaped as a whole.
      std::string line;
      size_t word_start = 0;
      while (word_start <= paragraph.size()) {
        const size_t word_end = std::min(paragraph.find(' ', word_start), paragraph.size());
        const std::string_view word = paragraph.substr(word_start, word_end - word_start);
        const std::string longer =
            line.empty() ? std::string(word) : line + " " + std::string(word);
        if (!line.empty() && font.shape(longer).advance > style.max_width) {
          lines.push_back(font.shape(line));
          line = word;
        } else {
          line = longer;
        }
        word_start = word_end + 1;
      }
      lines.push_back(font.shape(line));
    }
    if (end == text.size()) break;
    start = end + 1;
  }
  return lines;
}

FontAtlas bake_label_texts(const Font& font, std::span<const std::string> texts,
                           const TextStyle& style) {
  std::vector<GlyphKey> keys;
  for (const std::string& text : texts) {
    for (const ShapedLine& line : shape_label_text(font, text, style)) {
      for (const ShapedGlyph& g : line.glyphs) keys.push_back(g.key);
    }
  }
  return font.bake(keys);
}

LabelTextLayout layout_label_text(const Font& font, const FontAtlas& atlas, std::string_view text,
                                  const TextStyle& style, glm::vec2 min_size) {
  const std::vector<ShapedLine> lines = shape_label_text(font, text, style);
  float widest = 0.0f;
  for (const ShapedLine& line : lines) widest = std::max(widest, line.advance);
  const float spacing = std::round(font.line_spacing());
  const float text_height = font.line_height() + spacing * float(lines.size() - 1);

  LabelTextLayout out;
  out.lines = lines.size();
  out.size.x = std::max({std::ceil(widest + 2.0f * style.padding_x), style.min_width, min_size.x});
  out.size.y = std::max(std::ceil(text_height + 2.0f * style.padding_y), min_size.y);
  out.size = glm::ceil(out.size);

  // Glyphs sit on whole pixels: with quads aligned to the texel grid, a box at a whole-pixel
  // position samples texel centres and the text stays sharp.
  float baseline = std::round(0.5f * (out.size.y - text_height) + font.ascent());
  for (const ShapedLine& line : lines) {
    const float start = std::round(0.5f * (out.size.x - line.advance));
    for (const ShapedGlyph& shaped : line.glyphs) {
      const GlyphMetrics g = atlas.glyph(shaped.key);
      if (g.empty()) continue;
      const glm::vec2 origin(start + std::round(shaped.pen.x), baseline + std::round(shaped.pen.y));
      out.glyphs.push_back({g.uv, glm::vec4(origin, origin) + g.quad});
    }
    baseline += spacing;
  }
  return out;
}

std::vector<gpu::GlyphGpu> build_glyph_buffer(const Font& font, const FontAtlas& atlas,
                                              std::span<const std::string> texts,
                                              std::span<gpu::LabelGpu> labels,
                                              const TextStyle& style) {
  if (texts.size() != labels.size()) {
    throw Error("labels: " + std::to_string(texts.size()) + " texts for " +
                std::to_string(labels.size()) + " labels");
  }
  std::vector<gpu::GlyphGpu> glyphs;
  for (size_t i = 0; i < texts.size(); ++i) {
    gpu::LabelGpu& label = labels[i];
    const LabelTextLayout layout = layout_label_text(font, atlas, texts[i], style, label.size);
    label.size = layout.size;
    label.glyph_first = static_cast<uint32_t>(glyphs.size());
    label.glyph_count = static_cast<uint32_t>(layout.glyphs.size());
    glyphs.insert(glyphs.end(), layout.glyphs.begin(), layout.glyphs.end());
  }
  return glyphs;
}

}  // namespace strata
