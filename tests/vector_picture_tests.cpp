// Vector stills (frame/vector_picture.h): `render -o x.svg` and `-o x.pdf` put every shown label's
// box and text where strata's own PNG has them (the SVG rasterised by rsvg-convert, the PDF by
// pdftoppm, at the PNG's size), keep each line of text as text (one <text> per line; pdftotext
// finds it), and keep right-to-left and CJK text as written.
#include <doctest/doctest.h>

#include <sys/wait.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <regex>

#include <nlohmann/json.hpp>

#include "engine/core/font.h"
#include "engine/core/png.h"
#include "frame/labelled_render.h"
#include "frame/vector_picture.h"
#include "gpu_fixture.h"
#include "labeling/text_layout.h"
#include "test_files.h"

namespace strata {
namespace {

// A shell command's output (stdout and stderr), failing the test when it fails.
std::string run_tool(const std::string& command) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  REQUIRE_MESSAGE(pipe != nullptr, "cannot run " << command);
  std::string output;
  char buffer[4096];
  size_t n = 0;
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) output.append(buffer, n);
  const int status = pclose(pipe);
  REQUIRE_MESSAGE((WIFEXITED(status) && WEXITSTATUS(status) == 0), command << ": " << output);
  return output;
}

struct PixelBox {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;  // inclusive; x1 < x0: none
  bool empty() const { return x1 < x0; }
};

// The light pixels (the label text's white ink, over the box's dark fill) inside a layout box
// without its border and the ramps around it. A pixel counts at about a third of the text's
// coverage: the raster's glyphs are hinted (crisp rows), the vector files' are not, and a higher
// threshold would count an edge pixel in one and not the other. (The box's fill over white
// content stays below it.)
PixelBox ink_box(const Rgba8Image& image, const nlohmann::json& box) {
  constexpr int kBorder = 2;
  constexpr uint8_t kInk = 100;
  const int x0 = int(std::floor(box[0].get<double>())) + kBorder;
  const int y0 = int(std::floor(box[1].get<double>())) + kBorder;
  const int x1 = int(std::ceil(box[0].get<double>() + box[2].get<double>())) - 1 - kBorder;
  const int y1 = int(std::ceil(box[1].get<double>() + box[3].get<double>())) - 1 - kBorder;
  PixelBox ink{x1 + 1, y1 + 1, x0 - 1, y0 - 1};
  for (int y = std::max(y0, 0); y <= std::min(y1, int(image.height) - 1); ++y) {
    for (int x = std::max(x0, 0); x <= std::min(x1, int(image.width) - 1); ++x) {
      const uint8_t* p = &image.pixels[(size_t(y) * image.width + size_t(x)) * 4];
      if (std::min({p[0], p[1], p[2]}) < kInk) continue;
      ink = {std::min(ink.x0, x), std::min(ink.y0, y), std::max(ink.x1, x), std::max(ink.y1, y)};
    }
  }
  return ink.x0 > ink.x1 ? PixelBox{} : ink;
}

// How far apart two ink boxes' edges are, at most (a large number when only one has ink).
int ink_distance(const PixelBox& a, const PixelBox& b) {
  if (a.empty() || b.empty()) return a.empty() && b.empty() ? 0 : 1000;
  return std::max(
      {std::abs(a.x0 - b.x0), std::abs(a.y0 - b.y0), std::abs(a.x1 - b.x1), std::abs(a.y1 - b.y1)});
}

struct Rendered {
  nlohmann::json layout;     // the PNG's
  Rgba8Image png, svg, pdf;  // the SVG and PDF rasterised at the PNG's size
  std::string svg_file, pdf_text;
};

