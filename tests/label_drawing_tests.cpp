// The font atlas, text layout, and the label drawing and compositing passes against their CPU
// reference (passes/label_drawing.h), which runs the shaders' own shape and loop code.
//
// Tolerance: 2/255 per channel, in the layers and in the final image. Both sides evaluate the same
// expressions in float, but the GPU may contract multiply-adds and has its own sqrt and division;
// its bilinear filter weights are fixed-point (8 bits of sub-texel position on lavapipe); and it
// rounds to half (layers) and to 8 bits (final) its own way. Every shape edge is a one-pixel
// ramp, so none of these moves a pixel by more than a fraction of a step.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include <ft2build.h>
#include FT_FREETYPE_H
#include <glm/gtc/packing.hpp>
#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "engine/core/font.h"
#include "engine/core/image_atlas.h"
#include "engine/core/png.h"
#include "engine/gpu/resources.h"
#include "engine/graph/graph_runner.h"
#include "frame/labelled_render.h"
#include "gpu_fixture.h"
#include "labeling/text_layout.h"
#include "passes/label_drawing.h"
#include "test_scenes.h"

namespace strata {
namespace {

constexpr float kTolerance = 2.0f / 255.0f;

const Font& test_font() {
  static const Font font(14.0f);
  return font;
}

// Every printable ASCII character's glyph, and those of the texts the tests draw.
const FontAtlas& test_atlas() {
  static const FontAtlas atlas = [] {
    std::string ascii;
    for (char c = 32; c < 127; ++c) ascii.push_back(c);
    const std::vector<std::string> texts = {ascii};
    return bake_label_texts(test_font(), texts);
  }();
  return atlas;
}

std::vector<gpu::GlyphGpu> test_glyphs(std::span<const std::string> texts,
                                       std::span<gpu::LabelGpu> labels) {
  return build_glyph_buffer(test_font(), test_atlas(), texts, labels);
}

// Layers, labels with their placements, and what the composite puts behind them.
struct LabelScene {
  graph::Extent size{112, 96};
  uint32_t layer_count = 3;
  std::vector<glm::vec4> layers;  // layer after layer, premultiplied, half-representable
  std::vector<gpu::LabelGpu> labels;
  std::vector<gpu::PlacementGpu> placements;
  std::vector<gpu::GlyphGpu> glyphs;
  Background background{{0.2f, 0.25f, 0.3f}};
  bool layer_frames = false;
  ImageAtlas images;    // the labels' pictures (none: one transparent texel)
  GhostSettings ghost;  // (off)
  // The renderer's depth image (empty: nothing opaque anywhere) and what of its frame the anchors'
  // cover reads: the layers' splits, the near plane, the ray step and depth_alpha.
  std::vector<float> depth;
  gpu::FrameGpu frame = test_frame();

