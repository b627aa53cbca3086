#include "engine/core/font.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numeric>

#include <fribidi.h>
#include <ft2build.h>
#include FT_FREETYPE_H
#include <hb-ft.h>
#include <hb.h>

#include "engine/core/error.h"

namespace strata {
namespace {

constexpr uint32_t kAtlasWidth = 512;
// Zero texels around each glyph's ink: a glyph's quad covers its ink plus this border, so bilinear
// filtering at the quad's edge fades to zero and never reaches a neighbour's ink.
constexpr int kPad = 1;
constexpr char32_t kReplacement = 0xFFFD;
// FriBiDi indexes with int; a label line is far shorter.
constexpr size_t kMaxLineCharacters = size_t(1) << 24;

// Light hinting (vertical only) keeps small text crisp without moving glyphs sideways, so the
// shaped advances (unhinted) and the ink agree.
constexpr FT_Int32 kLoadFlags = FT_LOAD_TARGET_LIGHT;

}  // namespace

struct Font::Faces {
  FT_Library library = nullptr;
  std::vector<FT_Face> faces;     // main, then fallbacks
  std::vector<hb_font_t*> fonts;  // HarfBuzz fonts over them

  ~Faces() {
    for (hb_font_t* f : fonts) hb_font_destroy(f);
    for (FT_Face f : faces) FT_Done_Face(f);
    if (library) FT_Done_FreeType(library);
  }
};

std::string font_file(const std::string& path) {
  const char* env = std::getenv("STRATA_FONT");
  return path == kDefaultFontPath && env && *env ? std::string(env) : path;
}

namespace {

// The code point at text[i] and its length in bytes; 0 for a malformed or truncated sequence
// (overlong forms, surrogates and values past U+10FFFF are malformed too).
size_t decode_one(std::string_view text, size_t i, char32_t& cp) {
  const auto b = static_cast<unsigned char>(text[i]);
  const size_t length = b < 0x80u              ? 1
                        : (b & 0xE0u) == 0xC0u ? 2
                        : (b & 0xF0u) == 0xE0u ? 3
                        : (b & 0xF8u) == 0xF0u ? 4
                                               : 0;
  if (length == 0 || i + length > text.size()) return 0;
  cp = length == 1 ? b : length == 2 ? (b & 0x1Fu) : length == 3 ? (b & 0x0Fu) : (b & 0x07u);
  for (size_t k = 1; k < length; ++k) {
    const auto c = static_cast<unsigned char>(text[i + k]);
    if ((c & 0xC0u) != 0x80u) return 0;
    cp = (cp << 6) | (c & 0x3Fu);
  }
  const char32_t least[] = {0, 0, 0x80, 0x800, 0x10000};
  const bool ok = cp >= least[length] && cp <= 0x10FFFF && !(cp >= 0xD800 && cp <= 0xDFFF);
  return ok ? length : 0;
}

}  // namespace

std::u32string decode_utf8(std::string_view text) {
  std::u32string out;
  size_t i = 0;
  while (i < text.size()) {
    char32_t cp = 0;
    const size_t length = decode_one(text, i, cp);
    if (length == 0) {
      out.push_back(kReplacement);
      ++i;
      while (i < text.size() && (static_cast<unsigned char>(text[i]) & 0xC0u) == 0x80u) ++i;
      continue;
    }
    out.push_back(cp);
    i += length;
  }
  return out;
}

std::string encode_utf8(std::u32string_view text) {
  std::string out;
  for (char32_t c : text) {
    if (c > 0x10FFFF || (c >= 0xD800 && c <= 0xDFFF)) c = kReplacement;
    if (c < 0x80) {
      out += char(c);
    } else if (c < 0x800) {
      out += {char(0xC0 | (c >> 6)), char(0x80 | (c & 0x3F))};
    } else if (c < 0x10000) {
      out += {char(0xE0 | (c >> 12)), char(0x80 | ((c >> 6) & 0x3F)), char(0x80 | (c & 0x3F))};
    } else {
      out += {char(0xF0 | (c >> 18)), char(0x80 | ((c >> 12) & 0x3F)),
              char(0x80 | ((c >> 6) & 0x3F)), char(0x80 | (c & 0x3F))};
    }
  }
  return out;
}

std::string codepoint_name(char32_t c) {
  char name[16];
  std::snprintf(name, sizeof name, "U+%04X", unsigned(c));
  return name;
}

std::string printable_text(std::string_view text) {
  std::string out;
  char escape[16];
  for (size_t i = 0; i < text.size();) {
    char32_t cp = 0;
    const size_t length = decode_one(text, i, cp);
    if (length == 0) {
      std::snprintf(escape, sizeof escape, "\\x%02X",
                    unsigned(static_cast<unsigned char>(text[i])));
      out += escape;
      ++i;
      continue;
    }
    // (C0 and C1 controls, DEL, and the bidirectional controls that would reorder what follows)
    const bool control = cp < 0x20 || (cp >= 0x7F && cp <= 0x9F) || cp == 0x200E || cp == 0x200F ||
                         (cp >= 0x202A && cp <= 0x202E) || (cp >= 0x2066 && cp <= 0x2069);
    if (control) {
      std::snprintf(escape, sizeof escape, "\\u%04X", unsigned(cp));
      out += escape;
    } else {
      out += text.substr(i, length);
    }
    i += length;
  }
  return out;
}

TextDirection paragraph_direction(std::string_view paragraph) {
  // (rules P2 and P3 of the bidirectional algorithm: FriBiDi's own resolution of FRIBIDI_PAR_ON,
  // which skips the characters inside isolates)
  const std::u32string text = decode_utf8(paragraph);
  if (text.empty() || text.size() > kMaxLineCharacters) return TextDirection::left_to_right;
  const auto length = static_cast<FriBidiStrIndex>(text.size());
  const auto* chars = reinterpret_cast<const FriBidiChar*>(text.data());
  std::vector<FriBidiCharType> types(text.size());
  std::vector<FriBidiBracketType> brackets(text.size());
  std::vector<FriBidiLevel> levels(text.size());
  fribidi_get_bidi_types(chars, length, types.data());
  fribidi_get_bracket_types(chars, length, types.data(), brackets.data());
  FriBidiParType base = FRIBIDI_PAR_ON;
  if (fribidi_get_par_embedding_levels_ex(types.data(), brackets.data(), length, &base,
                                          levels.data()) == 0) {
    throw Error("font: FriBiDi could not resolve a label paragraph of " +
                std::to_string(text.size()) + " characters");
  }
  return FRIBIDI_IS_RTL(base) ? TextDirection::right_to_left : TextDirection::left_to_right;
}

Font::Font(float pixel_height, const std::string& path) : faces_(std::make_unique<Faces>()) {
  if (!(pixel_height >= 4.0f && pixel_height <= 512.0f)) {
    throw Error("font: pixel height " + std::to_string(pixel_height) + " is not in 4..512");
  }
  const std::string file = font_file(path);
  if (!std::filesystem::is_regular_file(file)) {
    throw Error(file + ": no such font file (Debian package fonts-dejavu-core provides " +
                kDefaultFontPath + ")");
  }
  if (FT_Init_FreeType(&faces_->library) != 0) throw Error("font: FreeType did not start");
  std::vector<std::string> files{file};
  for (const char* fallback : kFallbackFontPaths) {
    if (std::filesystem::is_regular_file(fallback)) files.emplace_back(fallback);
  }
  for (const char* cjk : kCjkFontPaths) {
    if (std::filesystem::is_regular_file(cjk)) {
      files.emplace_back(cjk);
      break;
    }
  }
  float em_pixels = 0.0f;
  for (size_t i = 0; i < files.size(); ++i) {
    FT_Face face = nullptr;
    if (FT_New_Face(faces_->library, files[i].c_str(), 0, &face) != 0 || !FT_IS_SCALABLE(face)) {
      if (face) FT_Done_Face(face);
      if (i == 0) throw Error(files[i] + ": not a scalable font FreeType can read");
      continue;  // (a broken fallback is skipped, never fatal)
    }
    if (i == 0) {
      const float span = float(face->ascender - face->descender);
      if (!(span > 0.0f)) {
        FT_Done_Face(face);
        throw Error(files[i] + ": the font has no ascent or descent");
      }
      // The main face's ascent to descent spans pixel_height; every face gets the same em.
      em_pixels = pixel_height * float(face->units_per_EM) / span;
      const float scale = em_pixels / float(face->units_per_EM);
      ascent_ = float(face->ascender) * scale;
      descent_ = float(face->descender) * scale;
      line_spacing_ = std::max(float(face->height) * scale, ascent_ - descent_);
    }
    const FT_F26Dot6 em = FT_F26Dot6(std::lround(em_pixels * 64.0f));
    FT_Set_Char_Size(face, 0, em, 72, 72);
    em_pixels_ = float(em) / 64.0f;
    faces_->faces.push_back(face);
    hb_font_t* font = hb_ft_font_create_referenced(face);
    hb_ft_font_set_load_flags(font, kLoadFlags);
    faces_->fonts.push_back(font);
  }
  pixel_height_ = pixel_height;
}

Font::~Font() = default;
Font::Font(Font&&) noexcept = default;
Font& Font::operator=(Font&&) noexcept = default;

size_t Font::face_count() const {
  return faces_->faces.size();
}

FT_FaceRec_* Font::face(size_t index) const {
  return faces_->faces.at(index);
}

std::string Font::family_name(size_t index) const {
  const FT_Face face = faces_->faces.at(index);
  return face->family_name ? face->family_name : "";
}

bool Font::covers(char32_t codepoint) const {
  for (FT_Face face : faces_->faces) {
    if (FT_Get_Char_Index(face, codepoint) != 0) return true;
  }
  return false;
}

namespace {

bool real_script(hb_script_t s) {
  return s != HB_SCRIPT_COMMON && s != HB_SCRIPT_INHERITED && s != HB_SCRIPT_UNKNOWN &&
         s != HB_SCRIPT_INVALID;
}

// The face of each character: the first that has it; a combining mark stays with its base's
// face when that face has the mark too; none has it: the main face (its missing-glyph box).
std::vector<uint32_t> faces_of(const std::u32string& text, const std::vector<FT_Face>& faces) {
  hb_unicode_funcs_t* unicode = hb_unicode_funcs_get_default();
  const size_t n = text.size();
  std::vector<uint32_t> face_of(n, 0);
  for (size_t i = 0; i < n; ++i) {
    const bool mark = hb_unicode_general_category(unicode, text[i]) ==
                      HB_UNICODE_GENERAL_CATEGORY_NON_SPACING_MARK;
    if (mark && i > 0 && FT_Get_Char_Index(faces[face_of[i - 1]], text[i]) != 0) {
      face_of[i] = face_of[i - 1];
      continue;
    }
    for (uint32_t f = 0; f < faces.size(); ++f) {
      if (FT_Get_Char_Index(faces[f], text[i]) != 0) {
        face_of[i] = f;
        break;
      }
    }
  }
  return face_of;
}

// The script of each character: spaces, digits, punctuation and marks (common, inherited) take
// the script before them, else the one after.
std::vector<hb_script_t> scripts_of(const std::u32string& text) {
  hb_unicode_funcs_t* unicode = hb_unicode_funcs_get_default();
  const size_t n = text.size();
  std::vector<hb_script_t> script(n, HB_SCRIPT_INVALID);
  for (size_t i = 0; i < n; ++i) {
    const hb_script_t s = hb_unicode_script(unicode, text[i]);
    script[i] = real_script(s) ? s : i > 0 ? script[i - 1] : HB_SCRIPT_INVALID;
  }
  for (size_t i = n; i-- > 0;) {
    if (script[i] == HB_SCRIPT_INVALID) script[i] = i + 1 < n ? script[i + 1] : HB_SCRIPT_COMMON;
  }
  return script;
}

struct VisualOrder {
  std::vector<FriBidiLevel> levels;  // each character's embedding level
  std::vector<FriBidiStrIndex> map;  // map[visual] = logical
  FriBidiParType base = FRIBIDI_PAR_LTR;
};

// The bidirectional algorithm: embedding levels for the line as a paragraph of its own in
// `direction`, then the visual order (trailing spaces at the paragraph's level). Marks are not
// moved after their bases (no FRIBIDI_FLAG_REORDER_NSM): HarfBuzz places them, shaping each
// right-to-left run in its own direction.
VisualOrder visual_order(const std::u32string& text, TextDirection direction) {
  const size_t n = text.size();
  const auto length = static_cast<FriBidiStrIndex>(n);
  const auto* chars = reinterpret_cast<const FriBidiChar*>(text.data());
  std::vector<FriBidiCharType> types(n);
  std::vector<FriBidiBracketType> brackets(n);
  VisualOrder order{std::vector<FriBidiLevel>(n, 0), std::vector<FriBidiStrIndex>(n)};
  std::iota(order.map.begin(), order.map.end(), FriBidiStrIndex{0});
  order.base = direction == TextDirection::left_to_right   ? FRIBIDI_PAR_LTR
               : direction == TextDirection::right_to_left ? FRIBIDI_PAR_RTL
                                                           : FRIBIDI_PAR_ON;
  if (n > 0) {
    fribidi_get_bidi_types(chars, length, types.data());
    fribidi_get_bracket_types(chars, length, types.data(), brackets.data());
    if (fribidi_get_par_embedding_levels_ex(types.data(), brackets.data(), length, &order.base,
                                            order.levels.data()) == 0 ||
        fribidi_reorder_line(0, types.data(), length, 0, order.base, order.levels.data(), nullptr,
                             order.map.data()) == 0) {
      throw Error("font: FriBiDi could not order a label line of " + std::to_string(n) +
                  " characters");
    }
  } else if (order.base == FRIBIDI_PAR_ON) {
    order.base = FRIBIDI_PAR_LTR;
  }
  return order;
}

// A run: characters next to each other in both orders, of one level, face and script.
struct Run {
  size_t start = 0;  // its first character in logical order
  size_t count = 0;
  bool rtl = false;
  uint32_t face = 0;
  hb_script_t script = HB_SCRIPT_COMMON;
};

// The run that starts at visual position v.
Run run_at(size_t v, const VisualOrder& order, const std::vector<uint32_t>& face_of,
           const std::vector<hb_script_t>& script) {
  const std::vector<FriBidiStrIndex>& map = order.map;
  const size_t n = map.size();
  const auto first = size_t(map[v]);
  const FriBidiLevel level = order.levels[first];
  const bool rtl = (level & 1) != 0;
  size_t w = v + 1;
  for (; w < n; ++w) {
    const auto logical = size_t(map[w]);
    const size_t expected = rtl ? size_t(map[w - 1]) - 1 : size_t(map[w - 1]) + 1;
    if (logical != expected || order.levels[logical] != level ||
        face_of[logical] != face_of[first] || script[logical] != script[first]) {
      break;
    }
  }
  return {rtl ? size_t(map[w - 1]) : first, w - v, rtl, face_of[first], script[first]};
}

// Shapes one run with HarfBuzz and appends its glyphs at `pen` (moved past them); characters no
// face draws (glyph 0) are added to out.missing.
void shape_run(hb_buffer_t* buffer, hb_font_t* font, const std::u32string& text, const Run& run,
               glm::vec2& pen, ShapedLine& out) {
  const size_t n = text.size();
  hb_buffer_clear_contents(buffer);
  // (the whole line is the context: shaping at a run's edge sees its neighbours)
  hb_buffer_add_utf32(buffer, reinterpret_cast<const uint32_t*>(text.data()), int(n),
                      unsigned(run.start), int(run.count));
  hb_buffer_set_direction(buffer, run.rtl ? HB_DIRECTION_RTL : HB_DIRECTION_LTR);
  hb_buffer_set_script(buffer, run.script);
  hb_buffer_guess_segment_properties(buffer);  // (the language)
  hb_shape(font, buffer, nullptr, 0);
  out.runs.push_back({out.glyphs.size(), 0, run.start, run.count, run.rtl});
  unsigned glyphs = 0;
  const hb_glyph_info_t* info = hb_buffer_get_glyph_infos(buffer, &glyphs);
  const hb_glyph_position_t* position = hb_buffer_get_glyph_positions(buffer, &glyphs);
  for (unsigned g = 0; g < glyphs; ++g) {
    const glm::vec2 offset(float(position[g].x_offset) / 64.0f,
                           -float(position[g].y_offset) / 64.0f);
    out.glyphs.push_back({{run.face, info[g].codepoint}, pen + offset, info[g].cluster});
    pen += glm::vec2(float(position[g].x_advance), -float(position[g].y_advance)) / 64.0f;
    const char32_t c = info[g].cluster < n ? text[info[g].cluster] : kReplacement;
    if (info[g].codepoint == 0 &&
        std::find(out.missing.begin(), out.missing.end(), c) == out.missing.end()) {
      out.missing.push_back(c);
    }
  }
  out.runs.back().glyph_count = glyphs;
}

}  // namespace

ShapedLine Font::shape(std::string_view line, TextDirection direction) const {
  const std::u32string text = decode_utf8(line);
  const size_t n = text.size();
  if (n > kMaxLineCharacters) {
    throw Error("font: a label line of " + std::to_string(n) + " characters (at most " +
                std::to_string(kMaxLineCharacters) + ")");
  }
  const std::vector<uint32_t> face_of = faces_of(text, faces_->faces);
  const std::vector<hb_script_t> script = scripts_of(text);
  const VisualOrder order = visual_order(text, direction);

  ShapedLine out;
  out.text = text;
  out.right_to_left = FRIBIDI_IS_RTL(order.base);
  glm::vec2 pen(0.0f);
  hb_buffer_t* buffer = hb_buffer_create();
  for (size_t v = 0; v < n;) {  // (runs in visual order)
    const Run run = run_at(v, order, face_of, script);
    v += run.count;
    shape_run(buffer, faces_->fonts[run.face], text, run, pen, out);
  }
  hb_buffer_destroy(buffer);
  // (the runs were visited in visual order; the missing characters are listed in logical order)
  std::sort(out.missing.begin(), out.missing.end(),
            [&](char32_t a, char32_t b) { return text.find(a) < text.find(b); });
  out.advance = pen.x;
  return out;
}

FontAtlas Font::bake(std::span<const GlyphKey> keys) const {
  struct Ink {
    std::vector<uint8_t> pixels;  // rows x width
    int width = 0, rows = 0, left = 0, top = 0;
    int x = 0, y = 0;  // the cell's place in the atlas (padding included)
  };
  std::map<GlyphKey, Ink> inks;
  for (const GlyphKey& key : keys) {
    if (key.face >= faces_->faces.size() || inks.contains(key)) continue;
    FT_Face face = faces_->faces[key.face];
    Ink ink;
    if (FT_Load_Glyph(face, key.glyph, kLoadFlags | FT_LOAD_RENDER) == 0 &&
        face->glyph->bitmap.pixel_mode == FT_PIXEL_MODE_GRAY) {
      const FT_Bitmap& b = face->glyph->bitmap;
      ink.width = int(b.width);
      ink.rows = int(b.rows);
      ink.left = face->glyph->bitmap_left;
      ink.top = face->glyph->bitmap_top;
      ink.pixels.resize(size_t(ink.width) * size_t(ink.rows));
      for (int r = 0; r < ink.rows; ++r) {
        const unsigned char* row = b.buffer + std::ptrdiff_t(r) * b.pitch;
        std::copy(row, row + ink.width, ink.pixels.begin() + std::ptrdiff_t(r) * ink.width);
      }
    }
    if (ink.width + 2 * kPad > int(kAtlasWidth))
      throw Error("font: a glyph too large for the atlas");
    inks.emplace(key, std::move(ink));
  }
  // Shelf packing in key order: deterministic.
  int x = 0, y = 0, shelf = 0;
  for (auto& [key, ink] : inks) {
    if (ink.width == 0 || ink.rows == 0) continue;
    const int w = ink.width + 2 * kPad, h = ink.rows + 2 * kPad;
    if (x + w > int(kAtlasWidth)) {
      x = 0;
      y += shelf;
      shelf = 0;
    }
    ink.x = x;
    ink.y = y;
    x += w;
    shelf = std::max(shelf, h);
  }
  FontAtlas atlas;
  atlas.width = kAtlasWidth;
  atlas.height = uint32_t(std::max(y + shelf, 1));
  atlas.coverage.assign(size_t{atlas.width} * atlas.height, 0);
  const glm::vec2 texel = 1.0f / glm::vec2(atlas.width, atlas.height);
  for (const auto& [key, ink] : inks) {
    GlyphMetrics g;
    if (ink.width > 0 && ink.rows > 0) {
      for (int r = 0; r < ink.rows; ++r) {
        std::copy_n(ink.pixels.begin() + std::ptrdiff_t(r) * ink.width, ink.width,
                    atlas.coverage.begin() + std::ptrdiff_t(size_t(ink.y + kPad + r) * atlas.width +
                                                            size_t(ink.x + kPad)));
      }
      const glm::vec2 origin(float(ink.left - kPad), float(-ink.top - kPad));
      const glm::vec2 size(float(ink.width + 2 * kPad), float(ink.rows + 2 * kPad));
      g.quad = glm::vec4(origin, origin + size);
      g.uv = glm::vec4(float(ink.x) * texel.x, float(ink.y) * texel.y,
                       float(ink.x) * texel.x + size.x * texel.x,
                       float(ink.y) * texel.y + size.y * texel.y);
    }
    atlas.glyphs.emplace(key, g);
  }
  return atlas;
}

GlyphMetrics FontAtlas::glyph(GlyphKey key) const {
  const auto found = glyphs.find(key);
  return found == glyphs.end() ? GlyphMetrics{} : found->second;
}

}  // namespace strata