// The scene rendered to .png, .svg and .pdf (each with its layout, whose boxes must agree with
// the PNG's within a pixel), and the vector files rasterised.
Rendered render_three(const std::string& scene, const std::string& options, int size,
                      const std::filesystem::path& folder) {
  Rendered out;
  std::vector<nlohmann::json> layouts;
  for (const char* extension : {"png", "svg", "pdf"}) {
    const std::string base = (folder / "still").string() + "." + extension;
    const auto r =
        test::run_strata("render " + scene + " " + options + " --size " + std::to_string(size) +
                         " -o " + base + " --layout " + base + ".json");
    REQUIRE_MESSAGE(r.exit_code == 0, r.output);
    layouts.push_back(nlohmann::json::parse(test::read_file(base + ".json")));
  }
  const std::string s = std::to_string(size), stem = (folder / "still").string();
  run_tool("rsvg-convert -w " + s + " -h " + s + " " + stem + ".svg -o " + stem + ".svg.png");
  run_tool("pdftoppm -png -r 72 -singlefile " + stem + ".pdf " + stem + ".pdf");
  out.layout = layouts[0];
  out.png = read_png(stem + ".png");
  out.svg = read_png(stem + ".svg.png");
  out.pdf = read_png(stem + ".pdf.png");
  out.svg_file = test::read_file(stem + ".svg");
  out.pdf_text = run_tool("pdftotext " + stem + ".pdf -");
  for (const Rgba8Image* image : {&out.svg, &out.pdf}) {
    REQUIRE(image->width == out.png.width);
    REQUIRE(image->height == out.png.height);
  }
  for (size_t i = 0; i < layouts[0]["labels"].size(); ++i) {
    for (const nlohmann::json& other : {layouts[1], layouts[2]}) {
      for (int k = 0; k < 4; ++k) {
        CHECK(std::abs(other["labels"][i]["box"][k].get<double>() -
                       layouts[0]["labels"][i]["box"][k].get<double>()) <= 1.0);
      }
    }
  }
  return out;
}

struct InkDifference {
  int svg = 0, pdf = 0;  // the largest distance of an ink box's edge from the PNG's
  int labels = 0;        // shown labels compared
};

// Each shown label's text ink in the rasterised SVG and PDF against the PNG's.
InkDifference compare_ink(const Rendered& r) {
  InkDifference d;
  for (const nlohmann::json& l : r.layout["labels"]) {
    if (!l["shown"].get<bool>()) continue;
    const PixelBox png = ink_box(r.png, l["box"]);
    const PixelBox svg = ink_box(r.svg, l["box"]);
    const PixelBox pdf = ink_box(r.pdf, l["box"]);
    CHECK_MESSAGE(!png.empty(), l["text"]);
    const auto show = [](const PixelBox& b) {
      return std::to_string(b.x0) + "," + std::to_string(b.y0) + ".." + std::to_string(b.x1) + "," +
             std::to_string(b.y1);
    };
    INFO(l["text"].get<std::string>(), ": ink ", show(png), " in the PNG, ", show(svg),
         " in the SVG, ", show(pdf), " in the PDF");
    CHECK(ink_distance(png, svg) <= 1);
    CHECK(ink_distance(png, pdf) <= 1);
    d.svg = std::max(d.svg, ink_distance(png, svg));
    d.pdf = std::max(d.pdf, ink_distance(png, pdf));
    ++d.labels;
  }
  return d;
}

// The texts of the SVG's <text> elements (none of the test labels needs an escape).
std::vector<std::string> svg_texts(const std::string& svg) {
  std::vector<std::string> texts;
  const std::regex text("<text[^>]*>([^<]*)</text>");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), text); it != std::sregex_iterator();
       ++it) {
    texts.push_back((*it)[1].str());
  }
  return texts;
}

// The lines of each shown label's text, as the labels are shaped at the default settings.
std::vector<std::string> shown_lines(const nlohmann::json& layout) {
  const LabellingSettings settings;
  const Font font(settings.font_pixels * settings.label_scale);
  std::vector<std::string> lines;
  for (const nlohmann::json& l : layout["labels"]) {
    if (!l["shown"].get<bool>()) continue;
    for (const ShapedLine& line :
         shape_label_text(font, l["text"].get<std::string>(), label_text_style(settings))) {
      lines.push_back(encode_utf8(line.text));
    }
  }
  return lines;
}

// pdftotext's text without the bidirectional embedding marks it puts around right-to-left runs.
std::string without_embedding_marks(std::string text) {
  for (const char* mark : {"\u202A", "\u202B", "\u202C", "\u202D", "\u202E"}) {
    for (size_t at = text.find(mark); at != std::string::npos; at = text.find(mark))
      text.erase(at, std::string(mark).size());
  }
  return text;
}

