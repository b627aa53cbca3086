// A picture's title and legend: their layout (labeling/annotations.h), their drawing, the count
// of labels over them (`strata eval`), and, end to end, that no label of a crowded still or of any
// frame of a video is drawn over them.
#include <doctest/doctest.h>

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "engine/core/png.h"
#include "gpu_fixture.h"
#include "labeling/annotation_drawing.h"
#include "labeling/annotations.h"
#include "labeling/layout_metrics.h"
#include "test_files.h"

namespace strata {
namespace {

const Font& text_font() {
  static const Font font(14.0f);
  return font;
}
const Font& title_font() {
  static const Font font(21.0f);
  return font;
}
AnnotationFonts fonts() {
  return {text_font(), title_font()};
}

bool inside(glm::vec4 inner, glm::vec4 outer) {
  return inner.x >= outer.x && inner.y >= outer.y && inner.z <= outer.z && inner.w <= outer.w;
}
bool overlap(glm::vec4 a, glm::vec4 b) {
  return std::min(a.z, b.z) > std::max(a.x, b.x) && std::min(a.w, b.w) > std::max(a.y, b.y);
}

std::vector<LegendEntry> entries(size_t n) {
  std::vector<LegendEntry> out;
  for (size_t i = 0; i < n; ++i) {
    out.push_back({"Label " + std::to_string(i),
                   i % 2 == 0 ? std::optional(glm::vec3(0.2f, 0.6f, 0.9f)) : std::nullopt});
  }
  return out;
}

// Whether a layout file's drawn labels keep off its annotations (the acceptance check).
size_t labels_over_annotations(const std::string& path) {
  return frame_metrics(read_layout(path)).over_annotations;
}

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("title_is_centred_at_the_top_and_legend_in_its_corner_inside_the_image") {
    AnnotationSettings s;
    s.title = "Head: oblique view";
    s.legend = true;
    const glm::uvec2 image(256, 256);
    const std::vector<LegendEntry> rows = entries(3);
    const AnnotationLayout layout = layout_annotations(fonts(), s, image, rows);
    REQUIRE(layout.title);
    REQUIRE(layout.legend);
    const float gap = 6.0f;  // (6 / 14 em of a 14 px font)
    const glm::vec4 t = layout.title->box.rect, l = layout.legend->box.rect;
    CHECK(t.y == gap);
    CHECK(std::abs((t.x + t.z) * 0.5f - 128.0f) <= 0.5f);
    CHECK(l.z == 256.0f - gap);
    CHECK(l.w == 256.0f - gap);
    CHECK_FALSE(overlap(t, l));
    CHECK(layout.title->text.font_pixels == 21.0f);
    CHECK(layout.title->text.origin.x >= t.x);
    CHECK(layout.title->text.origin.x + layout.title->text.width <= t.z);
    // A row per entry, top to bottom, a swatch where the entry has a colour, all in the box.
    REQUIRE(layout.legend->rows.size() == 3);
    CHECK(layout.legend->listed == 3);
    for (size_t i = 0; i < 3; ++i) {
      const LegendRow& row = layout.legend->rows[i];
      CHECK(row.text.text == rows[i].text);
      CHECK(row.swatch.has_value() == rows[i].colour.has_value());
      if (row.swatch) CHECK(inside(*row.swatch, l));
      CHECK(row.text.origin.x + row.text.width <= l.z);
      if (i > 0) CHECK(row.text.origin.y > layout.legend->rows[i - 1].text.origin.y);
    }
    // The keep-out rectangles: each box grown by the gap, within the image.
    REQUIRE(layout.keep_out.size() == 2);
    CHECK(layout.keep_out[0] == glm::uvec4(t.x - gap, 0.0f, t.z + gap, t.w + gap));
    CHECK(layout.keep_out[1] == glm::uvec4(l.x - gap, l.y - gap, 256u, 256u));
    CHECK(layout.boxes().size() == 2);
    CHECK(layout.boxes()[1].name == "legend");

    s.corner = LegendCorner::top_left;
    const glm::vec4 top_left = layout_annotations(fonts(), s, image, rows).legend->box.rect;
    CHECK(top_left.x == gap);
    CHECK(top_left.y == t.w + 2.0f * gap);  // (below the title's keep-out)
  }

