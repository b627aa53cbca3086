#include "labeling/text_layout.h"

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"
#include "engine/core/image.h"

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
    // (every line of a wrapped paragraph has the paragraph's direction)
    const TextDirection direction = paragraph_direction(paragraph);
    if (style.max_width <= 0.0f) {
      lines.push_back(font.shape(paragraph, direction));
    } else {
      // Greedy: as many words as fit, each line shaped as a whole.
      std::string line;
      size_t word_start = 0;
      while (word_start <= paragraph.size()) {
        const size_t word_end = std::min(paragraph.find(' ', word_start), paragraph.size());
        const std::string_view word = paragraph.substr(word_start, word_end - word_start);
        const std::string longer =
            line.empty() ? std::string(word) : line + " " + std::string(word);
        if (!line.empty() && font.shape(longer, direction).advance > style.max_width) {
          lines.push_back(font.shape(line, direction));
          line = word;
        } else {
          line = longer;
        }
        word_start = word_end + 1;
      }
      lines.push_back(font.shape(line, direction));
    }
    if (end == text.size()) break;
    start = end + 1;
  }
  return lines;
}

const std::vector<ShapedLine>& ShapedTexts::lines(const Font& font, const std::string& text,
                                                  const TextStyle& style) {
  auto it = lines_.find(text);
  if (it == lines_.end()) it = lines_.emplace(text, shape_label_text(font, text, style)).first;
  return it->second;
}

std::vector<GlyphKey> label_glyph_keys(const Font& font, std::span<const std::string> texts,
                                       const TextStyle& style, ShapedTexts* shaped) {
  std::vector<GlyphKey> keys;
  for (const std::string& text : texts) {
    const std::vector<ShapedLine> own =
        shaped ? std::vector<ShapedLine>{} : shape_label_text(font, text, style);
    for (const ShapedLine& line : shaped ? shaped->lines(font, text, style) : own) {
      for (const ShapedGlyph& g : line.glyphs) keys.push_back(g.key);
    }
  }
  return keys;
}

FontAtlas bake_label_texts(const Font& font, std::span<const std::string> texts,
                           const TextStyle& style) {
  return font.bake(label_glyph_keys(font, texts, style));
}

std::vector<std::string> missing_glyph_warnings(const Font& font, std::span<const Label> labels) {
  std::vector<std::string> warnings;
  for (const Label& label : labels) {
    std::vector<char32_t> missing;
    for (const ShapedLine& line : shape_label_text(font, label.text)) {
      for (const char32_t c : line.missing) {
        if (std::find(missing.begin(), missing.end(), c) == missing.end()) missing.push_back(c);
      }
    }
    if (missing.empty()) continue;
    std::string characters;
    for (const char32_t c : missing) {
      const std::string utf8 = encode_utf8(std::u32string(1, c));
      const std::string shown = printable_text(utf8);
      characters += (characters.empty() ? "" : ", ") + codepoint_name(c) +
                    (shown == utf8 ? " (" + utf8 + ")" : "");
    }
    warnings.push_back("label " + std::to_string(label.id) + " \"" + printable_text(label.text) +
                       "\": no font has " + characters + "; drawn as an empty box");
  }
  return warnings;
}

LabelImages bake_label_images(std::span<const Label> labels, float scale) {
  LabelImages out;
  std::vector<Rgba8Image> drawn;
  for (const Label& label : labels) {
    if (!label.image) {
      out.blocks.emplace_back();
      continue;
    }
    const Rgba8Image& pixels = label.image->pixels;
    const float height = std::max(1.0f, std::round(label.image->height * scale));
    const float width =
        std::max(1.0f, std::round(height * float(pixels.width) / float(pixels.height)));
    drawn.push_back(resized_premultiplied(pixels, uint32_t(width), uint32_t(height)));
    out.blocks.push_back(
        LabelImageBlock{{width, height}, label.image->side == LabelImage::Side::left, {}});
  }
  out.atlas = pack_image_atlas(drawn);
  size_t next = 0;
  for (auto& block : out.blocks) {
    if (block) block->atlas = out.atlas.rects[next++];
  }
  return out;
}