  static gpu::FrameGpu test_frame() {
    gpu::FrameGpu f{};
    f.near_depth = 1.0f;
    f.far_depth = 100.0f;
    f.step = 0.5f;
    f.depth_alpha = 0.5f;
    return f;
  }
  size_t pixels() const { return size_t{size.width} * size.height; }
  std::vector<float> depth_image() const {
    return depth.empty() ? std::vector<float>(pixels(), 0.0f) : depth;
  }
  glm::vec4& at(uint32_t layer, uint32_t x, uint32_t y) {
    return layers[layer * pixels() + size_t{y} * size.width + x];
  }
};

glm::vec4 to_half_precision(glm::vec4 c) {
  return glm::unpackHalf4x16(glm::packHalf4x16(c));
}

gpu::LabelGpu label_on(uint32_t layer, glm::vec2 anchor, uint32_t flags = LABEL_ENABLED) {
  gpu::LabelGpu label{};
  label.anchor = anchor;
  label.layer = layer;
  label.flags = flags;
  return label;
}

// Three layers: a semi-transparent blue rectangle in front (over the rear label's box), a soft
// green ramp in the middle, an opaque grey ramp at the back. Four labels: an external one on each
// of the rear and middle layers (the middle one at a half-pixel position, so its text is filtered
// between texels), an internal one in front, and a hidden one.
LabelScene make_scene() {
  LabelScene s;
  s.layers.assign(s.layer_count * s.pixels(), glm::vec4(0.0f));
  for (uint32_t y = 0; y < s.size.height; ++y) {
    for (uint32_t x = 0; x < s.size.width; ++x) {
      if (x < 64 && y < 44) s.at(0, x, y) = glm::vec4(0.06f, 0.06f, 0.3f, 0.6f);
      const float ramp = float(x) / float(s.size.width);
      s.at(1, x, y) = glm::vec4(0.0f, 0.3f, 0.1f, 0.4f) * ramp;
      s.at(2, x, y) = glm::vec4(glm::vec3(0.3f + 0.4f * float(y) / float(s.size.height)), 1.0f);
    }
  }
  for (glm::vec4& c : s.layers) c = to_half_precision(c);
  s.labels = {label_on(2, {22.0f, 66.0f}), label_on(1, {92.0f, 78.0f}),
              label_on(0, {56.0f, 84.0f}, LABEL_ENABLED | LABEL_INTERNAL),
              label_on(0, {90.0f, 12.0f})};
  s.placements = {{{34.0f, 22.0f}, 0.0f, PLACEMENT_SHOWN},
                  {{74.5f, 52.5f}, 0.0f, PLACEMENT_SHOWN},
                  {{0.0f, 0.0f}, 0.0f, PLACEMENT_SHOWN},
                  {{88.0f, 30.0f}, 0.0f, PLACEMENT_HIDDEN}};
  const std::vector<std::string> texts = {"Cortex", "Ventricle", "Pons", "Hidden"};
  s.glyphs = test_glyphs(texts, s.labels);
  return s;
}

struct DrawnLabels {
  std::vector<glm::vec4> layers;
  std::vector<uint8_t> final;
  std::vector<gpu::AnchorCoverGpu> covers;  // labels.anchor_cover: per label, after the ghosting
};

Buffer storage_buffer(Context& ctx, std::span<const std::byte> bytes) {
  // A buffer is never empty (a label list without glyphs still binds one).
  Buffer buffer(ctx, std::max<VkDeviceSize>(bytes.size(), 16), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                MemoryKind::device_local);
  if (!bytes.empty()) upload(ctx, buffer, bytes);
  return buffer;
}

Image layer_image(Context& ctx, const LabelScene& s) {
  Image image(ctx, {VK_FORMAT_R16G16B16A16_SFLOAT,
                    {s.size.width, s.size.height, 1},
                    VK_IMAGE_TYPE_2D,
                    VK_IMAGE_USAGE_STORAGE_BIT,
                    s.layer_count,
                    true});
  std::vector<uint64_t> halves;
  for (const glm::vec4& c : s.layers) halves.push_back(glm::packHalf4x16(c));
  upload(ctx, image, as_bytes(halves), VK_IMAGE_LAYOUT_GENERAL);
  return image;
}

Image depth_image(Context& ctx, const LabelScene& s) {
  Image image(ctx, {VK_FORMAT_R32_SFLOAT,
                    {s.size.width, s.size.height, 1},
                    VK_IMAGE_TYPE_2D,
                    VK_IMAGE_USAGE_STORAGE_BIT});
  upload(ctx, image, as_bytes(s.depth_image()), VK_IMAGE_LAYOUT_GENERAL);
  return image;
}

Buffer frame_buffer(Context& ctx, const LabelScene& s) {
  Buffer buffer(ctx, sizeof(gpu::FrameGpu), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                MemoryKind::device_local);
  upload(ctx, buffer, as_bytes(std::span(&s.frame, 1)));
  return buffer;
}

DrawnLabels draw_on_gpu(Context& ctx, const LabelScene& s) {
  const Image layers = layer_image(ctx, s);
  const Image depth = depth_image(ctx, s);
  const Buffer frame = frame_buffer(ctx, s);
  const Buffer labels = storage_buffer(ctx, as_bytes(s.labels));
  const Buffer placements = storage_buffer(ctx, as_bytes(s.placements));
  const Buffer glyphs = storage_buffer(ctx, as_bytes(s.glyphs));
  LabelDrawing drawing(ctx, test_atlas(), s.images);
  drawing.set_label_count(static_cast<uint32_t>(s.labels.size()));
  drawing.set_layer_frames(s.layer_frames);
  drawing.set_ghost(s.ghost);

  graph::Graph g;
  const auto filled = [&g](const char* name, const Buffer& buffer) {
    return g.import_buffer(name, {.buffer = buffer.handle(), .has_content = true});
  };
  const auto layers_id = g.import_image("layers", {.image = layers.handle(),
                                                   .view = layers.view(),
                                                   .format = layers.desc().format,
                                                   .has_content = true,
                                                   .initial_layout = VK_IMAGE_LAYOUT_GENERAL,
                                                   .final_use = graph::Use::transfer_src});
  const auto final_id = g.add_image("final", {VK_FORMAT_R8G8B8A8_UNORM});
  const size_t label_count = std::max<size_t>(s.labels.size(), 1);
  const auto covers_id = g.add_buffer("covers", {[label_count](graph::Extent) {
                                        return label_count * sizeof(gpu::AnchorCoverGpu);
                                      }});
  const auto depth_id = g.import_image("depth", {.image = depth.handle(),
                                                 .view = depth.view(),
                                                 .format = VK_FORMAT_R32_SFLOAT,
                                                 .has_content = true,
                                                 .initial_layout = VK_IMAGE_LAYOUT_GENERAL});
  drawing.add_to(
      g, {.layers = layers_id,
          .layer_count = s.layer_count,
          .labels = filled("labels", labels),
          .placements = filled("placements", placements),
          .glyphs = filled("glyphs", glyphs),
          .output = final_id,
          .background = s.background,
          .ghost = s.ghost.strength > 0.0f,
          .depth = depth_id,
          .frame = g.import_buffer("frame", {.buffer = frame.handle(), .has_content = true}),
          .covers = covers_id});
  graph::GraphRunner runner(ctx, std::move(g));
  runner.set_viewport(s.size);
  runner.run_now();

  DrawnLabels out;
  const std::vector<std::byte> final_bytes = runner.download_image(final_id);
  out.final.resize(final_bytes.size());
  std::memcpy(out.final.data(), final_bytes.data(), final_bytes.size());
  const std::vector<std::byte> cover_bytes = runner.download_buffer(covers_id);
  out.covers.resize(s.labels.size());
  std::memcpy(out.covers.data(), cover_bytes.data(),
              out.covers.size() * sizeof(gpu::AnchorCoverGpu));
  const std::vector<std::byte> layer_bytes =
      download(ctx, layers, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  std::vector<uint64_t> halves(layer_bytes.size() / sizeof(uint64_t));
  std::memcpy(halves.data(), layer_bytes.data(), halves.size() * sizeof(uint64_t));
  for (const uint64_t h : halves) out.layers.push_back(glm::unpackHalf4x16(h));
  return out;
}

// What hides each anchor, measured on the layers ghosted (when the scene asks for it).
std::vector<gpu::AnchorCoverGpu> reference_covers(const LabelScene& s) {
  const std::vector<glm::vec4> ghosted =
      ghost_reference(s.layers, s.size, s.layer_count, {s.labels, s.placements, s.glyphs}, s.ghost);
  return anchor_cover_reference(ghosted, s.depth_image(), s.size, s.layer_count, s.frame, s.labels);
}

// The layers ghosted (when the scene asks for it), then the labels drawn.
std::vector<glm::vec4> reference_layers(const LabelScene& s) {
  const std::vector<gpu::AnchorCoverGpu> covers = reference_covers(s);
  const LabelDrawData data{s.labels,       s.placements, s.glyphs,
                           s.layer_frames, covers,       connector_halos(s.background)};
  const std::vector<glm::vec4> ghosted =
      ghost_reference(s.layers, s.size, s.layer_count, data, s.ghost);
  return draw_labels_reference(ghosted, s.size, s.layer_count, data, test_atlas(), s.images);
}

// The final image as the reference composites the reference's layers.
std::vector<uint8_t> reference_final(const LabelScene& s) {
  const std::vector<gpu::AnchorCoverGpu> covers = reference_covers(s);
  return composite_reference(reference_layers(s), s.size, s.layer_count, s.background,
                             {s.labels, s.placements, s.glyphs, false, covers});
}

// The largest difference per channel, and where it is.
float worst_difference(std::span<const glm::vec4> a, std::span<const glm::vec4> b, size_t& where) {
  float worst = 0.0f;
  for (size_t i = 0; i < a.size(); ++i) {
    const glm::vec4 e = glm::abs(a[i] - b[i]);
    const float d = std::max(std::max(e.x, e.y), std::max(e.z, e.w));
    if (d > worst) where = i;
    worst = std::max(worst, d);
  }
  return worst;
}

int worst_difference(std::span<const uint8_t> a, std::span<const uint8_t> b) {
  int worst = 0;
  for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(int(a[i]) - int(b[i])));
  return worst;
}

glm::vec4 final_pixel(const LabelScene& s, const std::vector<uint8_t>& final, glm::uvec2 p) {
  const size_t i = 4 * (size_t{p.y} * s.size.width + p.x);
  return glm::vec4(final[i], final[i + 1], final[i + 2], final[i + 3]) / 255.0f;
}

// The pixel of `layer` inside label i's box where the drawn layer is brightest (its text).
glm::uvec2 brightest_text_pixel(const LabelScene& s, const std::vector<glm::vec4>& drawn,
                                size_t i) {
  const gpu::LabelGpu& label = s.labels[i];
  const bool inner = (label.flags & LABEL_INTERNAL) != 0;
  const glm::vec2 centre = inner ? label.anchor : s.placements[i].position;
  const glm::uvec2 lo(centre - 0.5f * label.size), hi(centre + 0.5f * label.size);
  glm::uvec2 best = lo;
  float brightest = -1.0f;
  for (uint32_t y = lo.y; y < hi.y; ++y) {
    for (uint32_t x = lo.x; x < hi.x; ++x) {
      const float r = drawn[label.layer * s.pixels() + size_t{y} * s.size.width + x].r;
      if (r > brightest) best = {x, y};
      brightest = std::max(brightest, r);
    }
  }
  return best;
}

// Four flat quadrants, 32x32 texels, opaque: red, green / blue, yellow.
const std::array<glm::vec4, 4> kQuadrants = {
    glm::vec4(0.86f, 0.12f, 0.12f, 1.0f), glm::vec4(0.12f, 0.78f, 0.16f, 1.0f),
    glm::vec4(0.16f, 0.24f, 0.82f, 1.0f), glm::vec4(0.9f, 0.86f, 0.16f, 1.0f)};

Rgba8Image quadrant_picture(uint32_t width = 32, uint32_t height = 32) {
  Rgba8Image image{width, height, std::vector<uint8_t>(size_t{width} * height * 4)};
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      const glm::vec4 c = kQuadrants[(2 * y / height) * 2 + 2 * x / width];
      for (uint32_t k = 0; k < 4; ++k)
        image.pixels[(size_t{y} * width + x) * 4 + k] = uint8_t(std::lround(c[int(k)] * 255.0f));
    }
  }
  return image;
}

Label picture_label(float height, LabelImage::Side side, uint32_t width = 32) {
  Label label;
  label.image = LabelImage{"quadrants.png", quadrant_picture(width), height, side};
  return label;
}

// The pixel centre at the middle of quadrant q of label i's picture, as drawn.
glm::uvec2 quadrant_pixel(const LabelScene& s, size_t i, int q) {
  const gpu::LabelGpu& label = s.labels[i];
  const glm::vec4 box = s.glyphs[label.glyph_first + label.glyph_count].box;
  const glm::vec2 top_left = s.placements[i].position - 0.5f * label.size;
  const glm::vec2 f(q % 2 ? 0.75f : 0.25f, q / 2 ? 0.75f : 0.25f);
  return glm::uvec2(top_left + glm::mix(glm::vec2(box), glm::vec2(box.z, box.w), f));
}

