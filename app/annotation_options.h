// --title and --legend (render, video, view): a picture's title and legend
// (labeling/annotations.h), set in the label font at the labels' scale, kept free of labels by
// the placement and the label motion, and drawn over stills and video frames.
#pragma once

#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "engine/core/font.h"
#include "engine/scene/scene.h"
#include "frame/labelled_render.h"
#include "labeling/annotations.h"

namespace strata::app {

struct AnnotationOptions {
  std::string title;
  bool legend = false;
  bool any() const { return !title.empty() || legend; }
};
void add_annotation_options(CLI::App* cmd, AnnotationOptions& o);

// What the annotations of one picture size are set in: the label font and the title's, at the
// labels' font size and scale.
struct Annotations {
  AnnotationSettings settings;
  glm::uvec2 size;
  Font text, title;

  Annotations(const AnnotationOptions& o, const LabellingSettings& labelling, glm::uvec2 image);
  AnnotationFonts fonts() const { return {text, title}; }
  AnnotationLayout layout(std::span<const LegendEntry> entries = {},
                          std::optional<glm::vec4> legend_room = std::nullopt) const;
  void draw(std::vector<uint8_t>& rgba, const AnnotationLayout& layout) const;
};

// The legend's rows, in the scene's order: every label of the scene (`frame` none), or those
// `frame` shows. A row's swatch is the label's colour (a segmentation region's); with
// `layer_colors` and a frame, its layer's border colour.
std::vector<LegendEntry> legend_entries(const Scene& scene, const LabelledFrame* frame = nullptr,
                                        bool layer_colors = false);

// A still with its annotations, placed by `run` (LabelledRenderer::run): first with the title's
// keep-out; with a legend, its room is sized for the labels that placement shows, in the corner
// where it covers the fewest anchors, kept free, and the still placed again; the legend lists the
// labels shown then, in that room. The frame's layout has their boxes; the caller draws `layout`
// (Annotations::draw on the picture, or add_annotations in a vector file).
struct AnnotatedStill {
  LabelledFrame frame;
  AnnotationLayout layout;
};
AnnotatedStill annotated_still(LabelledRenderer& renderer, Annotations& notes, const Scene& scene,
                               const std::function<void()>& run);

// `labelling` keeping its labels off `layout` (after `kept`, the viewer's panel) and recording
// its boxes in the frames' layouts.
void keep_labels_off(LabellingSettings& labelling, const AnnotationLayout& layout,
                     std::span<const glm::uvec4> kept = {});

}  // namespace strata::app
