// Label text drawn as written: right-to-left and mixed text in visual order (checked against GNU
// FriBiDi's own reordering), Arabic joined, CJK from a fallback face, characters no face has
// named in a warning, and label texts printed by `strata info` with their control characters
// escaped.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <numeric>
#include <string>
#include <vector>

#include <fribidi.h>

#include "engine/core/font.h"
#include "gpu_fixture.h"
#include "labeling/text_layout.h"
#include "test_files.h"

namespace strata {

namespace {

const Font& bidi_font() {
  static const Font font(16.0f);
  return font;
}

// FriBiDi's visual order of `text` (map[visual] = logical code point index), the paragraph's
// direction taken from its first strong character.
std::vector<uint32_t> fribidi_visual_order(std::string_view text) {
  const std::u32string chars = decode_utf8(text);
  const auto n = static_cast<FriBidiStrIndex>(chars.size());
  std::vector<FriBidiChar> visual(chars.size() + 1);
  std::vector<FriBidiStrIndex> to_logical(chars.size());
  FriBidiParType base = FRIBIDI_PAR_ON;
  REQUIRE(fribidi_log2vis(reinterpret_cast<const FriBidiChar*>(chars.data()), n, &base,
                          visual.data(), nullptr, to_logical.data(), nullptr) != 0);
  return {to_logical.begin(), to_logical.end()};
}

// The clusters of a shaped line's glyphs from left to right (checking that they are in that
// order).
std::vector<uint32_t> drawn_order(const ShapedLine& line) {
  std::vector<uint32_t> clusters;
  for (size_t i = 0; i < line.glyphs.size(); ++i) {
    if (i > 0) CHECK(line.glyphs[i].pen.x >= line.glyphs[i - 1].pen.x);
    clusters.push_back(line.glyphs[i].cluster);
  }
  return clusters;
}

size_t index_of(const std::vector<uint32_t>& order, uint32_t cluster) {
  return size_t(std::find(order.begin(), order.end(), cluster) - order.begin());
}

constexpr const char* kHebrewFirst =
    "\xD7\x92\xD7\x99\xD7\x93\xD7\x95\xD7\x9C 12 mm";  // גידול 12 mm
constexpr const char* kLatinFirst =
    "Tumour \xD7\x92\xD7\x99\xD7\x93\xD7\x95\xD7\x9C";       // Tumour גידול
constexpr const char* kArabic = "\xD8\xA8\xD9\x8A\xD8\xAA";  // بيت
constexpr const char* kBrain = "\xF0\x9F\xA7\xA0";           // U+1F9E0

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("hebrew_first_label_is_drawn_right_to_left_with_its_numbers_left_to_right") {
    const ShapedLine line = bidi_font().shape(kHebrewFirst);
    CHECK(line.right_to_left);
    const std::vector<uint32_t> order = drawn_order(line);
    CHECK(order == fribidi_visual_order(kHebrewFirst));
    // "mm 12" left of the Hebrew, "12" itself left to right, the Hebrew's first letter rightmost.
    REQUIRE(order.size() == 11);
    CHECK(index_of(order, 9) < index_of(order, 6));  // "mm" before "12"
    CHECK(index_of(order, 6) < index_of(order, 7));  // "1" before "2"
    CHECK(index_of(order, 7) < index_of(order, 4));  // "12" before the Hebrew
    CHECK(order.back() == 0);                        // ג at the right end
    for (const ShapedGlyph& g : line.glyphs) CHECK(g.key.glyph != 0);
  }

  TEST_CASE("hebrew_inside_a_left_to_right_label_is_reversed_in_place") {
    const ShapedLine line = bidi_font().shape(kLatinFirst);
    CHECK_FALSE(line.right_to_left);
    const std::vector<uint32_t> order = drawn_order(line);
    CHECK(order == fribidi_visual_order(kLatinFirst));
    CHECK(order == std::vector<uint32_t>{0, 1, 2, 3, 4, 5, 6, 11, 10, 9, 8, 7});
  }

  TEST_CASE("mixed_lines_in_both_directions_match_fribidi_and_the_layout_keeps_the_order") {
    for (const char* text :
         {"abc \xD7\x90\xD7\x91 (1, 2) def", "\xD7\x90\xD7\x91 [C3] \xD7\x92 x=4",
          "CT \xD8\xA8\xD9\x8A\xD8\xAA 5 cm", "12 \xD7\x90 34", "..."}) {
      CAPTURE(text);
      CHECK(drawn_order(bidi_font().shape(text)) == fribidi_visual_order(text));
    }
    CHECK(bidi_font().shape("").glyphs.empty());
    // The layout draws the glyphs left to right as shaped, so the box holds them in that order.
    const std::vector<std::string> texts{kHebrewFirst};
    const FontAtlas atlas = bake_label_texts(bidi_font(), texts);
    const LabelTextLayout layout = layout_label_text(bidi_font(), atlas, kHebrewFirst);
    const ShapedLine line = bidi_font().shape(kHebrewFirst);
    std::vector<uint32_t> inked;  // the glyphs with ink (not the spaces)
    for (const ShapedGlyph& g : line.glyphs) {
      if (!atlas.glyph(g.key).empty()) inked.push_back(g.key.glyph);
    }
    REQUIRE(layout.glyphs.size() == inked.size());
    for (size_t i = 1; i < layout.glyphs.size(); ++i)
      CHECK(layout.glyphs[i].box.x > layout.glyphs[i - 1].box.x);
  }

