// Label text: OpenType/TrueType faces read by FreeType and shaped by HarfBuzz (kerning, ligatures,
// combining marks, Arabic joining), a character the main face lacks taken from the first fallback
// face that has it, right-to-left and mixed text put in visual order by GNU FriBiDi (the Unicode
// bidirectional algorithm), and the glyphs a set of texts uses rasterised into an R8 coverage
// atlas. Labels sample the
// atlas with bilinear filtering, so every glyph keeps one texel of zero coverage around it.
#pragma once

#include <compare>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

struct FT_FaceRec_;  // FreeType's face (FT_Face), for writers that draw the outlines

namespace strata {

// From Debian's fonts-dejavu-core.
inline constexpr const char* kDefaultFontPath = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
// Tried in order for characters the main face lacks (Debian's fonts-freefont-ttf, then a CJK
// face: fonts-wqy-microhei, which scripts/setup.sh installs, else fonts-noto-cjk, fonts-wqy-zenhei
// or fonts-droid-fallback); those not installed are skipped. Of the CJK faces only the first
// installed one is read.
inline constexpr const char* kFallbackFontPaths[] = {
    "/usr/share/fonts/truetype/freefont/FreeSans.ttf",
    "/usr/share/fonts/truetype/freefont/FreeSerif.ttf"};
inline constexpr const char* kCjkFontPaths[] = {
    "/usr/share/fonts/truetype/wqy/wqy-microhei.ttc",
    "/usr/share/fonts/opentype/noto/NotoSansCJK-Regular.ttc",
    "/usr/share/fonts/truetype/wqy/wqy-zenhei.ttc",
    "/usr/share/fonts/truetype/droid/DroidSansFallbackFull.ttf"};

// A paragraph's base direction: automatic takes its first strong character's (left-to-right when
// it has none), as HTML's dir=auto does.
enum class TextDirection { automatic, left_to_right, right_to_left };

// A glyph of one of the font's faces (0: the main face, then the fallbacks in order).
struct GlyphKey {
  uint32_t face = 0;
  uint32_t glyph = 0;
  auto operator<=>(const GlyphKey&) const = default;
};

// A shaped glyph: its pen position from the line's start on the baseline, pixels, y down.
struct ShapedGlyph {
  GlyphKey key;
  glm::vec2 pen{0.0f};
  uint32_t cluster = 0;  // the (first) character it draws: an index into the line's code points
};

// Glyphs shaped together: one face, one direction, the characters [first_char, first_char +
// char_count) of the line drawn by glyphs [first_glyph, first_glyph + glyph_count).
struct ShapedRun {
  size_t first_glyph = 0, glyph_count = 0;
  size_t first_char = 0, char_count = 0;
  bool right_to_left = false;
};

struct ShapedLine {
  std::u32string text;              // the line's characters in logical order (what clusters index)
  std::vector<ShapedGlyph> glyphs;  // in visual order, left to right
  std::vector<ShapedRun> runs;      // in visual order
  float advance = 0.0f;             // the line's width, pixels
  bool right_to_left = false;       // the paragraph's resolved direction
  std::vector<char32_t> missing;    // characters no face has (drawn as the missing-glyph box),
                                    // each once, in logical order
};

struct GlyphMetrics {
  glm::vec4 quad{0.0f};  // x0, y0, x1, y1: pixels from the pen on the baseline, y down
  glm::vec4 uv{0.0f};    // u0, v0, u1, v1: the same rectangle in the atlas, normalised
  bool empty() const { return quad.z <= quad.x || quad.w <= quad.y; }
};

struct FontAtlas {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<uint8_t> coverage;  // R8, row-major, width x height
  std::map<GlyphKey, GlyphMetrics> glyphs;
  // The glyph's metrics (an empty glyph when it was not baked).
  GlyphMetrics glyph(GlyphKey key) const;
};

class Font {
 public:
  // The main face at `path` (STRATA_FONT replaces the default: see font_file) sized so that its
  // ascent to descent spans `pixel_height` pixels, with the fallback faces that exist. Throws
  // Error naming the file (and, for the default font, the Debian package) when the main face is
  // missing or not a font, or the size is outside 4..512.
  explicit Font(float pixel_height, const std::string& path = kDefaultFontPath);
  ~Font();
  Font(Font&&) noexcept;
  Font& operator=(Font&&) noexcept;

  float pixel_height() const { return pixel_height_; }
  float ascent() const { return ascent_; }    // pixels above the baseline (positive)
  float descent() const { return descent_; }  // pixels below the baseline (negative)
  float line_height() const { return ascent_ - descent_; }
  // Baseline to baseline.
  float line_spacing() const { return line_spacing_; }
  size_t face_count() const;
  // The size of an em in pixels, as the faces are set (ascent to descent is pixel_height).
  float em_pixels() const { return em_pixels_; }
  // Face `index` (0: the main face, then the fallbacks) at em_pixels, for drawing its outlines
  // (frame/vector_picture.cpp); the Font keeps it.
  FT_FaceRec_* face(size_t index) const;
  // Its family name ("DejaVu Sans").
  std::string family_name(size_t index) const;

  // One line of UTF-8 text (malformed bytes become U+FFFD), shaped: its embedding levels resolved
  // in `direction` (the paragraph's: see paragraph_direction), cut into runs of one level, face
  // and script, each shaped in its direction, the runs in visual order. A character no face has
  // is drawn with the main face's missing-glyph box and listed in `missing`.
  ShapedLine shape(std::string_view line, TextDirection direction = TextDirection::automatic) const;
  // Whether some face has a glyph for `codepoint`.
  bool covers(char32_t codepoint) const;

  // Rasterises `keys` (duplicates allowed) into an atlas 512 texels wide.
  FontAtlas bake(std::span<const GlyphKey> keys) const;

 private:
  struct Faces;
  std::unique_ptr<Faces> faces_;
  float pixel_height_ = 0.0f;
  float ascent_ = 0.0f;
  float descent_ = 0.0f;
  float line_spacing_ = 0.0f;
  float em_pixels_ = 0.0f;
};

// The font file to read for `path`: STRATA_FONT, when set, replaces the default font (hosts
// without fonts-dejavu-core).
std::string font_file(const std::string& path = kDefaultFontPath);

// UTF-8 to code points; a malformed or truncated sequence becomes one U+FFFD.
std::u32string decode_utf8(std::string_view text);

// Code points to UTF-8 (a value past U+10FFFF or a surrogate becomes U+FFFD).
std::string encode_utf8(std::u32string_view text);

// The direction of the first strong character of `paragraph` (UTF-8): right_to_left or
// left_to_right (also when it has none).
TextDirection paragraph_direction(std::string_view paragraph);

// `text` (UTF-8) safe to print on a terminal: control characters (C0, DEL, C1, U+0000 too) and
// bidirectional controls written \u0007, \u001B, ...; a malformed byte \xFF; the rest as is.
std::string printable_text(std::string_view text);

// "U+1F600".
std::string codepoint_name(char32_t c);

}  // namespace strata