  TEST_CASE("legend_rows_past_its_room_become_one_more_row_and_long_texts_are_shortened") {
    AnnotationSettings s;
    s.legend = true;
    const AnnotationLayout many = layout_annotations(fonts(), s, {256, 128}, entries(40));
    REQUIRE(many.legend);
    const LegendLayout& legend = *many.legend;
    CHECK(legend.listed + 1 == legend.rows.size());
    CHECK(legend.rows.back().text.text == "+" + std::to_string(40 - legend.listed) + " more");
    CHECK(legend.box.rect.w - legend.box.rect.y <= 0.75f * 128.0f);
    CHECK_FALSE(many.title);

    const std::vector<LegendEntry> long_one{{std::string(200, 'W'), std::nullopt}};
    const AnnotationLayout cut = layout_annotations(fonts(), s, {256, 256}, long_one);
    REQUIRE(cut.legend);
    const std::string& text = cut.legend->rows[0].text.text;
    CHECK(text.size() < 200);
    CHECK(text.substr(text.size() - 3) == "\xE2\x80\xA6");
    CHECK(cut.legend->box.rect.z - cut.legend->box.rect.x <= 128.0f);

    // A line break (a label's text may have one) is a space: a title and each row are one line.
    AnnotationSettings broken;
    broken.title = "Line one\nline two";
    broken.legend = true;
    const std::vector<LegendEntry> two_lines{{"Left\nhippocampus", std::nullopt}};
    const AnnotationLayout one = layout_annotations(fonts(), broken, {256, 256}, two_lines);
    CHECK(one.title->text.text == "Line one line two");
    CHECK(one.legend->rows[0].text.text == "Left hippocampus");

    // No entries, or no room for a row: no legend, nothing kept out.
    CHECK_FALSE(layout_annotations(fonts(), s, {256, 256}, {}).legend);
    CHECK(layout_annotations(fonts(), s, {256, 256}, {}).keep_out.empty());
    CHECK_FALSE(layout_annotations(fonts(), s, {64, 20}, entries(2)).legend);
  }

  TEST_CASE("a_legend_in_a_given_room_keeps_the_rooms_keep_out_whatever_it_lists") {
    AnnotationSettings s;
    s.legend = true;
    const glm::uvec2 image(256, 256);
    const AnnotationLayout reserved = layout_annotations(fonts(), s, image, entries(6));
    const glm::vec4 room = reserved.legend->box.rect;
    const AnnotationLayout fewer = layout_annotations(fonts(), s, image, entries(2), room);
    REQUIRE(fewer.legend);
    CHECK(inside(fewer.legend->box.rect, room));
    CHECK(fewer.legend->box.rect.z == room.z);  // (its corner of the room)
    CHECK(fewer.legend->box.rect.w == room.w);
    CHECK(fewer.keep_out == reserved.keep_out);
    // More than the room holds: "+N more".
    const AnnotationLayout more = layout_annotations(fonts(), s, image, entries(9), room);
    CHECK(more.legend->rows.size() == 6);
    CHECK(more.legend->listed == 5);
  }

  TEST_CASE("annotations_are_drawn_in_their_boxes_only") {
    AnnotationSettings s;
    s.title = "Title";
    s.legend = true;
    const glm::uvec2 image(128, 128);
    const AnnotationLayout layout = layout_annotations(fonts(), s, image, entries(2));
    std::vector<uint8_t> rgba(size_t(image.x) * image.y * 4, 0);
    for (size_t p = 3; p < rgba.size(); p += 4) rgba[p] = 255;  // opaque black
    draw_annotations(rgba, image, layout, fonts());
    size_t changed_outside = 0, bright_in_title = 0;
    for (uint32_t y = 0; y < image.y; ++y) {
      for (uint32_t x = 0; x < image.x; ++x) {
        const uint8_t* p = &rgba[(size_t(y) * image.x + x) * 4];
        const glm::vec2 c(float(x) + 0.5f, float(y) + 0.5f);
        bool in_box = false;
        for (const NamedBox& b : layout.boxes()) {
          in_box = in_box || (c.x > b.rect.x - 1.0f && c.x < b.rect.z + 1.0f &&
                              c.y > b.rect.y - 1.0f && c.y < b.rect.w + 1.0f);
        }
        if (!in_box && (p[0] | p[1] | p[2]) != 0) ++changed_outside;
        if (overlap(glm::vec4(c, c + 0.1f), layout.title->box.rect) && p[0] > 200)
          ++bright_in_title;
        CHECK(p[3] == 255);
      }
    }
    CHECK(changed_outside == 0);
    CHECK(bright_in_title > 20);  // the text and the border, white on the dark box
    std::vector<uint8_t> wrong(10);
    CHECK_THROWS_AS(draw_annotations(wrong, image, layout, fonts()), Error);
  }

