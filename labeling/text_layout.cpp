#include "labeling/text_layout.h"

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"

namespace strata {

LabelTextLayout layout_label_text(const FontAtlas& font, std::string_view text,
                                  const TextStyle& style, glm::vec2 min_size) {
  const std::string ascii = printable_ascii(text);
  float advance = 0.0f;
  for (const char c : ascii) advance += font.glyph(c).advance;

  LabelTextLayout out;
  out.size.x = std::max({std::ceil(advance + 2.0f * style.padding_x), style.min_width, min_size.x});
  out.size.y = std::max(std::ceil(font.line_height() + 2.0f * style.padding_y), min_size.y);
  out.size = glm::ceil(out.size);

  // Glyphs sit on whole pixels: with quads aligned to the texel grid, a box at a whole-pixel
  // position samples texel centres and the text stays sharp.
  float pen = std::round(0.5f * (out.size.x - advance));
  const float baseline = std::round(0.5f * (out.size.y - font.line_height()) + font.ascent);
  for (const char c : ascii) {
    const GlyphMetrics& g = font.glyph(c);
    if (!g.empty()) {
      const glm::vec2 origin(std::round(pen), baseline);
      out.glyphs.push_back({g.uv, glm::vec4(origin, origin) + g.quad});
    }
    pen += g.advance;
  }
  return out;
}

std::vector<gpu::GlyphGpu> build_glyph_buffer(const FontAtlas& font,
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
    const LabelTextLayout layout = layout_label_text(font, texts[i], style, label.size);
    label.size = layout.size;
    label.glyph_first = static_cast<uint32_t>(glyphs.size());
    label.glyph_count = static_cast<uint32_t>(layout.glyphs.size());
    glyphs.insert(glyphs.end(), layout.glyphs.begin(), layout.glyphs.end());
  }
  return glyphs;
}

}  // namespace strata
