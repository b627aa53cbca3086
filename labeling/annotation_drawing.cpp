#include "labeling/annotation_drawing.h"

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"
#include "shared/label_drawing.h"

namespace strata {
namespace {

// The picture as premultiplied floats, and back.
struct Canvas {
  std::span<uint8_t> rgba;
  glm::uvec2 size;

  // `colour` (premultiplied) over pixel (x, y).
  void over(int x, int y, glm::vec4 colour) const {
    if (x < 0 || y < 0 || x >= int(size.x) || y >= int(size.y) || colour.a <= 0.0f) return;
    uint8_t* p = &rgba[(size_t(y) * size.x + size_t(x)) * 4];
    const float a = float(p[3]) / 255.0f;
    const glm::vec4 back(glm::vec3(p[0], p[1], p[2]) / 255.0f * a, a);
    const glm::vec4 out = colour + (1.0f - colour.a) * back;
    const glm::vec3 straight = out.a > 0.0f ? glm::vec3(out) / out.a : glm::vec3(0.0f);
    for (int c = 0; c < 3; ++c)
      p[c] = uint8_t(std::lround(std::clamp(straight[c], 0.0f, 1.0f) * 255.0f));
    p[3] = uint8_t(std::lround(std::clamp(out.a, 0.0f, 1.0f) * 255.0f));
  }
};

glm::vec4 premultiplied(glm::vec4 straight, float coverage) {
  const float a = straight.a * std::clamp(coverage, 0.0f, 1.0f);
  return {glm::vec3(straight) * a, a};
}

glm::vec4 glm_of(gpu::vec4 c) {
  return {c.x, c.y, c.z, c.w};
}

// A box drawn as a label's box without a connector: fill, border and rounded corners.
void draw_box(const Canvas& canvas, glm::vec4 rect) {
  const glm::vec2 lo(rect.x, rect.y), hi(rect.z, rect.w);
  const glm::vec2 centre = 0.5f * (lo + hi), size = hi - lo;
  for (int y = int(std::floor(lo.y)) - 1; y <= int(std::ceil(hi.y)); ++y) {
    for (int x = int(std::floor(lo.x)) - 1; x <= int(std::ceil(hi.x)); ++x) {
      const glm::vec2 p = glm::vec2(x, y) + 0.5f;
      const gpu::vec4 c =
          gpu::label_frame(p, centre, centre, size, false, gpu::LABEL_BORDER_COLOR, 0.0f, false);
      canvas.over(x, y, glm_of(c));
    }
  }
}

// A colour square with a one-pixel rim of the border colour (it reads on the dark fill).
void draw_swatch(const Canvas& canvas, glm::vec4 rect, glm::vec3 colour) {
  const glm::vec4 rim = premultiplied(glm_of(gpu::LABEL_BORDER_COLOR), 1.0f);
  for (int y = int(rect.y); y < int(rect.w); ++y) {
    for (int x = int(rect.x); x < int(rect.z); ++x) {
      const bool edge =
          x == int(rect.x) || y == int(rect.y) || x + 1 == int(rect.z) || y + 1 == int(rect.w);
      canvas.over(x, y, edge ? rim : glm::vec4(colour, 1.0f));
    }
  }
}

float coverage_at(const FontAtlas& atlas, glm::vec2 texel) {
  const glm::ivec2 t = glm::clamp(glm::ivec2(glm::floor(texel)), glm::ivec2(0),
                                  glm::ivec2(atlas.width - 1, atlas.height - 1));
  return float(atlas.coverage[size_t(t.y) * atlas.width + size_t(t.x)]) / 255.0f;
}

// A text run's glyphs, each quad on whole pixels as the label text is (its texels on the
// pixels), in the run's colour.
void draw_text(const Canvas& canvas, const Font& font, const TextRun& run) {
  const ShapedLine line = font.shape(run.text);
  std::vector<GlyphKey> keys;
  for (const ShapedGlyph& g : line.glyphs) keys.push_back(g.key);
  const FontAtlas atlas = font.bake(keys);
  const glm::vec2 texels(atlas.width, atlas.height);
  for (const ShapedGlyph& shaped : line.glyphs) {
    const GlyphMetrics g = atlas.glyph(shaped.key);
    if (g.empty()) continue;
    const glm::vec2 origin = run.origin + glm::round(shaped.pen);
    const glm::vec2 lo = origin + glm::vec2(g.quad.x, g.quad.y);
    const glm::vec2 hi = origin + glm::vec2(g.quad.z, g.quad.w);
    const glm::vec2 uv_lo = glm::vec2(g.uv.x, g.uv.y) * texels;
    const glm::vec2 uv_hi = glm::vec2(g.uv.z, g.uv.w) * texels;
    for (int y = int(std::floor(lo.y)); y < int(std::ceil(hi.y)); ++y) {
      for (int x = int(std::floor(lo.x)); x < int(std::ceil(hi.x)); ++x) {
        const glm::vec2 q = (glm::vec2(x, y) + 0.5f - lo) / (hi - lo);
        const float c = coverage_at(atlas, glm::mix(uv_lo, uv_hi, q));
        canvas.over(x, y, premultiplied(run.colour, c));
      }
    }
  }
}

}  // namespace

void draw_annotations(std::span<uint8_t> rgba, glm::uvec2 size, const AnnotationLayout& layout,
                      const AnnotationFonts& fonts) {
  if (rgba.size() != size_t(size.x) * size.y * 4) {
    throw Error("annotations: a picture of " + std::to_string(rgba.size()) + " bytes for " +
                std::to_string(size.x) + "x" + std::to_string(size.y));
  }
  const Canvas canvas{rgba, size};
  if (layout.title) {
    draw_box(canvas, layout.title->box.rect);
    draw_text(canvas, fonts.title, layout.title->text);
  }
  if (layout.legend) {
    draw_box(canvas, layout.legend->box.rect);
    for (const LegendRow& row : layout.legend->rows) {
      if (row.swatch) draw_swatch(canvas, *row.swatch, row.colour);
      draw_text(canvas, fonts.text, row.text);
    }
  }
}

}  // namespace strata
