#include "labeling/annotations.h"

#include <algorithm>
#include <cmath>

#include "shared/label_drawing.h"

namespace strata {
namespace {

constexpr const char* kEllipsis = "\xE2\x80\xA6";  // "…"

float advance(const Font& font, const std::string& text) {
  return font.shape(text).advance;
}

// `text`, or its longest start (whole code points) with "…" that is at most `width` wide.
std::string fitted(const Font& font, const std::string& text, float width) {
  if (advance(font, text) <= width) return text;
  std::string start = text;
  while (!start.empty()) {
    // (the last code point: its continuation bytes, then its first byte)
    while (!start.empty() && (uint8_t(start.back()) & 0xC0u) == 0x80u) start.pop_back();
    if (!start.empty()) start.pop_back();
    if (advance(font, start + kEllipsis) <= width) return start + kEllipsis;
  }
  return kEllipsis;
}

// A text on one line: its line breaks (a label's text may have some) become spaces.
std::string one_line(std::string text) {
  std::replace_if(
      text.begin(), text.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  return text;
}

glm::vec4 text_colour() {
  const gpu::vec4 c = gpu::LABEL_TEXT_COLOR;
  return {c.x, c.y, c.z, c.w};
}

TextRun run(const Font& font, std::string text, glm::vec2 origin) {
  const float width = advance(font, text);
  return {std::move(text), origin, font.pixel_height(), width, text_colour()};
}

glm::uvec4 kept_free(glm::vec4 rect, float gap, glm::uvec2 image) {
  const glm::vec4 grown = glm::vec4(rect.x - gap, rect.y - gap, rect.z + gap, rect.w + gap);
  const glm::vec2 size(image);
  const glm::vec2 lo = glm::clamp(glm::floor(glm::vec2(grown.x, grown.y)), glm::vec2(0.0f), size);
  const glm::vec2 hi = glm::clamp(glm::ceil(glm::vec2(grown.z, grown.w)), glm::vec2(0.0f), size);
  return {uint32_t(lo.x), uint32_t(lo.y), uint32_t(hi.x), uint32_t(hi.y)};
}

TitleLayout layout_title(const Font& font, const AnnotationSettings& s, glm::uvec2 image,
                         float gap) {
  const glm::vec2 padding = glm::round(glm::vec2(s.style.padding_x, s.style.padding_y));
  const float room = std::max(float(image.x) - 2.0f * gap - 2.0f * padding.x, 0.0f);
  const std::string text = fitted(font, one_line(s.title), room);
  const float width = advance(font, text);
  const glm::vec2 size = glm::ceil(glm::vec2(std::max(width + 2.0f * padding.x, s.style.min_width),
                                             font.line_height() + 2.0f * padding.y));
  const glm::vec2 lo(std::round(0.5f * (float(image.x) - size.x)), gap);
  const float baseline = lo.y + std::round(0.5f * (size.y - font.line_height()) + font.ascent());
  TitleLayout title;
  title.box.rect = glm::vec4(lo, lo + size);
  title.text = run(font, text, {lo.x + std::round(0.5f * (size.x - width)), baseline});
  return title;
}

bool on_right(LegendCorner c) {
  return c == LegendCorner::bottom_right || c == LegendCorner::top_right;
}
bool on_bottom(LegendCorner c) {
  return c == LegendCorner::bottom_right || c == LegendCorner::bottom_left;
}

// The legend inside `room`, in its corner of it; none without room for a row.
std::optional<LegendLayout> layout_legend(const Font& font, const AnnotationSettings& s,
                                          std::span<const LegendEntry> entries, glm::vec4 room) {
  const glm::vec2 padding = glm::round(glm::vec2(s.style.padding_x, s.style.padding_y));
  const float spacing = std::round(font.line_spacing());
  const float rows_height = room.w - room.y - 2.0f * padding.y - font.line_height();
  if (entries.empty() || rows_height < 0.0f) return std::nullopt;
  const size_t fit = size_t(std::floor(rows_height / spacing)) + 1;
  const size_t listed = entries.size() <= fit ? entries.size() : fit - 1;
  bool swatches = false;
  for (size_t i = 0; i < listed; ++i) swatches = swatches || entries[i].colour.has_value();
  const float side = std::round(0.7f * font.pixel_height());
  const float indent = swatches ? side + std::round(0.4f * font.pixel_height()) : 0.0f;
  const float text_room = std::max(room.z - room.x - 2.0f * padding.x - indent, 0.0f);

  std::vector<std::string> texts;
  for (size_t i = 0; i < listed; ++i) {
    texts.push_back(fitted(font, one_line(entries[i].text), text_room));
  }
  if (listed < entries.size())
    texts.push_back("+" + std::to_string(entries.size() - listed) + " more");
  float widest = 0.0f;
  for (const std::string& t : texts) widest = std::max(widest, advance(font, t));
  const glm::vec2 size = glm::ceil(
      glm::vec2(std::max(widest + indent + 2.0f * padding.x, s.style.min_width),
                font.line_height() + spacing * float(texts.size() - 1) + 2.0f * padding.y));
  const glm::vec2 lo(on_right(s.corner) ? room.z - size.x : room.x,
                     on_bottom(s.corner) ? room.w - size.y : room.y);

  LegendLayout legend;
  legend.box.rect = glm::vec4(lo, lo + size);
  legend.listed = listed;
  float baseline = lo.y + padding.y + std::round(font.ascent());
  for (size_t i = 0; i < texts.size(); ++i, baseline += spacing) {
    LegendRow row;
    row.text = run(font, texts[i], {lo.x + padding.x + indent, baseline});
    if (i < listed && entries[i].colour) {
      const float middle = baseline - font.ascent() + 0.5f * font.line_height();
      const glm::vec2 at(lo.x + padding.x, std::round(middle - 0.5f * side));
      row.swatch = glm::vec4(at, at + side);
      row.colour = *entries[i].colour;
    }
    legend.rows.push_back(std::move(row));
  }
  return legend;
}

}  // namespace

std::vector<NamedBox> AnnotationLayout::boxes() const {
  std::vector<NamedBox> out;
  if (title) out.push_back({"title", title->box.rect});
  if (legend) out.push_back({"legend", legend->box.rect});
  return out;
}

AnnotationLayout layout_annotations(const AnnotationFonts& fonts,
                                    const AnnotationSettings& settings, glm::uvec2 image,
                                    std::span<const LegendEntry> entries,
                                    std::optional<glm::vec4> legend_room) {
  const float gap = std::round(settings.gap_em * fonts.text.pixel_height());
  AnnotationLayout out;
  float top = gap;  // where the legend's room may start
  if (!settings.title.empty()) {
    out.title = layout_title(fonts.title, settings, image, gap);
    out.keep_out.push_back(kept_free(out.title->box.rect, gap, image));
    top = out.title->box.rect.w + 2.0f * gap;
  }
  if (settings.legend) {
    const glm::vec2 far = glm::vec2(image) - gap;
    const glm::vec2 most = glm::round(
        glm::vec2(image) * glm::vec2(settings.legend_width_share, settings.legend_height_share));
    const glm::vec2 lo(on_right(settings.corner) ? std::max(far.x - most.x, gap) : gap,
                       on_bottom(settings.corner) ? std::max(far.y - most.y, top) : top);
    const glm::vec2 hi(on_right(settings.corner) ? far.x : std::min(gap + most.x, far.x),
                       on_bottom(settings.corner) ? far.y : std::min(top + most.y, far.y));
    const glm::vec4 room = legend_room.value_or(glm::vec4(lo, hi));
    out.legend = layout_legend(fonts.text, settings, entries, room);
    if (out.legend) {
      out.keep_out.push_back(kept_free(legend_room ? room : out.legend->box.rect, gap, image));
    }
  }
  return out;
}

}  // namespace strata