// `word_by_word`: lines pdftotext cannot give in logical order, whose words it must give. It
// orders a line's runs left to right on a page mostly left-to-right, so a right-to-left paragraph
// with a left-to-right run ("<Hebrew> 12 mm") comes out as "12 mm <Hebrew>"; its runs themselves
// come out as written.
void check_text_is_kept(const Rendered& r, const std::vector<std::string>& word_by_word = {}) {
  const std::vector<std::string> lines = shown_lines(r.layout);
  std::vector<std::string> texts = svg_texts(r.svg_file);
  std::vector<std::string> expected = lines;
  std::sort(texts.begin(), texts.end());
  std::sort(expected.begin(), expected.end());
  CHECK(texts == expected);  // one <text> per shown line, its text as written
  const std::string pdf_text = without_embedding_marks(r.pdf_text);
  for (const std::string& line : lines) {
    if (std::find(word_by_word.begin(), word_by_word.end(), line) == word_by_word.end()) {
      CHECK_MESSAGE(pdf_text.find(line) != std::string::npos, line << " in " << pdf_text);
      continue;
    }
    for (size_t at = 0; at <= line.size();) {
      const size_t space = std::min(line.find(' ', at), line.size());
      const std::string word = line.substr(at, space - at);
      CHECK_MESSAGE(pdf_text.find(word) != std::string::npos, word << " in " << pdf_text);
      at = space + 1;
    }
  }
}

const std::string kHead = STRATA_SOURCE_DIR "/assets/scenes/head.json";

}  // namespace

