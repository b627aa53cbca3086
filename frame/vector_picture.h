// A still as a vector file: a list of drawn items (pictures, shapes, lines of text) in groups, each
// group drawn at its opacity, written as SVG (by hand: each line of text one <text> element that
// an editor can change and a search can find) or as PDF (cairo: the text as the label font's
// glyphs with their characters, so a reader can search and copy it). A labelled still's picture is
// the rendering without the label marks (LabellingSettings::marks off), with every drawn label's
// leader, box, picture, text and anchor mark over it, where and as the raster drawing draws them
// (shaders/shared/label_drawing.h). More items (a title, a legend, a background) are more groups.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include <glm/glm.hpp>

#include "engine/core/font.h"
#include "engine/core/png.h"
#include "engine/scene/scene.h"
#include "frame/labelled_render.h"
#include "labeling/annotations.h"

namespace strata {

// A picture stretched over a rectangle (pixels).
struct VectorImage {
  glm::vec2 origin{0.0f};
  glm::vec2 size{0.0f};
  Rgba8Image pixels;  // straight alpha
};

// A line, a box with rounded corners or a circle, filled, then stroked. Colours straight alpha;
// alpha 0: no fill or no stroke.
struct VectorShape {
  enum class Kind { line, box, circle };
  Kind kind = Kind::line;
  glm::vec2 a{0.0f};    // line: one end; box: its top-left corner; circle: its centre
  glm::vec2 b{0.0f};    // line: the other end; box: its size; circle: (radius, 0)
  float corner = 0.0f;  // box: the corners' radius
  glm::vec4 fill{0.0f};
  glm::vec4 stroke{0.0f};
  float stroke_width = 0.0f;
  bool round_caps = false;
  glm::vec2 dash{0.0f};      // on and off lengths; zero: solid
  float dash_offset = 0.0f;  // how far into the pattern `a` lies
};

// One line of text as the font shaped it, its glyphs at origin + pen (the raster puts each on
// whole pixels, glyph_origin: at most half a pixel apart).
struct VectorText {
  std::shared_ptr<const Font> font;  // (cairo draws its faces)
  ShapedLine line;
  glm::vec2 origin{0.0f};  // the line's start on its baseline
  glm::vec4 color{1.0f};
};

using VectorItem = std::variant<VectorImage, VectorShape, VectorText>;

// Items drawn one over the other, then the whole at `opacity` (a label fading in).
struct VectorGroup {
  float opacity = 1.0f;
  std::vector<VectorItem> items;
};

struct VectorPicture {
  uint32_t width = 0;  // pixels; a PDF page is as many points
  uint32_t height = 0;
  std::vector<VectorGroup> groups;  // in drawing order
};

enum class VectorFormat { svg, pdf };
// By `path`'s extension, case-insensitive: .svg, .pdf; none for another.
std::optional<VectorFormat> vector_format(const std::filesystem::path& path);

std::string svg_document(const VectorPicture& picture);
std::string pdf_document(const VectorPicture& picture);
// As vector_format(path) says, whole or not at all (engine/core/atomic_file.h); Error
// "<path>: <reason>".
void write_vector_picture(const std::filesystem::path& path, const VectorPicture& picture);

// The rgba8 picture alone.
VectorPicture image_picture(uint32_t width, uint32_t height, std::span<const uint8_t> rgba);

// The frame's picture (rendered with LabellingSettings::marks off) with its labels drawn over it
// as the raster drawing draws them: every label placed and not faded out, rear layers first, in
// label order within a layer, a rear label seen as far as what lies in front of it lets it
// through (`layers`: LabelledRenderer::download_layers, and the front labels' boxes; no layers:
// no content in front); then, on top, a rear label's connector dashed and its mark where the
// front hides them (label_behind). frame.labels[i] is scene.labels[i]; `settings` those it was
// rendered with (font, scale, wrap width, layer colours, internal labelling).
VectorPicture labelled_picture(const LabelledFrame& frame, const Scene& scene,
                               const LabellingSettings& settings,
                               std::span<const glm::vec4> layers = {});

// A title and a legend (labeling/annotations.h) over everything, as the raster draws them
// (labeling/annotation_drawing.h): boxes like the labels', colour swatches, lines of text.
void add_annotations(VectorPicture& picture, const AnnotationLayout& layout);

}  // namespace strata