// The scene drawn on the GPU, its layers and final image checked against the reference.
DrawnLabels draw_matching_the_reference(Context& ctx, const LabelScene& s) {
  DrawnLabels gpu = draw_on_gpu(ctx, s);
  const std::vector<glm::vec4> expected = reference_layers(s);
  REQUIRE(gpu.layers.size() == expected.size());
  size_t where = 0;
  const float worst = worst_difference(gpu.layers, expected, where);
  CHECK_MESSAGE(worst <= kTolerance,
                "layer pixel " << where << " differs by " << worst * 255.0f << "/255");
  CHECK(worst_difference(gpu.final, reference_final(s)) <= 2);
  // What hides each anchor, read between the ghosting and the drawing.
  const std::vector<gpu::AnchorCoverGpu> covers = reference_covers(s);
  REQUIRE(gpu.covers.size() == covers.size());
  for (size_t i = 0; i < covers.size(); ++i) {
    CAPTURE(i);
    CHECK(gpu.covers[i].front_alpha == doctest::Approx(covers[i].front_alpha).epsilon(1e-4));
    CHECK(gpu.covers[i].hidden == doctest::Approx(covers[i].hidden).epsilon(1e-4));
  }
  return gpu;
}

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("font_bakes_coverage_for_letters_and_none_for_space") {
    const Font& font = test_font();
    const ShapedLine line = font.shape("A A");
    REQUIRE(line.glyphs.size() == 3);
    const FontAtlas atlas =
        font.bake(std::vector<GlyphKey>{line.glyphs[0].key, line.glyphs[1].key});
    REQUIRE(atlas.coverage.size() == size_t{atlas.width} * atlas.height);
    const GlyphMetrics a = atlas.glyph(line.glyphs[0].key);
    REQUIRE_FALSE(a.empty());
    const glm::uvec4 texels(
        glm::round(a.uv * glm::vec4(atlas.width, atlas.height, atlas.width, atlas.height)));
    int ink = 0;
    for (uint32_t y = texels.y; y < texels.w; ++y) {
      for (uint32_t x = texels.x; x < texels.z; ++x)
        ink = std::max(ink, int(atlas.coverage[size_t{y} * atlas.width + x]));
    }
    CHECK(ink > 200);                                // small glyphs rarely cover a texel fully
    CHECK(atlas.glyph(line.glyphs[1].key).empty());  // the space has no ink ...
    CHECK(line.glyphs[2].pen.x > line.glyphs[1].pen.x + 2.0f);  // ... but an advance
    CHECK(font.ascent() > 0.0f);
    CHECK(font.descent() < 0.0f);
    CHECK(font.line_height() == doctest::Approx(14.0f));
    CHECK(font.line_spacing() >= font.line_height());
  }

  TEST_CASE("font_missing_file_names_the_path_and_the_debian_package") {
    const std::string path = "/nonexistent/fonts/NoSuchFont.ttf";
    try {
      (void)Font(14.0f, path);
      FAIL("no error for a missing font");
    } catch (const Error& e) {
      const std::string message = e.what();
      CHECK(message.find(path) != std::string::npos);
      CHECK(message.find("fonts-dejavu-core") != std::string::npos);
    }
    CHECK_THROWS_AS(Font(14.0f, STRATA_SOURCE_DIR "/README.md"), Error);  // not a font
    CHECK_THROWS_AS(Font(2.0f), Error);
  }

  TEST_CASE("utf8_is_decoded_and_malformed_bytes_become_one_replacement_each") {
    CHECK(decode_utf8("Gyrus") == U"Gyrus");
    CHECK(decode_utf8("pr\xC3\xA9"
                      "central \xE2\x80\x93 \xCE\x98") == U"précentral – Θ");
    CHECK(decode_utf8("\x80x") == U"\uFFFDx");        // a stray continuation byte
    CHECK(decode_utf8("\xC3") == U"\uFFFD");          // truncated
    CHECK(decode_utf8("\xC0\xAF") == U"\uFFFD");      // overlong
    CHECK(decode_utf8("\xED\xA0\x80") == U"\uFFFD");  // a surrogate
    CHECK(decode_utf8("\xF0\x9F\x98\x80") == U"\U0001F600");
  }

  TEST_CASE("shaping_kerns_composes_accents_and_falls_back_for_missing_characters") {
    const Font& font = test_font();
    // DejaVu Sans kerns "AV": closer than the two letters' own advances.
    const float a = font.shape("A").advance, v = font.shape("V").advance;
    CHECK(font.shape("AV").advance < a + v - 0.5f);
    // A precomposed accent is one glyph of the main face; a base letter with a combining accent
    // is positioned by the font (the mark sits over the base, not after it).
    const ShapedLine e = font.shape("\xC3\xA9");
    REQUIRE(e.glyphs.size() == 1);
    CHECK(e.glyphs[0].key.face == 0);
    CHECK(e.glyphs[0].key.glyph != 0);
    const ShapedLine combining = font.shape("e\xCC\x81");
    REQUIRE(combining.glyphs.size() >= 1);
    CHECK(combining.advance == doctest::Approx(font.shape("e").advance));
    // Greek is in the main face.
    for (const ShapedGlyph& g :
         font.shape("\xCE\x98\xCE\xAC\xCE\xBB\xCE\xB1\xCE\xBC\xCE\xBF\xCF\x82").glyphs) {
      CHECK(g.key.face == 0);
      CHECK(g.key.glyph != 0);
    }
    // Devanagari is not in DejaVu Sans: it comes from a fallback face.
    REQUIRE(font.face_count() > 1);
    const ShapedLine fallback = font.shape("\xE0\xA4\x95");  // U+0915
    REQUIRE_FALSE(fallback.glyphs.empty());
    CHECK(fallback.glyphs[0].key.face > 0);
    CHECK(fallback.glyphs[0].key.glyph != 0);
  }

  TEST_CASE("text_layout_gives_a_longer_text_a_wider_box_and_each_line_its_own_row") {
    const Font& font = test_font();
    const FontAtlas& atlas = test_atlas();
    const LabelTextLayout short_text = layout_label_text(font, atlas, "Pons");
    const LabelTextLayout long_text = layout_label_text(font, atlas, "Pons and medulla");
    CHECK(long_text.size.x > short_text.size.x + 40.0f);
    CHECK(long_text.size.y == short_text.size.y);
    CHECK(short_text.size.y >= font.line_height());
    CHECK(layout_label_text(font, atlas, "i").size.x == TextStyle{}.min_width);
    CHECK(layout_label_text(font, atlas, "").glyphs.empty());
    // A given size is kept as a minimum.
    CHECK(layout_label_text(font, atlas, "Pons", {}, {200.0f, 40.0f}).size ==
          glm::vec2(200.0f, 40.0f));
    // "\n" starts a line: the box grows by one line spacing and narrows to the wider line.
    const LabelTextLayout two = layout_label_text(font, atlas, "Pons and\nmedulla");
    CHECK(two.lines == 2);
    CHECK(two.size.y == short_text.size.y + std::round(font.line_spacing()));
    CHECK(two.size.x < long_text.size.x);
    // Wrapping at a width: at spaces, never inside a word.
    TextStyle narrow;
    narrow.max_width = 60.0f;
    const std::vector<ShapedLine> wrapped = shape_label_text(font, "Pons and medulla", narrow);
    CHECK(wrapped.size() == 2);
    for (const ShapedLine& line : wrapped) CHECK(line.advance <= 60.0f);
    CHECK(shape_label_text(font, "Parahippocampal", narrow).size() == 1);  // one long word
    // The label scale scales the box.
    const LabelTextLayout big = layout_label_text(
        Font(28.0f), bake_label_texts(Font(28.0f), std::vector<std::string>{"Pons"}), "Pons",
        TextStyle{}.scaled(2.0f));
    CHECK(big.size.x == doctest::Approx(2.0f * short_text.size.x).epsilon(0.1));
    CHECK(big.size.y == doctest::Approx(2.0f * short_text.size.y).epsilon(0.1));
  }

  // Accents, a dash, Greek and a line break, against FreeType's own rendering of the same string
  // (character by character with its kerning): the same glyphs, the same ink, at the same places
  // (within a pixel: HarfBuzz and FreeType round advances differently).
  TEST_CASE("utf8_label_text_matches_a_freetype_rendering_of_the_same_string") {
    const std::string text =
        "Pr\xC3\xA9"
        "central \xE2\x80\x93\n\xCE\x98\xCE\xAC\xCE\xBB\xCE\xB1\xCE\xBC\xCE\xBF\xCF\x82";
    const Font& font = test_font();
    const FontAtlas atlas = bake_label_texts(font, std::vector<std::string>{text});
    const LabelTextLayout layout = layout_label_text(font, atlas, text);
    REQUIRE(layout.lines == 2);

    FT_Library library = nullptr;
    REQUIRE(FT_Init_FreeType(&library) == 0);
    FT_Face face = nullptr;
    REQUIRE(FT_New_Face(library, font_file().c_str(), 0, &face) == 0);
    const float em = 14.0f * float(face->units_per_EM) / float(face->ascender - face->descender);
    FT_Set_Char_Size(face, 0, FT_F26Dot6(std::lround(em * 64.0f)), 72, 72);
    struct Ink {
      float left = 0.0f;
      int line = 0;
      std::vector<uint8_t> pixels;
      int width = 0, rows = 0;
    };
    std::vector<Ink> reference;
    int line = 0;
    for (const std::u32string& characters :
         {decode_utf8("Pr\xC3\xA9"
                      "central \xE2\x80\x93"),
          decode_utf8("\xCE\x98\xCE\xAC\xCE\xBB\xCE\xB1\xCE\xBC\xCE\xBF\xCF\x82")}) {
      float pen = 0.0f;
      FT_UInt previous = 0;
      for (const char32_t c : characters) {
        const FT_UInt index = FT_Get_Char_Index(face, c);
        REQUIRE(index != 0);
        FT_Vector kern{0, 0};
        if (previous != 0) FT_Get_Kerning(face, previous, index, FT_KERNING_UNFITTED, &kern);
        pen += float(kern.x) / 64.0f;
        REQUIRE(FT_Load_Glyph(face, index, FT_LOAD_TARGET_LIGHT | FT_LOAD_RENDER) == 0);
        const FT_Bitmap& b = face->glyph->bitmap;
        if (b.width > 0 && b.rows > 0) {
          Ink ink{pen + float(face->glyph->bitmap_left), line, {}, int(b.width), int(b.rows)};
          for (unsigned r = 0; r < b.rows; ++r) {
            const unsigned char* row = b.buffer + std::ptrdiff_t(r) * b.pitch;
            ink.pixels.insert(ink.pixels.end(), row, row + b.width);
          }
          reference.push_back(std::move(ink));
        }
        pen += float(face->glyph->linearHoriAdvance) / 65536.0f;
        previous = index;
      }
      ++line;
    }
    FT_Done_Face(face);
    FT_Done_FreeType(library);

    // Ours: each glyph's quad (one texel of border around the ink) and its atlas texels.
    REQUIRE(layout.glyphs.size() == reference.size());
    float line_start[2] = {0.0f, 0.0f};
    for (size_t i = 0; i < reference.size(); ++i) {
      CAPTURE(i);
      const gpu::GlyphGpu& g = layout.glyphs[i];
      const int width = int(std::lround(g.box.z - g.box.x)) - 2;
      const int rows = int(std::lround(g.box.w - g.box.y)) - 2;
      CHECK(width == reference[i].width);
      CHECK(rows == reference[i].rows);
      const int ax = int(std::lround(g.atlas.x * float(atlas.width))) + 1;
      const int ay = int(std::lround(g.atlas.y * float(atlas.height))) + 1;
      int differing = 0;
      for (int r = 0; r < std::min(rows, reference[i].rows); ++r) {
        for (int c = 0; c < std::min(width, reference[i].width); ++c) {
          const int ours = atlas.coverage[size_t(ay + r) * atlas.width + size_t(ax + c)];
          const int theirs =
              reference[i].pixels[size_t(r) * size_t(reference[i].width) + size_t(c)];
          if (ours != theirs) ++differing;
        }
      }
      CHECK(differing == 0);
      // Place: relative to its line's first glyph, within a pixel of FreeType's pen.
      const int l = reference[i].line;
      if (i == 0 || reference[i - 1].line != l) line_start[l] = g.box.x + 1.0f - reference[i].left;
      CHECK(std::abs(g.box.x + 1.0f - line_start[l] - reference[i].left) <= 1.0f);
    }
    // The second line lies one line spacing below the first.
    CHECK(layout.glyphs.back().box.w > layout.glyphs[0].box.w + font.line_spacing() - 8.0f);
  }

  TEST_CASE("text_layout_glyph_boxes_lie_in_the_label_box_in_reading_order") {
    const Font& font = test_font();
    const FontAtlas& atlas = test_atlas();
    const LabelTextLayout layout = layout_label_text(font, atlas, "Thalamus");
    REQUIRE(layout.glyphs.size() == 8);
    for (size_t i = 0; i < layout.glyphs.size(); ++i) {
      const glm::vec4 box = layout.glyphs[i].box;
      const glm::vec4 uv = layout.glyphs[i].atlas;
      CHECK(box.x >= 0.0f);
      CHECK(box.y >= 0.0f);
      CHECK(box.z <= layout.size.x);
      CHECK(box.w <= layout.size.y);
      // One pixel per texel: the quad is the glyph's atlas rectangle, unscaled.
      CHECK((box.z - box.x) == doctest::Approx((uv.z - uv.x) * float(atlas.width)));
      CHECK((box.w - box.y) == doctest::Approx((uv.w - uv.y) * float(atlas.height)));
      if (i > 0) CHECK(box.x > layout.glyphs[i - 1].box.x);
    }
  }

  // The box holds the picture above the text (centred across the box) or left of it (centred
  // down the box), with the text's padding around it; the text moves out of its way.
  TEST_CASE("text_layout_holds_a_picture_above_or_left_of_the_text") {
    const Font& font = test_font();
    const FontAtlas& atlas = test_atlas();
    const TextStyle style;
    const LabelTextLayout text = layout_label_text(font, atlas, "Pons");
    const LabelImageBlock picture{{40.0f, 24.0f}, false, {0.1f, 0.2f, 0.3f, 0.4f}};
    const LabelTextLayout above = layout_label_text(font, atlas, "Pons", style, {}, picture);
    CHECK(above.size ==
          glm::vec2(40.0f + 2.0f * style.padding_x, text.size.y + 24.0f + style.padding_y));
    REQUIRE(above.image);
    CHECK(above.image->atlas == picture.atlas);
    CHECK(above.image->box == glm::vec4(std::round(0.5f * (above.size.x - 40.0f)), style.padding_y,
                                        std::round(0.5f * (above.size.x - 40.0f)) + 40.0f,
                                        style.padding_y + 24.0f));
    REQUIRE(above.glyphs.size() == text.glyphs.size());
    for (size_t g = 0; g < text.glyphs.size(); ++g) {
      CHECK(above.glyphs[g].box.y == text.glyphs[g].box.y + 24.0f + style.padding_y);
      CHECK(above.glyphs[g].box.y >= above.image->box.w);
    }

    LabelImageBlock beside = picture;
    beside.left = true;
    beside.size = {20.0f, 40.0f};  // taller than the text
    const LabelTextLayout left = layout_label_text(font, atlas, "Pons", style, {}, beside);
    CHECK(left.size ==
          glm::vec2(style.padding_x + 20.0f + text.size.x, 40.0f + 2.0f * style.padding_y));
    REQUIRE(left.image);
    CHECK(left.image->box == glm::vec4(style.padding_x, style.padding_y, style.padding_x + 20.0f,
                                       style.padding_y + 40.0f));
    for (size_t g = 0; g < text.glyphs.size(); ++g) {
      CHECK(left.glyphs[g].box.x == text.glyphs[g].box.x + 20.0f + style.padding_x);
      CHECK(left.glyphs[g].box.x >= left.image->box.z);
    }

    // No text: the picture and its padding. A given size is still a minimum.
    const LabelTextLayout alone = layout_label_text(font, atlas, "", style, {}, picture);
    CHECK(alone.size == glm::vec2(40.0f + 2.0f * style.padding_x, 24.0f + 2.0f * style.padding_y));
    CHECK(layout_label_text(font, atlas, "Pons", style, {300.0f, 100.0f}, picture).size ==
          glm::vec2(300.0f, 100.0f));
    CHECK_FALSE(text.image);
  }

  TEST_CASE("label_pictures_are_baked_at_their_height_times_the_scale_with_their_aspect") {
    std::vector<Label> labels(3);
    labels[0] = picture_label(20.0f, LabelImage::Side::above, 64);  // 64 x 32 texels
    labels[2] = picture_label(16.0f, LabelImage::Side::left);
    const LabelImages images = bake_label_images(labels, 1.5f);
    REQUIRE(images.blocks.size() == 3);
    REQUIRE(images.blocks[0]);
    CHECK(images.blocks[0]->size == glm::vec2(60.0f, 30.0f));
    CHECK_FALSE(images.blocks[0]->left);
    CHECK_FALSE(images.blocks[1]);
    REQUIRE(images.blocks[2]);
    CHECK(images.blocks[2]->size == glm::vec2(24.0f, 24.0f));
    CHECK(images.blocks[2]->left);
    REQUIRE(images.atlas.rects.size() == 2);
    CHECK(images.blocks[2]->atlas == images.atlas.rects[1]);
    const glm::vec4 r = images.blocks[0]->atlas;
    CHECK((r.z - r.x) * float(images.atlas.width) == doctest::Approx(60.0f));
    CHECK((r.w - r.y) * float(images.atlas.height) == doctest::Approx(30.0f));

    // In the glyph buffer: the picture's quad after the label's glyphs.
    std::vector<gpu::LabelGpu> gpu_labels(3);
    const std::vector<std::string> texts = {"Insula", "Pons", "Cortex"};
    const std::vector<gpu::GlyphGpu> glyphs =
        build_glyph_buffer(test_font(), test_atlas(), texts, gpu_labels, {}, images.blocks);
    CHECK(gpu_labels[0].image_quads == 1);
    CHECK(gpu_labels[1].image_quads == 0);
    CHECK(gpu_labels[1].glyph_first == 7);
    CHECK(gpu_labels[2].glyph_first == 11);
    CHECK(glyphs[6].atlas == images.blocks[0]->atlas);
    CHECK(glyphs.size() == 6 + 1 + 4 + 6 + 1);
    CHECK(gpu_labels[0].size.y > 30.0f + test_font().line_height());
  }

  TEST_CASE("glyph_buffer_gives_each_label_its_range_and_size") {
    std::vector<gpu::LabelGpu> labels(3);
    labels[2].size = {150.0f, 0.0f};
    const std::vector<std::string> texts = {"Insula", "a b", "Amygdala"};
    const std::vector<gpu::GlyphGpu> glyphs = test_glyphs(texts, labels);
    CHECK(labels[0].glyph_first == 0);
    CHECK(labels[0].glyph_count == 6);
    CHECK(labels[1].glyph_first == 6);
    CHECK(labels[1].glyph_count == 2);  // the space has no quad
    CHECK(labels[2].glyph_first == 8);
    CHECK(glyphs.size() == 16);
    CHECK(labels[0].size == layout_label_text(test_font(), test_atlas(), "Insula").size);
    CHECK(labels[2].size.x == 150.0f);
    std::vector<gpu::LabelGpu> too_few(2);
    CHECK_THROWS_AS(test_glyphs(texts, too_few), Error);
  }

  TEST_CASE("label_reference_draws_only_enabled_shown_labels_on_their_own_layer") {
    LabelScene s = make_scene();
    const std::vector<glm::vec4> drawn = reference_layers(s);
    size_t changed[3] = {0, 0, 0};
    for (uint32_t l = 0; l < s.layer_count; ++l) {
      for (size_t p = 0; p < s.pixels(); ++p)
        changed[l] += drawn[l * s.pixels() + p] != s.layers[l * s.pixels() + p];
    }
    CHECK(changed[0] > 200);
    CHECK(changed[1] > 500);
    CHECK(changed[2] > 500);
    // The hidden label's box (around 88, 30 on layer 0) is untouched.
    CHECK(drawn[size_t{30} * s.size.width + 88] == s.at(0, 88, 30));
    for (gpu::LabelGpu& label : s.labels) label.flags &= ~LABEL_ENABLED;
    CHECK(reference_layers(s) == s.layers);
  }

  TEST_CASE("a_tile_far_from_a_label_holds_none_of_its_shapes") {
    // The drawing passes leave a label out of a 16 x 16 tile when label_far_from_tile says so:
    // then none of what it draws (frame, connector solid or dashed, the anchor's mark filled or
    // hollow, the composite's dashed connector with its halo, anything inside its box) may reach a
    // pixel centre of the tile. Random labels with long connectors, tiles all around them; the test
    // also asserts the tight test leaves out tiles that the connector's bounding rectangle would
    // keep.
    uint32_t seed = 12345u;
    const auto next = [&seed](float lo, float hi) {
      seed = seed * 1664525u + 1013904223u;
      return lo + (hi - lo) * float(seed >> 8) / float(1u << 24);
    };
    size_t far_tiles = 0, inside_rectangle = 0, touched = 0;
    for (int n = 0; n < 120; ++n) {
      gpu::LabelGpu label = label_on(1, {next(0.0f, 256.0f), next(0.0f, 256.0f)});
      label.size = {next(10.0f, 120.0f), next(10.0f, 40.0f)};
      gpu::PlacementGpu placement{{next(0.0f, 256.0f), next(0.0f, 256.0f)}, 0.0f, PLACEMENT_SHOWN};
      placement.opacity = 1.0f;
      const glm::vec2 centre = placement.position, half = 0.5f * label.size;
      for (uint32_t ty = 0; ty < 16; ++ty) {
        for (uint32_t tx = 0; tx < 16; ++tx) {
          const glm::vec2 lo = glm::vec2(tx * 16, ty * 16) + 0.5f, hi = lo + 15.0f;
          if (!gpu::label_far_from_tile(lo, hi, label.anchor, centre, label.size)) continue;
          ++far_tiles;
          bool near_rectangle = true;
          for (float y = lo.y; y <= hi.y; y += 1.0f) {
            for (float x = lo.x; x <= hi.x; x += 1.0f) {
              const glm::vec2 p{x, y};
              near_rectangle =
                  near_rectangle && !gpu::label_far_from(p, label.anchor, centre, label.size);
              const glm::vec4 none(0.0f);
              for (const float hidden : {0.0f, 0.5f, 1.0f}) {  // (seen, turning, hidden)
                touched += gpu::label_frame(p, label.anchor, centre, label.size, true,
                                            gpu::LABEL_BORDER_COLOR, hidden, true) != none ||
                           gpu::label_anchor_mark(p, label.anchor, hidden) != none ||
                           gpu::label_box_distance(p, centre, half, 0.0f) <= 1.0f ||
                           gpu::label_behind(label, placement, p, 1.0f, hidden) != none;
              }
            }
          }
          inside_rectangle += near_rectangle;
        }
      }
    }
    CHECK(touched == 0);
    CHECK(far_tiles > 4000);
    CHECK(inside_rectangle > 40);
  }
}