TEST_SUITE("cli") {
  TEST_CASE("vector_stills_put_each_label_box_and_text_where_the_png_has_them") {
    const auto folder = test::fresh_folder("cli", "vector_head");
    const Rendered r = render_three(kHead, "--camera oblique", 256, folder);
    const InkDifference d = compare_ink(r);
    CHECK(d.labels > 0);
    CHECK(d.svg <= 1);
    CHECK(d.pdf <= 1);
    check_text_is_kept(r);
  }

  // A title and a legend: drawn where the PNG has them, as text (the title and each
  // legend row one <text>; pdftotext finds the title), and the labels still where the PNG has
  // them.
  TEST_CASE("vector_stills_draw_the_title_and_legend_as_text_where_the_png_has_them") {
    const auto folder = test::fresh_folder("cli", "vector_notes");
    const Rendered r = render_three(kHead, "--camera oblique --title Brain --legend", 256, folder);
    const InkDifference d = compare_ink(r);
    CHECK(d.svg <= 1);
    CHECK(d.pdf <= 1);
    REQUIRE(r.layout.contains("annotations"));
    REQUIRE(r.layout["annotations"].size() == 2);
    for (const nlohmann::json& a : r.layout["annotations"]) {
      CAPTURE(a["name"].get<std::string>());
      const PixelBox png = ink_box(r.png, a["box"]);
      CHECK(!png.empty());
      CHECK(ink_distance(png, ink_box(r.svg, a["box"])) <= 1);
      CHECK(ink_distance(png, ink_box(r.pdf, a["box"])) <= 1);
    }
    const std::vector<std::string> texts = svg_texts(r.svg_file);
    CHECK(std::count(texts.begin(), texts.end(), "Brain") == 1);
    CHECK(r.pdf_text.find("Brain") != std::string::npos);
    // Every shown label's line in its box (and in the legend, unless shortened to fit), and the
    // legend's rows besides.
    const std::vector<std::string> lines = shown_lines(r.layout);
    for (const std::string& line : lines) {
      CAPTURE(line);
      CHECK(std::count(texts.begin(), texts.end(), line) >= 1);
    }
    CHECK(texts.size() > lines.size() + 1);
  }

  TEST_CASE("vector_stills_keep_hebrew_and_cjk_label_text_as_written") {
    const auto folder = test::fresh_folder("cli", "vector_bidi");
    // (Hebrew words, a Hebrew word inside left-to-right text, Chinese with Latin, a right-to-left
    // paragraph with a number and a unit)
    const std::filesystem::path scene = test::write_file(folder / "scene.json", R"({
      "strata_scene": 1, "labels": [
        {"id": 1, "text": "\u05d2\u05d9\u05d3\u05d5\u05dc \u05de\u05de\u05d0\u05d9\u05e8", "anchor": [0, 0, 0]},
        {"id": 2, "text": "\u6d77\u9a6c\u4f53 Hippocampus", "anchor": [30, 0, 20]},
        {"id": 3, "text": "Tumour \u05d2\u05d9\u05d3\u05d5\u05dc", "anchor": [-30, 0, -20]},
        {"id": 4, "text": "\u05d2\u05d9\u05d3\u05d5\u05dc 12 mm", "anchor": [30, 0, -20]}]})");
    const Rendered r = render_three(scene.string(), "", 256, folder);
    const InkDifference d = compare_ink(r);
    CHECK(d.labels == 4);
    CHECK(d.svg <= 1);
    CHECK(d.pdf <= 1);
    check_text_is_kept(r, {"\u05d2\u05d9\u05d3\u05d5\u05dc 12 mm"});
  }

  TEST_CASE("vector_stills_of_several_cameras_and_without_labels_are_named_as_images_are") {
    const auto folder = test::fresh_folder("cli", "vector_names");
    const std::string out = (folder / "out.svg").string();
    auto r = test::run_strata("render " + kHead + " --camera front,left --size 64 -o " + out);
    REQUIRE_MESSAGE(r.exit_code == 0, r.output);
    CHECK(std::filesystem::exists(folder / "out-front.svg"));
    CHECK(std::filesystem::exists(folder / "out-left.svg"));
    const std::string pdf = (folder / "bare.PDF").string();
    r = test::run_strata("render " + kHead + " --no-labels --size 64 -o " + pdf);
    REQUIRE_MESSAGE(r.exit_code == 0, r.output);
    CHECK(test::read_file(pdf).starts_with("%PDF-"));
    r = test::run_strata("render " + kHead + " --size 64 -o " + (folder / "x.eps").string());
    CHECK(r.exit_code == 2);
    CHECK(r.output.find(".png, .jpg, .jpeg, .svg or .pdf") != std::string::npos);
  }

  // The acceptance at 1024 pixels, by hand (--no-skip): the largest differences are reported.
  TEST_CASE("vector_stills_match_the_png_at_1024_pixels" * doctest::skip()) {
    for (const char* name : {"head", "head-100"}) {
      const auto folder = test::fresh_folder("cli", std::string("vector_1024_") + name);
      const Rendered r =
          render_three(STRATA_SOURCE_DIR "/assets/scenes/" + std::string(name) + ".json",
                       "--camera oblique", 1024, folder);
      const InkDifference d = compare_ink(r);
      MESSAGE(std::string(name) << ": " << d.labels << " shown labels, text ink within " << d.svg
                                << " px (SVG) and " << d.pdf << " px (PDF) of the PNG's");
      CHECK(d.svg <= 1);
      CHECK(d.pdf <= 1);
      check_text_is_kept(r);
    }
  }
}

TEST_SUITE("cpu") {
  TEST_CASE("svg_text_is_escaped_and_a_picture_alone_is_one_image") {
    const std::vector<uint8_t> rgba(4 * 2 * 2, 255);
    VectorPicture picture = image_picture(2, 2, rgba);
    auto font = std::make_shared<const Font>(14.0f);
    picture.groups.push_back(
        {0.5f, {VectorText{font, font->shape("a<b & \"c\"\x01"), {1.0f, 1.0f}, glm::vec4(1.0f)}}});
    const std::string svg = svg_document(picture);
    CHECK(svg.find("<image") != std::string::npos);
    CHECK(svg.find("<g opacity=\"0.5\">") != std::string::npos);
    CHECK(svg.find(">a&lt;b &amp; &quot;c&quot;\xEF\xBF\xBD</text>") != std::string::npos);
    CHECK(pdf_document(picture).starts_with("%PDF-"));
    CHECK(vector_format("x.SVG") == VectorFormat::svg);
    CHECK(!vector_format("x.png"));
  }
}

}  // namespace strata