LabelBoxLayout place_label_text(const Font& font, const std::vector<ShapedLine>& lines,
                                bool empty_text, const TextStyle& style, glm::vec2 min_size,
                                const std::optional<LabelImageBlock>& image) {
  float widest = 0.0f;
  for (const ShapedLine& line : lines) widest = std::max(widest, line.advance);
  const float spacing = std::round(font.line_spacing());
  const float text_height = font.line_height() + spacing * float(lines.size() - 1);

  // The text's own box; a picture adds a strip above or left of it (its padding on the far side
  // comes from the text box, or from the text box's padding alone when there is no text).
  glm::vec2 text_box(std::max(std::ceil(widest + 2.0f * style.padding_x), style.min_width),
                     std::ceil(text_height + 2.0f * style.padding_y));
  if (image && empty_text) text_box = {style.padding_x, style.padding_y};
  const glm::vec2 padding = glm::round(glm::vec2(style.padding_x, style.padding_y));
  glm::vec2 strip(0.0f), box = text_box;
  if (image && image->left) {
    strip.x = padding.x + image->size.x;
    box = {strip.x + text_box.x, std::max(text_box.y, image->size.y + 2.0f * padding.y)};
  } else if (image) {
    strip.y = padding.y + image->size.y;
    box = {std::max(text_box.x, image->size.x + 2.0f * padding.x), strip.y + text_box.y};
  }

  LabelBoxLayout out;
  out.size = glm::ceil(glm::max(glm::max(box, min_size), glm::vec2(style.min_width, 0.0f)));
  if (image) {
    const glm::vec2 at =
        image->left ? glm::vec2(padding.x, std::round(0.5f * (out.size.y - image->size.y)))
                    : glm::vec2(std::round(0.5f * (out.size.x - image->size.x)), padding.y);
    out.image = glm::vec4(at, at + image->size);
  }
  const glm::vec2 region = out.size - strip;  // what the text is centred in
  float baseline = strip.y + std::round(0.5f * (region.y - text_height) + font.ascent());
  for (const ShapedLine& line : lines) {
    out.line_origins.emplace_back(strip.x + std::round(0.5f * (region.x - line.advance)), baseline);
    baseline += spacing;
  }
  return out;
}

LabelTextLayout layout_label_text(const Font& font, const FontAtlas& atlas, std::string_view text,
                                  const TextStyle& style, glm::vec2 min_size,
                                  const std::optional<LabelImageBlock>& image,
                                  const std::vector<ShapedLine>* shaped_lines) {
  const std::vector<ShapedLine> own =
      shaped_lines ? std::vector<ShapedLine>{} : shape_label_text(font, text, style);
  const std::vector<ShapedLine>& lines = shaped_lines ? *shaped_lines : own;
  const LabelBoxLayout box = place_label_text(font, lines, text.empty(), style, min_size, image);
  LabelTextLayout out;
  out.lines = lines.size();
  out.size = box.size;
  if (box.image) out.image = gpu::GlyphGpu{image->atlas, *box.image};
  for (size_t l = 0; l < lines.size(); ++l) {
    for (const ShapedGlyph& shaped : lines[l].glyphs) {
      const GlyphMetrics g = atlas.glyph(shaped.key);
      if (g.empty()) continue;
      const glm::vec2 origin = glyph_origin(box.line_origins[l], shaped);
      out.glyphs.push_back({g.uv, glm::vec4(origin, origin) + g.quad});
    }
  }
  return out;
}

std::vector<gpu::GlyphGpu> build_glyph_buffer(
    const Font& font, const FontAtlas& atlas, std::span<const std::string> texts,
    std::span<gpu::LabelGpu> labels, const TextStyle& style,
    std::span<const std::optional<LabelImageBlock>> images, ShapedTexts* shaped) {
  if (texts.size() != labels.size() || (!images.empty() && images.size() != labels.size())) {
    throw Error("labels: " + std::to_string(texts.size()) + " texts and " +
                std::to_string(images.size()) + " images for " + std::to_string(labels.size()) +
                " labels");
  }
  std::vector<gpu::GlyphGpu> glyphs;
  for (size_t i = 0; i < texts.size(); ++i) {
    gpu::LabelGpu& label = labels[i];
    const LabelTextLayout layout = layout_label_text(
        font, atlas, texts[i], style, label.size, images.empty() ? std::nullopt : images[i],
        shaped ? &shaped->lines(font, texts[i], style) : nullptr);
    label.size = layout.size;
    label.glyph_first = static_cast<uint32_t>(glyphs.size());
    label.glyph_count = static_cast<uint32_t>(layout.glyphs.size());
    label.image_quads = layout.image ? 1u : 0u;
    glyphs.insert(glyphs.end(), layout.glyphs.begin(), layout.glyphs.end());
    if (layout.image) glyphs.push_back(*layout.image);
  }
  return glyphs;
}

}  // namespace strata
