// A bitmap font for label text: printable ASCII of one TrueType font baked by stb_truetype into an
// R8 coverage atlas, with per-character metrics. Labels sample the atlas with bilinear filtering,
// so every glyph keeps one texel of zero coverage around it (see font.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

namespace strata {

inline constexpr char kFirstFontChar = 32;  // ' '
inline constexpr char kLastFontChar = 126;  // '~'
inline constexpr char kReplacementChar = '?';
// From Debian's fonts-dejavu-core.
inline constexpr const char* kDefaultFontPath = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

struct GlyphMetrics {
  float advance = 0.0f;  // pen movement to the next character, pixels
  glm::vec4 quad{0.0f};  // x0, y0, x1, y1: pixels from the pen on the baseline, y down
  glm::vec4 uv{0.0f};    // u0, v0, u1, v1: the same rectangle in the atlas, normalised
  bool empty() const { return quad.z <= quad.x || quad.w <= quad.y; }
};

struct FontAtlas {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<uint8_t> coverage;  // R8, row-major, width x height
  float pixel_height = 0.0f;      // as asked for: ascent - descent
  float ascent = 0.0f;            // pixels above the baseline (positive)
  float descent = 0.0f;           // pixels below the baseline (negative)
  float line_gap = 0.0f;
  std::array<GlyphMetrics, kLastFontChar - kFirstFontChar + 1> glyphs{};

  float line_height() const { return ascent - descent; }
  // The metrics of `c`; characters outside printable ASCII get those of '?'.
  const GlyphMetrics& glyph(char c) const;
};

// The font file to read for `path`: STRATA_FONT, when set, replaces the default font (hosts
// without fonts-dejavu-core).
std::string font_file(const std::string& path = kDefaultFontPath);

// Bakes printable ASCII of the font at `path` at `pixel_height` (ascent to descent). Throws
// Error naming the path (and, for the default font, the Debian package) when it is missing or
// not a font.
FontAtlas load_font_atlas(float pixel_height, const std::string& path = kDefaultFontPath);

// `text` (UTF-8) as printable ASCII: each character outside 32..126, multi-byte sequences
// included, becomes one '?'.
std::string printable_ascii(std::string_view text);

}  // namespace strata