TEST_SUITE("gpu") {
  TEST_CASE_FIXTURE(test::GpuTest, "label_drawing_and_composite_match_the_cpu_reference") {
    const LabelScene s = make_scene();
    const DrawnLabels gpu = draw_matching_the_reference(ctx, s);
    // Guards against comparing two unlabelled pictures.
    CHECK(gpu.layers != s.layers);
    if (std::getenv("STRATA_KEEP_IMAGES")) {
      write_png(test::output_dir() + "/labels.png", s.size.width, s.size.height, gpu.final);
    }
  }

  // With no background the composite keeps its alpha, straight: as the reference, nothing where
  // every layer is empty, and over white the composite on white again (connectors with halos on
  // both).
  TEST_CASE_FIXTURE(test::GpuTest, "a_transparent_composite_is_straight_alpha_as_the_reference") {
    LabelScene s = make_scene();
    for (uint32_t y = 80; y < s.size.height; ++y) {  // (the rear layer opaque above only)
      for (uint32_t x = 0; x < s.size.width; ++x) s.at(2, x, y) = glm::vec4(0.0f);
    }
    s.background = {glm::vec3(1.0f)};
    const DrawnLabels opaque = draw_matching_the_reference(ctx, s);
    s.background.transparent = true;
    const DrawnLabels clear = draw_matching_the_reference(ctx, s);
    size_t empty = 0, partial = 0;
    int worst = 0;
    for (size_t p = 0; p < s.pixels(); ++p) {
      const int a = clear.final[4 * p + 3];
      empty += a == 0;
      partial += a > 0 && a < 255;
      for (int ch = 0; ch < 3; ++ch) {
        const float over = (float(clear.final[4 * p + ch]) * float(a) +
                            (255.0f - float(a)) * 255.0f * s.background.color[ch]) /
                           255.0f;
        worst = std::max(worst, int(std::lround(std::abs(over - float(opaque.final[4 * p + ch])))));
      }
    }
    CHECK(empty > 0);
    CHECK(partial > 0);
    CHECK(worst <= 2);
  }

  TEST_CASE_FIXTURE(test::GpuTest, "many_overlapping_labels_match_the_cpu_reference") {
    // 300 labels over the image on every layer, some internal, some hidden, some fading: each
    // workgroup keeps the labels that can touch its tile (ten words of its bit set, past the
    // eight of the old 256-label limit), and the picture, layers and composite, is still the
    // reference's, label order included.
    LabelScene s = make_scene();
    s.labels.clear();
    s.placements.clear();
    std::vector<std::string> texts;
    for (uint32_t i = 0; i < 300; ++i) {
      const glm::vec2 anchor{float((i * 37) % 112), float((i * 53) % 96)};
      const uint32_t flags = LABEL_ENABLED | (i % 9 == 4 ? LABEL_INTERNAL : 0u);
      s.labels.push_back(label_on(i % 3, anchor, i % 11 == 7 ? 0u : flags));
      gpu::PlacementGpu p{{float((i * 29 + 13) % 112), float((i * 17 + 5) % 96)},
                          0.0f,
                          i % 13 == 6 ? PLACEMENT_HIDDEN : PLACEMENT_SHOWN};
      p.opacity = i % 5 == 2 ? 0.5f : 1.0f;
      s.placements.push_back(p);
      texts.push_back(i % 2 ? "Cortex" : "Pons");
    }
    s.glyphs = test_glyphs(texts, s.labels);
    const DrawnLabels gpu = draw_matching_the_reference(ctx, s);
    CHECK(gpu.layers != s.layers);
  }

  TEST_CASE_FIXTURE(test::GpuTest,
                    "ghosting_opens_the_front_layers_at_rear_anchors_as_the_reference") {
    // The rear label (layer 2, anchor 22,66) lies under the middle layer's ramp; the middle label
    // (layer 1, anchor 92,78) under nothing in front. With ghosting the layers in front of each
    // open around its anchor and along its connector; the GPU pass equals the reference, labels
    // drawn after it included.
    LabelScene s = make_scene();
    for (uint32_t y = 0; y < s.size.height; ++y) {
      for (uint32_t x = 0; x < s.size.width; ++x) {
        s.at(0, x, y) = to_half_precision(glm::vec4(0.3f, 0.2f, 0.1f, 0.5f));  // a veil in front
      }
    }
    s.ghost = {1.0f, 14.0f, 4.0f};
    const DrawnLabels gpu = draw_matching_the_reference(ctx, s);
    const LabelDrawData data{s.labels, s.placements, s.glyphs};
    const std::vector<glm::vec4> ghosted =
        ghost_reference(s.layers, s.size, s.layer_count, data, s.ghost);
    const auto front_alpha = [&](const std::vector<glm::vec4>& layers, glm::vec2 p, uint32_t l) {
      const size_t q = size_t(p.y) * s.size.width + size_t(p.x);
      float a = 0.0f;
      for (uint32_t k = 0; k < l; ++k) a += (1.0f - a) * layers[k * s.pixels() + q].a;
      return a;
    };
    const glm::vec2 rear = s.labels[0].anchor, middle = s.labels[1].anchor;
    CHECK(gpu.covers[0].front_alpha ==
          doctest::Approx(front_alpha(ghosted, rear, 2)).epsilon(1e-4));
    CHECK(gpu.covers[0].front_alpha <= 0.3f);
    CHECK(front_alpha(s.layers, rear, 2) > 0.5f);
    CHECK(front_alpha(ghosted, rear, 2) <= 0.3f);
    CHECK(front_alpha(ghosted, middle, 1) <= 0.3f);
    // Far from every lens (twice the radius from both rear anchors, away from their connectors)
    // nothing changed: the corner (104, 4).
    const size_t corner = size_t{4} * s.size.width + 104;
    for (uint32_t k = 0; k < s.layer_count; ++k) {
      CHECK(ghosted[k * s.pixels() + corner] == s.layers[k * s.pixels() + corner]);
    }
    // A fading label's lens fades with it; off, nothing changes.
    s.placements[0].opacity = 0.5f;
    const std::vector<glm::vec4> half =
        ghost_reference(s.layers, s.size, s.layer_count, data, s.ghost);
    const float a_half = front_alpha(half, rear, 2);
    CHECK(a_half > front_alpha(ghosted, rear, 2));
    CHECK(a_half < front_alpha(s.layers, rear, 2));
    CHECK(ghost_reference(s.layers, s.size, s.layer_count, data, {}) == s.layers);
  }

  TEST_CASE_FIXTURE(test::GpuTest, "label_on_a_rear_layer_is_partly_covered_by_the_front_layer") {
    const LabelScene s = make_scene();
    const DrawnLabels gpu = draw_on_gpu(ctx, s);
    // Label 0 is on layer 2, under the front layer's blue rectangle (alpha 0.6) and the middle
    // layer's faint green: its white text shows through, dimmed and tinted.
    const glm::uvec2 rear = brightest_text_pixel(s, gpu.layers, 0);
    const size_t pixel = size_t{rear.y} * s.size.width + rear.x;
    const glm::vec4 text = gpu.layers[2 * s.pixels() + pixel];
    CHECK(text.r > 0.9f);
    const glm::vec4 front = gpu.layers[pixel], middle = gpu.layers[s.pixels() + pixel];
    CHECK(front.a == doctest::Approx(0.6f).epsilon(0.01));
    const glm::vec4 covered = final_pixel(s, gpu.final, rear);
    const float expected = front.r + (1.0f - front.a) * (middle.r + (1.0f - middle.a) * text.r);
    CHECK(covered.r == doctest::Approx(expected).epsilon(0.02));
    CHECK(covered.r < 0.6f);  // covered ...
    CHECK(covered.r > 0.3f);  // ... partly
    CHECK(covered.b > covered.r);
    // Label 2 is on the front layer: its text is at least as white in the final image as in its
    // layer (anything behind only adds where the text's coverage is partial).
    const glm::uvec2 nearest = brightest_text_pixel(s, gpu.layers, 2);
    const float unobstructed = gpu.layers[size_t{nearest.y} * s.size.width + nearest.x].r;
    CHECK(unobstructed > 0.8f);
    CHECK(final_pixel(s, gpu.final, nearest).r >= unobstructed - kTolerance);
  }

  // A label on the rear layer whose connector and anchor lie under an opaque slab of the front
  // layer: the composite draws them again on top, dashed (bright pixels with gaps between) with
  // the anchor's mark (a ring: the slab hides the anchor), as the reference does; a hidden label
  // draws nothing there.
  TEST_CASE_FIXTURE(test::GpuTest, "a_leader_behind_an_opaque_slab_stays_visible_dashed") {
    LabelScene s;
    s.layer_count = 2;
    s.layers.assign(2 * s.pixels(), glm::vec4(0.0f));
    for (uint32_t y = 0; y < s.size.height; ++y) {
      for (uint32_t x = 30; x < 80; ++x)
        s.at(0, x, y) = to_half_precision({0.3f, 0.3f, 0.3f, 1.0f});
    }
    s.labels = {label_on(1, {45.5f, 48.5f})};
    const std::vector<std::string> texts = {"Pons"};
    s.glyphs = test_glyphs(texts, s.labels);
    s.placements = {{{95.0f, 48.5f}, 0.0f, PLACEMENT_SHOWN}};
    const DrawnLabels gpu = draw_on_gpu(ctx, s);
    CHECK(worst_difference(gpu.final, reference_final(s)) <= 2);
    // Along the connector inside the slab (past the marker): dashes and gaps.
    int bright = 0, slab = 0;
    for (uint32_t x = 52; x < 78; ++x) {
      const float r = final_pixel(s, gpu.final, {x, 48}).r;
      if (r > 0.6f) ++bright;
      if (std::abs(r - 0.3f) < 0.02f) ++slab;
    }
    CHECK(bright >= 6);
    CHECK(slab >= 6);
    // The slab hides the anchor: its mark is a ring (the slab through its middle).
    CHECK(gpu.covers[0].hidden == 1.0f);
    CHECK(final_pixel(s, gpu.final, {45, 48}).r == doctest::Approx(0.3f).epsilon(0.03));
    CHECK(final_pixel(s, gpu.final, {45, 45}).r > 0.6f);
    // Hidden: the slab is untouched.
    s.placements[0].shown = PLACEMENT_HIDDEN;
    const DrawnLabels hidden = draw_on_gpu(ctx, s);
    for (uint32_t x = 40; x < 78; ++x) {
      CHECK(final_pixel(s, hidden.final, {x, 48}).r == doctest::Approx(0.3f).epsilon(0.03));
    }
  }

  // An anchor behind an opaque surface of its own layer (the depth image says where the picture
  // first becomes opaque: depth 10 over the slab x 30..80), one in front of it and one on it (an
  // anchor picked on a surface): the hidden one is drawn with a dashed connector to a ring, the
  // slab seen through its middle; the others solid to a filled mark. As the reference draws them.
  TEST_CASE_FIXTURE(test::GpuTest, "a_hidden_anchor_is_drawn_dashed_to_a_ring_the_others_solid") {
    LabelScene s;
    s.layer_count = 1;
    s.layers.assign(s.pixels(), glm::vec4(0.0f));
    s.depth.assign(s.pixels(), 0.0f);
    for (uint32_t y = 0; y < s.size.height; ++y) {
      for (uint32_t x = 30; x < 80; ++x) {
        s.at(0, x, y) = to_half_precision({0.3f, 0.3f, 0.3f, 1.0f});
        s.depth[size_t{y} * s.size.width + x] = 10.0f;
      }
    }
    s.labels = {label_on(0, {45.5f, 48.5f}), label_on(0, {45.5f, 15.5f}),
                label_on(0, {45.5f, 80.5f})};
    s.labels[0].anchor_depth = 20.0f;   // behind the surface
    s.labels[1].anchor_depth = 5.0f;    // in front of it
    s.labels[2].anchor_depth = 10.25f;  // on it (within two ray steps)
    const std::vector<std::string> texts = {"Pons", "Pons", "Pons"};
    s.glyphs = test_glyphs(texts, s.labels);
    s.placements = {{{95.0f, 48.5f}, 0.0f, PLACEMENT_SHOWN},
                    {{95.0f, 15.5f}, 0.0f, PLACEMENT_SHOWN},
                    {{95.0f, 80.5f}, 0.0f, PLACEMENT_SHOWN}};
    const DrawnLabels gpu = draw_matching_the_reference(ctx, s);
    CHECK(gpu.covers[0].hidden == 1.0f);
    CHECK(gpu.covers[1].hidden == 0.0f);
    CHECK(gpu.covers[2].hidden == 0.0f);
    // Along each connector over the slab (past the mark, to the box): dashes and gaps where the
    // anchor is hidden, a solid line where it is not.
    const float box_left = 95.0f - 0.5f * s.labels[0].size.x;
    for (size_t i = 0; i < 3; ++i) {
      CAPTURE(i);
      const uint32_t row = uint32_t(s.labels[i].anchor.y);
      int bright = 0, slab = 0, along = 0;
      for (uint32_t x = 52; float(x) + 2.0f < box_left; ++x, ++along) {
        const float r = final_pixel(s, gpu.final, {x, row}).r;
        if (r > 0.6f) ++bright;
        if (std::abs(r - 0.3f) < 0.02f) ++slab;
      }
      REQUIRE(along >= 14);
      CHECK((i == 0 ? bright >= 6 && slab >= 3 : bright == along));
      // The mark: the slab through the ring's middle, or a white disc.
      const float centre = final_pixel(s, gpu.final, {45, row}).r;
      CHECK((i == 0 ? std::abs(centre - 0.3f) < 0.02f : centre > 0.9f));
    }
    if (std::getenv("STRATA_KEEP_IMAGES")) {
      write_png(test::output_dir() + "/hidden_anchor.png", s.size.width, s.size.height, gpu.final);
    }
  }

  // A rear label (layer 1) behind a slab of the front layer, with content behind it: ghosting
  // opens the slab at its anchor, which is then seen; without ghosting the slab hides it. The
  // depth image's surface (in the front layer, before the ghosting) does not hide it by itself;
  // in the label's own layer (a split in front of the surface) it does, ghosting or not.
  TEST_CASE_FIXTURE(test::GpuTest, "an_anchor_is_hidden_unless_ghosting_opens_what_hides_it") {
    LabelScene s;
    s.layer_count = 2;
    s.layers.assign(2 * s.pixels(), glm::vec4(0.0f));
    s.depth.assign(s.pixels(), 0.0f);
    for (uint32_t y = 0; y < s.size.height; ++y) {
      for (uint32_t x = 0; x < s.size.width; ++x) {
        s.at(1, x, y) = to_half_precision({0.5f, 0.2f, 0.2f, 1.0f});
        s.depth[size_t{y} * s.size.width + x] = 30.0f;
        if (x < 30 || x >= 80) continue;
        s.at(0, x, y) = to_half_precision({0.3f, 0.3f, 0.3f, 1.0f});
        s.depth[size_t{y} * s.size.width + x] = 10.0f;
      }
    }
    s.frame.splits[0].x = 15.0f;  // layer 1 from depth 15 on
    s.labels = {label_on(1, {45.5f, 48.5f})};
    s.labels[0].anchor_depth = 20.0f;
    const std::vector<std::string> texts = {"Pons"};
    s.glyphs = test_glyphs(texts, s.labels);
    s.placements = {{{95.0f, 48.5f}, 0.0f, PLACEMENT_SHOWN}};
    s.ghost = {1.0f, 14.0f, 0.0f};
    CHECK(draw_matching_the_reference(ctx, s).covers[0].hidden == 0.0f);
    s.ghost = {};
    const DrawnLabels unghosted = draw_matching_the_reference(ctx, s);
    CHECK(unghosted.covers[0].front_alpha == 1.0f);
    CHECK(unghosted.covers[0].hidden == 1.0f);
    s.ghost = {1.0f, 14.0f, 0.0f};
    s.frame.splits[0].x = 5.0f;  // the surface in the label's own layer
    CHECK(draw_matching_the_reference(ctx, s).covers[0].hidden == 1.0f);
  }

  // The whole labelled frame, a still and the frames of a video: an opaque quad (a mesh) with one
  // anchor behind it and one in front, with the default layering and ghosting (nothing lies
  // behind the quad for a lens to show). The layout says which anchor is hidden, and the picture
  // draws it so: the quad seen through its ring, a dashed leader; the other a filled mark with a
  // solid leader.
  TEST_CASE_FIXTURE(test::GpuTest, "an_anchor_behind_a_mesh_is_flagged_hidden_and_drawn_so") {
    Scene scene;
    scene.meshes = {test::quad(0.0f, {0.3f, 0.5f, 0.8f, 1.0f}, 12.0f)};
    scene.labels = {{1, "Behind", {-5.0f, 3.0f, -6.0f}}, {2, "Front", {5.0f, -4.0f, 6.0f}}};
    scene.camera = {glm::lookAt(glm::vec3(0.0f, 0.0f, 60.0f), glm::vec3(0.0f), {0, 1, 0}), 30.0f,
                    1.0f, 200.0f};
    const graph::Extent size{128, 128};
    const auto check = [&size](const LabelledFrame& frame) {
      REQUIRE(frame.labels.size() == 2);
      const auto pixel = [&](glm::vec2 p) {
        const size_t i = 4 * (size_t(p.y) * size.width + size_t(p.x));
        return glm::vec3(frame.image[i], frame.image[i + 1], frame.image[i + 2]) / 255.0f;
      };
      for (size_t i = 0; i < 2; ++i) {
        const LabelLayout& l = frame.labels[i];
        CAPTURE(l.text);
        REQUIRE(l.placed);
        REQUIRE(l.opacity == 1.0f);
        const bool hidden = i == 0;
        CHECK(l.anchor_hidden == std::optional(hidden));
        // The mark's middle, then the leader from the mark's edge to the box: white all along,
        // or dashes (white) and gaps (the quad, bluish, or the background).
        const glm::vec3 centre = pixel(l.anchor);
        CHECK((hidden ? centre.b > centre.r + 0.2f
                      : glm::all(glm::greaterThan(centre, glm::vec3(0.9f)))));
        const glm::vec2 end = glm::clamp(l.anchor, l.box_origin, l.box_origin + l.box_size);
        const float length = glm::distance(l.anchor, end);
        REQUIRE(length > 24.0f);
        const glm::vec2 along = (end - l.anchor) / length, across(-along.y, along.x);
        int white = 0, other = 0;
        for (float t = 7.0f; t < length - 2.0f; t += 1.0f) {
          float whitest = 0.0f;  // (of the pixels across the line: one has its centre near it)
          for (const float k : {-1.0f, 0.0f, 1.0f}) {
            const glm::vec3 c = pixel(l.anchor + t * along + k * across);
            whitest = std::max(whitest, std::min({c.r, c.g, c.b}));
          }
          (whitest > 0.6f ? white : other) += 1;
        }
        CHECK(white > 6);
        CHECK((hidden ? other > 6 : other == 0));
      }
    };
    LabelledRenderer renderer(ctx, scene, scene.camera, size, {});
    renderer.run();
    const LabelledFrame still = renderer.result();
    check(still);
    const nlohmann::json layout = nlohmann::json::parse(layout_json(still));
    CHECK(layout["labels"][0]["anchor_hidden"] == true);
    CHECK(layout["labels"][1]["anchor_hidden"] == false);
    LabelledRenderer video(ctx, scene, scene.camera, size, {});
    for (int frame = 0; frame < 20; ++frame) video.advance(0.05);  // (faded in by then)
    check(video.result());
    if (std::getenv("STRATA_KEEP_IMAGES")) {
      write_png(test::output_dir() + "/hidden_anchor_mesh.png", size.width, size.height,
                still.image);
    }
  }

  // Borders in their layer's colour (a depth cue): as the reference draws them, and different
  // from the plain ones on a rear layer.
  TEST_CASE_FIXTURE(test::GpuTest, "layer_colored_borders_match_the_cpu_reference") {
    LabelScene s = make_scene();
    s.layer_frames = true;
    const DrawnLabels gpu = draw_on_gpu(ctx, s);
    size_t where = 0;
    CHECK(worst_difference(gpu.layers, reference_layers(s), where) <= kTolerance);
    s.layer_frames = false;
    CHECK(worst_difference(gpu.layers, reference_layers(s), where) > 0.1f);
  }

  // The acceptance test of labels with pictures: two labels, a picture above the text (at a
  // whole-pixel position: a texel per pixel) and one left of it (at a half-pixel position: each
  // pixel filtered between texels, the picture's edges half covered), drawn as the reference
  // draws them, and each quadrant's colour found where the picture lies in the box.
  TEST_CASE_FIXTURE(test::GpuTest, "an_image_label_draws_its_image") {
    LabelScene s = make_scene();
    const std::vector<Label> pictures = {picture_label(24.0f, LabelImage::Side::above),
                                         picture_label(16.0f, LabelImage::Side::left)};
    const LabelImages images = bake_label_images(pictures, 1.0f);
    s.images = images.atlas;
    s.labels = {label_on(2, {20.0f, 80.0f}), label_on(1, {100.0f, 88.0f})};
    s.placements = {{{30.0f, 30.0f}, 0.0f, PLACEMENT_SHOWN},
                    {{76.5f, 61.5f}, 0.0f, PLACEMENT_SHOWN}};
    const std::vector<std::string> texts = {"Cortex", "Pons"};
    s.glyphs = build_glyph_buffer(test_font(), test_atlas(), texts, s.labels, {}, images.blocks);
    REQUIRE(s.labels[0].image_quads == 1);
    REQUIRE(s.labels[1].image_quads == 1);

    const DrawnLabels gpu = draw_matching_the_reference(ctx, s);

    // The picture in each label's own layer (label 0 lies under the front layer's blue), and
    // in the final image where nothing lies in front of it (label 1).
    for (size_t i = 0; i < 2; ++i) {
      for (int q = 0; q < 4; ++q) {
        CAPTURE(i);
        CAPTURE(q);
        const glm::uvec2 p = quadrant_pixel(s, i, q);
        const glm::vec4 drawn =
            gpu.layers[s.labels[i].layer * s.pixels() + size_t{p.y} * s.size.width + p.x];
        CHECK(glm::all(glm::lessThan(glm::abs(drawn - kQuadrants[size_t(q)]), glm::vec4(0.01f))));
        if (i == 1) {
          const glm::vec4 shown = final_pixel(s, gpu.final, p);
          CHECK(glm::all(glm::lessThan(glm::abs(shown - kQuadrants[size_t(q)]), glm::vec4(0.01f))));
        }
      }
    }
    if (std::getenv("STRATA_KEEP_IMAGES")) {
      write_png(test::output_dir() + "/image_labels.png", s.size.width, s.size.height, gpu.final);
    }
  }

  TEST_CASE_FIXTURE(test::GpuTest, "label_with_a_hidden_placement_draws_nothing") {
    LabelScene s = make_scene();
    for (gpu::PlacementGpu& p : s.placements) p.shown = PLACEMENT_HIDDEN;
    const DrawnLabels gpu = draw_on_gpu(ctx, s);
    CHECK(gpu.layers == s.layers);
    CHECK(worst_difference(gpu.final, reference_final(s)) <= 2);
  }
}

}  // namespace strata