  TEST_CASE("eval_counts_drawn_labels_over_a_title_or_legend") {
    const nlohmann::json file = nlohmann::json::parse(R"({"width": 100, "height": 100, "labels": [
      {"id": 1, "anchor": [5, 5], "box": [10, 10, 20, 10], "shown": true},
      {"id": 2, "anchor": [5, 5], "box": [60, 60, 20, 10], "shown": true},
      {"id": 3, "anchor": [5, 5], "box": [0, 0, 20, 10], "shown": false, "placed": false},
      {"id": 4, "anchor": [5, 5], "box": [30, 40, 10, 10], "shown": true}],
      "annotations": [{"name": "title", "box": [0, 0, 100, 12]},
                      {"name": "legend", "box": [70, 65, 30, 35]}]})");
    const Layout layout = parse_layout(file, "a.json");
    REQUIRE(layout.annotations.size() == 2);
    CHECK(layout.annotations[1].name == "legend");
    // 1 reaches into the title, 2 into the legend; 3 is not drawn; 4 is clear (touching counts
    // for nothing).
    CHECK(frame_metrics(layout).over_annotations == 2);
    nlohmann::json bad = file;
    bad["annotations"][0]["box"] = {1, 2};
    CHECK_THROWS_WITH_AS(parse_layout(bad, "a.json"), doctest::Contains("annotations[0].box"),
                         Error);
  }
}

TEST_SUITE("cli") {
  // The acceptance check: in a crowded still at 256 px, labels would lie over the title and the
  // legend without them; with them, no label's box touches their boxes, which the layout file
  // records and `strata eval` counts.
  TEST_CASE("no_label_is_placed_over_the_title_or_legend_of_a_crowded_still") {
    const std::string dir = test::output_dir() + "/annotations";
    std::filesystem::create_directories(dir);
    const std::string scene =
        STRATA_SOURCE_DIR "/assets/scenes/head.json --camera oblique --size 256";
    const auto with =
        test::run_strata("--validate render " + scene + " -o " + dir + "/still.png --layout " +
                         dir + "/still.json --title \"Head: oblique\" --legend");
    REQUIRE(with.exit_code == 0);
    CHECK(with.output.find("validation:") == std::string::npos);
    const Layout layout = read_layout(dir + "/still.json");
    REQUIRE(layout.annotations.size() == 2);
    CHECK(frame_metrics(layout).over_annotations == 0);
    CHECK(frame_metrics(layout).shown >= 4);
    const auto eval = test::run_strata("eval " + dir + "/still.json");
    CHECK(eval.output.find("\"over_annotations\": 0") != std::string::npos);

    // The same still without them: its labels lie where the title and legend are.
    const auto without = test::run_strata("render " + scene + " -o " + dir +
                                          "/plain.png --layout " + dir + "/plain.json");
    REQUIRE(without.exit_code == 0);
    Layout plain = read_layout(dir + "/plain.json");
    plain.annotations = layout.annotations;
    CHECK(frame_metrics(plain).over_annotations >= 1);
  }

  // Every frame of a video (planned, the default) keeps its labels off the title and legend while
  // they move, and each frame's layout records them.
  TEST_CASE("no_label_is_drawn_over_the_title_or_legend_in_any_video_frame") {
    const std::string dir = test::output_dir() + "/annotations-video";
    std::filesystem::remove_all(dir);
    const auto r = test::run_strata("--validate video " STRATA_SOURCE_DIR
                                    "/assets/scenes/head.json --orbit 40 --seconds 1 --fps 8 "
                                    "--size 256 -o " +
                                    dir + "/frames --layout-dir " + dir +
                                    "/layouts --title Turntable --legend");
    REQUIRE(r.exit_code == 0);
    CHECK(r.output.find("validation:") == std::string::npos);
    size_t frames = 0, drawn = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir + "/layouts")) {
      const Layout layout = read_layout(entry.path());
      CHECK(layout.annotations.size() == 2);
      CHECK(labels_over_annotations(entry.path().string()) == 0);
      drawn += frame_metrics(layout).opaque;
      ++frames;
    }
    CHECK(frames == 9);
    CHECK(drawn >= frames);
    const Rgba8Image first = read_png(dir + "/frames/frame-00000.png");
    CHECK(first.width == 256);
  }
}

}  // namespace strata
