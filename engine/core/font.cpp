#include "engine/core/font.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>

#include <stb_truetype.h>

#include "engine/core/error.h"

namespace strata {
namespace {

constexpr uint32_t kAtlasWidth = 512;
// Zero texels around each glyph's ink: a glyph's quad covers its ink plus this border, so bilinear
// filtering at the quad's edge fades to zero and never reaches a neighbour's ink.
constexpr int kPad = 1;

std::vector<unsigned char> read_font_file(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw Error(path + ": no such font file (Debian package fonts-dejavu-core provides " +
                kDefaultFontPath + ")");
  }
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

struct Cell {
  int x = 0, y = 0, w = 0, h = 0;  // the glyph's rectangle in the atlas, padding included
  int ix0 = 0, iy0 = 0;            // ink offset from the pen, pixels
};

// Shelf packing, in character order: ample for 95 glyphs, and deterministic.
std::vector<Cell> pack(const stbtt_fontinfo& font, float scale, uint32_t& height) {
  std::vector<Cell> cells;
  int x = 0, y = 0, shelf = 0;
  for (int c = kFirstFontChar; c <= kLastFontChar; ++c) {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    stbtt_GetCodepointBitmapBox(&font, c, scale, scale, &x0, &y0, &x1, &y1);
    Cell cell{0, 0, x1 - x0 + 2 * kPad, y1 - y0 + 2 * kPad, x0, y0};
    if (cell.w > int(kAtlasWidth)) throw Error("font: glyphs too large for the atlas");
    if (x + cell.w > int(kAtlasWidth)) {
      x = 0;
      y += shelf;
      shelf = 0;
    }
    cell.x = x;
    cell.y = y;
    x += cell.w;
    shelf = std::max(shelf, cell.h);
    cells.push_back(cell);
  }
  height = static_cast<uint32_t>(y + shelf);
  return cells;
}

}  // namespace

const GlyphMetrics& FontAtlas::glyph(char c) const {
  if (c < kFirstFontChar || c > kLastFontChar) c = kReplacementChar;
  return glyphs[static_cast<size_t>(c - kFirstFontChar)];
}

std::string font_file(const std::string& path) {
  const char* env = std::getenv("STRATA_FONT");
  return path == kDefaultFontPath && env && *env ? std::string(env) : path;
}

FontAtlas load_font_atlas(float pixel_height, const std::string& path) {
  if (!(pixel_height >= 4.0f && pixel_height <= 128.0f)) {
    throw Error("font: pixel height " + std::to_string(pixel_height) + " is not in 4..128");
  }
  const std::vector<unsigned char> data = read_font_file(font_file(path));
  // stb_truetype trusts its input: refuse what cannot even hold a font's table directory.
  if (data.size() < 12) throw Error(path + ": not a TrueType font");
  stbtt_fontinfo font{};
  const int offset = stbtt_GetFontOffsetForIndex(data.data(), 0);
  if (offset < 0 || !stbtt_InitFont(&font, data.data(), offset)) {
    throw Error(path + ": not a TrueType font");
  }
  const float scale = stbtt_ScaleForPixelHeight(&font, pixel_height);
  FontAtlas atlas;
  atlas.pixel_height = pixel_height;
  int ascent = 0, descent = 0, line_gap = 0;
  stbtt_GetFontVMetrics(&font, &ascent, &descent, &line_gap);
  atlas.ascent = float(ascent) * scale;
  atlas.descent = float(descent) * scale;
  atlas.line_gap = float(line_gap) * scale;

  const std::vector<Cell> cells = pack(font, scale, atlas.height);
  atlas.width = kAtlasWidth;
  atlas.height = std::max(atlas.height, 1u);
  atlas.coverage.assign(size_t{atlas.width} * atlas.height, 0);
  const glm::vec2 texel = 1.0f / glm::vec2(atlas.width, atlas.height);
  for (int c = kFirstFontChar; c <= kLastFontChar; ++c) {
    const Cell& cell = cells[size_t(c - kFirstFontChar)];
    GlyphMetrics& g = atlas.glyphs[size_t(c - kFirstFontChar)];
    int advance = 0, left_bearing = 0;
    stbtt_GetCodepointHMetrics(&font, c, &advance, &left_bearing);
    g.advance = float(advance) * scale;
    if (cell.w == 2 * kPad || cell.h == 2 * kPad) continue;  // no ink: ' '
    uint8_t* ink = &atlas.coverage[size_t(cell.y + kPad) * atlas.width + size_t(cell.x + kPad)];
    stbtt_MakeCodepointBitmap(&font, ink, cell.w - 2 * kPad, cell.h - 2 * kPad, int(atlas.width),
                              scale, scale, c);
    const glm::vec2 origin(float(cell.ix0 - kPad), float(cell.iy0 - kPad));
    g.quad = glm::vec4(origin, origin + glm::vec2(float(cell.w), float(cell.h)));
    g.uv = glm::vec4(float(cell.x) * texel.x, float(cell.y) * texel.y,
                     float(cell.x + cell.w) * texel.x, float(cell.y + cell.h) * texel.y);
  }
  return atlas;
}

std::string printable_ascii(std::string_view text) {
  std::string out;
  bool in_sequence = false;  // after a UTF-8 lead byte: its continuation bytes are skipped
  for (const char ch : text) {
    const auto b = static_cast<unsigned char>(ch);
    const bool continuation = (b & 0xC0u) == 0x80u;
    if (continuation && in_sequence) continue;
    in_sequence = b >= 0xC0u;
    const bool printable = b >= uint8_t(kFirstFontChar) && b <= uint8_t(kLastFontChar);
    out.push_back(printable ? ch : kReplacementChar);
  }
  return out;
}

}  // namespace strata