  TEST_CASE("a_wrapped_right_to_left_paragraph_keeps_its_direction_on_every_line") {
    // "גידול 12 mm" wrapped after its first word: the second line, "12 mm" alone, is still
    // right-to-left (its numbers and Latin sit left to right in it, as in the whole paragraph).
    TextStyle style;
    style.max_width = bidi_font().shape("12 mm").advance + 0.5f;
    const std::vector<ShapedLine> lines = shape_label_text(bidi_font(), kHebrewFirst, style);
    REQUIRE(lines.size() == 2);
    CHECK(lines[0].right_to_left);
    CHECK(lines[1].right_to_left);
    // (in a right-to-left paragraph "12 mm" is drawn "mm 12": two left-to-right runs, right to
    // left)
    CHECK(drawn_order(lines[1]) == std::vector<uint32_t>{3, 4, 2, 0, 1});
    CHECK(paragraph_direction("12 \xD7\x90") == TextDirection::right_to_left);
    CHECK(paragraph_direction("12 a \xD7\x90") == TextDirection::left_to_right);
    CHECK(paragraph_direction("12 !") == TextDirection::left_to_right);
  }

  TEST_CASE("arabic_is_still_joined_in_either_paragraph_direction") {
    const Font& font = bidi_font();
    // Each letter of بيت alone is its isolated form; in the word, the first two join forwards.
    std::vector<uint32_t> isolated;
    for (const char* letter : {"\xD8\xA8", "\xD9\x8A", "\xD8\xAA"}) {
      const ShapedLine one = font.shape(letter);
      REQUIRE(one.glyphs.size() == 1);
      isolated.push_back(one.glyphs[0].key.glyph);
    }
    for (const std::string& text : {std::string(kArabic), "CT " + std::string(kArabic) + " 5"}) {
      CAPTURE(text);
      const ShapedLine word = font.shape(text);
      const size_t offset = text == kArabic ? 0 : 3;
      std::vector<uint32_t> joined(3);
      for (const ShapedGlyph& g : word.glyphs) {
        if (g.cluster >= offset && g.cluster < offset + 3) joined[g.cluster - offset] = g.key.glyph;
      }
      CHECK(joined[0] != isolated[0]);  // initial beh
      CHECK(joined[1] != isolated[1]);  // medial yeh
      CHECK(joined[2] != isolated[2]);  // final teh
      CHECK(drawn_order(word) == fribidi_visual_order(text));
    }
  }

  TEST_CASE("cjk_label_draws_real_glyphs_from_a_cjk_fallback_face") {
    const bool installed =
        std::any_of(std::begin(kCjkFontPaths), std::end(kCjkFontPaths),
                    [](const char* path) { return std::filesystem::is_regular_file(path); });
    REQUIRE_MESSAGE(installed, "no CJK font (scripts/setup.sh installs fonts-wqy-microhei)");
    const Font& font = bidi_font();
    const char* text = "\xE8\x82\xBF\xE7\x98\xA4 \xEB\x87\x8C";  // 肿瘤 뇌 (tumour, brain)
    const ShapedLine line = font.shape(text);
    CHECK(line.missing.empty());
    REQUIRE(line.glyphs.size() == 4);
    std::vector<GlyphKey> keys;
    for (const ShapedGlyph& g : line.glyphs) {
      CHECK(g.key.glyph != 0);
      if (g.cluster != 2) {
        CHECK(g.key.face == font.face_count() - 1);  // the CJK face, last
        keys.push_back(g.key);
      }
    }
    // Each ideograph and the hangul syllable has ink, and wide ink: an ideograph fills its em.
    const FontAtlas atlas = font.bake(keys);
    for (const GlyphKey& key : keys) {
      const GlyphMetrics g = atlas.glyph(key);
      REQUIRE_FALSE(g.empty());
      CHECK(g.quad.z - g.quad.x > 0.6f * font.pixel_height());
      uint32_t ink = 0;
      const auto x0 = uint32_t(g.uv.x * float(atlas.width)),
                 x1 = uint32_t(g.uv.z * float(atlas.width));
      const auto y0 = uint32_t(g.uv.y * float(atlas.height)),
                 y1 = uint32_t(g.uv.w * float(atlas.height));
      for (uint32_t y = y0; y < y1; ++y) {
        for (uint32_t x = x0; x < x1; ++x) {
          if (atlas.coverage[size_t(y) * atlas.width + x] > 128) ++ink;
        }
      }
      CHECK(ink > 20);
    }
  }

