// Label text through the font (engine/core/font.cpp): UTF-8 decoding (malformed bytes become
// U+FFFD), the bidirectional algorithm (GNU FriBiDi), the runs shaped by HarfBuzz with the
// fallback faces, and the glyphs baked into an atlas; and printable_text, which `strata info`
// prints label texts with. The first byte picks the paragraph direction (automatic, left-to-right,
// right-to-left); the rest is the text, split into lines at "\n" as labels are.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string_view>
#include <vector>

#include "engine/core/font.h"
#include "fuzz/fuzz_input.h"

namespace {

void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz: %s\n", what);
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const strata::Font font(12.0f);
  if (size == 0) return 0;
  const auto direction = static_cast<strata::TextDirection>(data[0] % 3);
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  strata::fuzz::expect_only_errors([&] {
    const std::string shown = strata::printable_text(text);
    for (const char c : shown) check(static_cast<unsigned char>(c) >= 0x20, "a control printed");
    std::vector<strata::GlyphKey> keys;
    size_t start = 0;
    while (start <= text.size()) {
      const size_t end = std::min(text.find('\n', start), text.size());
      const std::string_view line = text.substr(start, end - start);
      const auto chosen = direction == strata::TextDirection::automatic
                              ? strata::paragraph_direction(line)
                              : direction;
      const strata::ShapedLine shaped = font.shape(line, chosen);
      const size_t characters = strata::decode_utf8(line).size();
      check(std::isfinite(shaped.advance), "a line's advance is not finite");
      check(shaped.right_to_left == (chosen == strata::TextDirection::right_to_left),
            "the line's direction is not the paragraph's");
      for (const strata::ShapedGlyph& g : shaped.glyphs) {
        check(g.cluster < characters, "a glyph's cluster past the line's characters");
        check(g.key.face < font.face_count(), "a glyph of no face");
        keys.push_back(g.key);
      }
      start = end + 1;
    }
    const strata::FontAtlas atlas = font.bake(keys);
    check(atlas.coverage.size() == size_t(atlas.width) * atlas.height,
          "an atlas of the wrong size");
  });
  return 0;
}