  TEST_CASE("a_character_no_font_has_is_named_once_per_label_in_a_warning") {
    const Font& font = bidi_font();
    REQUIRE_MESSAGE(!font.covers(U'\U0001F9E0'),
                    "a font with U+1F9E0 is installed: the test "
                    "needs a character no face has");
    std::vector<Label> labels(3);
    labels[0].id = 7;
    labels[0].text = std::string("Amygdala ") + kBrain + " " + kBrain + "\nLeft " + kBrain;
    labels[1].id = 8;
    labels[1].text = "Hippocampus \xD7\x92 \xE8\x82\xBF";  // covered: no warning
    labels[2].id = 9;
    labels[2].text = std::string("bell\x07") + kBrain;
    const ShapedLine line = font.shape(labels[0].text.substr(0, labels[0].text.find('\n')));
    CHECK(line.missing == std::vector<char32_t>{U'\U0001F9E0'});
    const std::vector<std::string> warnings = missing_glyph_warnings(font, labels);
    REQUIRE(warnings.size() == 2);
    CHECK(warnings[0] == std::string("label 7 \"Amygdala ") + kBrain + " " + kBrain +
                             "\\u000ALeft " + kBrain + "\": no font has U+1F9E0 (" + kBrain +
                             "); drawn as an empty box");
    // A control character is named, never written raw.
    CHECK(warnings[1] == std::string("label 9 \"bell\\u0007") + kBrain +
                             "\": no font has U+0007, U+1F9E0 (" + kBrain +
                             "); drawn as an empty box");
  }

  TEST_CASE("malformed_utf8_and_controls_in_a_label_shape_without_crashing") {
    const Font& font = bidi_font();
    for (const std::string& text : {std::string("\xFF\xFE\xD7"), std::string("a\0b", 3),
                                    std::string("\xE2\x80\xAE"
                                                "abc"),
                                    std::string("\xD7\x90\xE2\x80\xAB x \xE2\x80\xAC\xE2\x81\xA6"),
                                    std::string(300, '\xD7')}) {
      const ShapedLine line = font.shape(text);
      CHECK(line.advance >= 0.0f);
      for (const ShapedGlyph& g : line.glyphs) CHECK(g.cluster < decode_utf8(text).size());
    }
  }

  TEST_CASE("printable_text_escapes_controls_and_malformed_bytes_and_keeps_the_rest") {
    CHECK(printable_text("plain") == "plain");
    CHECK(printable_text(std::string("a\x07"
                                     "b\x1B[31m\0c",
                                     10)) == "a\\u0007b\\u001B[31m\\u0000c");
    CHECK(printable_text("\xC3\xA9\xD7\x90") == "\xC3\xA9\xD7\x90");  // é א
    CHECK(printable_text("x\xFFy") == "x\\xFFy");
    CHECK(printable_text("\xE2\x80\xAE"
                         "evil") == "\\u202Eevil");  // right-to-left override
    CHECK(printable_text("\xC2\x9B") == "\\u009B");  // a C1 control
    CHECK(codepoint_name(U'\U0001F9E0') == "U+1F9E0");
  }
}

TEST_SUITE("cli") {
  TEST_CASE("info_shows_label_control_characters_escaped_and_the_text_after_a_nul") {
    const std::filesystem::path folder = test::fresh_folder("cli", "label_controls");
    const std::filesystem::path scene =
        test::write_file(folder / "scene.json", R"({"strata_scene": 1, "labels": [
          {"id": 1, "text": "bell\u0007 esc\u001b[31m red nul\u0000after", "anchor": [0, 0, 0]}]})");
    const auto r = test::run_strata("info " + scene.string());
    CHECK(r.exit_code == 0);
    CHECK(r.output.find("\"bell\\u0007 esc\\u001B[31m red nul\\u0000after\"") != std::string::npos);
    CHECK(r.output.find('\x07') == std::string::npos);
    CHECK(r.output.find('\x1B') == std::string::npos);
    CHECK(r.output.find('\0') == std::string::npos);
  }

  TEST_CASE("render_warns_about_a_label_character_no_font_has") {
    const std::filesystem::path folder = test::fresh_folder("cli", "label_missing_glyph");
    const std::filesystem::path scene =
        test::write_file(folder / "scene.json", R"({"strata_scene": 1, "labels": [
          {"id": 4, "text": "Amygdala \ud83e\udde0", "anchor": [0, 0, 0]},
          {"id": 5, "text": "Tumour \u05d2\u05d9\u05d3\u05d5\u05dc", "anchor": [1, 0, 0]}]})");
    const auto r = test::run_strata("render " + scene.string() + " --size 64 -o /dev/null");
    CHECK(r.exit_code == 0);
    CHECK(r.output.find(std::string("strata: warning: label 4 \"Amygdala ") + kBrain +
                        "\": no font has U+1F9E0 (" + kBrain + "); drawn as an empty box") !=
          std::string::npos);
    CHECK(r.output.find("label 5") == std::string::npos);
  }
}

}  // namespace strata
