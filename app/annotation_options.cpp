#include "app/annotation_options.h"

#include <tuple>
#include <unordered_map>

#include "labeling/annotation_drawing.h"
#include "shared/label_drawing.h"

namespace strata::app {

void add_annotation_options(CLI::App* cmd, AnnotationOptions& o) {
  cmd->add_option("--title", o.title,
                  "a title centred along the top of the picture, in a box as the labels' (labels "
                  "keep off it)");
  cmd->add_flag("--legend", o.legend,
                "a legend in a corner: the labels (a still: those it shows; a video, the viewer: "
                "all the scene's), each with its colour where it has one; labels keep off it");
}

Annotations::Annotations(const AnnotationOptions& o, const LabellingSettings& labelling,
                         glm::uvec2 image)
    : size(image),
      text(labelling.font_pixels * labelling.label_scale),
      title(labelling.font_pixels * labelling.label_scale * AnnotationSettings{}.title_scale) {
  settings.title = o.title;
  settings.legend = o.legend;
  settings.style = TextStyle{}.scaled(labelling.label_scale);
}

AnnotationLayout Annotations::layout(std::span<const LegendEntry> entries,
                                     std::optional<glm::vec4> legend_room) const {
  return layout_annotations(fonts(), settings, size, entries, legend_room);
}

void Annotations::draw(std::vector<uint8_t>& rgba, const AnnotationLayout& layout) const {
  draw_annotations(rgba, size, layout, fonts());
}

std::vector<LegendEntry> legend_entries(const Scene& scene, const LabelledFrame* frame,
                                        bool layer_colors) {
  std::vector<LegendEntry> out;
  if (!frame) {
    for (const Label& label : scene.labels) out.push_back({label.text, label.colour});
    return out;
  }
  std::unordered_map<int, const Label*> by_id;
  for (const Label& label : scene.labels) by_id.emplace(label.id, &label);
  for (const LabelLayout& l : frame->labels) {
    if (!l.shown) continue;
    const auto it = by_id.find(l.id);
    std::optional<glm::vec3> colour = it != by_id.end() ? it->second->colour : std::nullopt;
    if (layer_colors) {
      const gpu::vec4 c = gpu::label_border_color(l.layer, true);
      colour = glm::vec3(c.x, c.y, c.z);
    }
    out.push_back({l.text, colour});
  }
  return out;
}

namespace {

// The corner whose legend covers the fewest anchors of `frame` (the first such in
// LegendCorner's order): a legend box over an anchor dims its mark.
LegendCorner emptiest_corner(Annotations& notes, std::span<const LegendEntry> entries,
                             const LabelledFrame& frame) {
  LegendCorner best = LegendCorner::bottom_right;
  size_t fewest = SIZE_MAX;
  for (const LegendCorner corner : {LegendCorner::bottom_right, LegendCorner::bottom_left,
                                    LegendCorner::top_right, LegendCorner::top_left}) {
    notes.settings.corner = corner;
    const AnnotationLayout layout = notes.layout(entries);
    if (!layout.legend) continue;
    const glm::vec4 r = layout.legend->box.rect;
    size_t covered = 0;
    for (const LabelLayout& l : frame.labels) {
      covered += l.anchor.x >= r.x && l.anchor.x < r.z && l.anchor.y >= r.y && l.anchor.y < r.w;
    }
    if (covered < fewest) {
      fewest = covered;
      best = corner;
    }
  }
  return best;
}

// The still placed with the legend's room kept free: its frame, and the legend of the labels it
// shows in that room.
std::pair<LabelledFrame, AnnotationLayout> placed_beside_legend(
    LabelledRenderer& renderer, const Annotations& notes, const Scene& scene, glm::vec4 room,
    const std::vector<LegendEntry>& entries, const std::function<void()>& run) {
  LabellingSettings& settings = renderer.settings();
  keep_labels_off(settings, notes.layout(entries, room));
  run();
  LabelledFrame frame = renderer.result();
  AnnotationLayout layout =
      notes.layout(legend_entries(scene, &frame, settings.layer_colors), room);
  frame.annotations = layout.boxes();
  return {std::move(frame), std::move(layout)};
}

}  // namespace

AnnotatedStill annotated_still(LabelledRenderer& renderer, Annotations& notes, const Scene& scene,
                               const std::function<void()>& run) {
  LabellingSettings& settings = renderer.settings();
  AnnotationLayout layout = notes.layout();
  keep_labels_off(settings, layout);
  run();
  LabelledFrame frame = renderer.result();
  if (notes.settings.legend) {
    const std::vector<LegendEntry> first = legend_entries(scene, &frame, settings.layer_colors);
    notes.settings.corner = emptiest_corner(notes, first, frame);
    layout = notes.layout(first);
    if (layout.legend) {
      // The room the labels shown first need; placed off it, fewer may be shown. Then once in
      // the room those need, kept where the legend there lists every label shown.
      const glm::vec4 first_room = layout.legend->box.rect;
      std::tie(frame, layout) =
          placed_beside_legend(renderer, notes, scene, first_room, first, run);
      if (layout.legend && layout.legend->box.rect != first_room) {
        const glm::vec4 room = layout.legend->box.rect;
        auto [smaller, smaller_layout] =
            placed_beside_legend(renderer, notes, scene, room,
                                 legend_entries(scene, &frame, settings.layer_colors), run);
        if (smaller_layout.legend &&
            smaller_layout.legend->listed == smaller_layout.legend->rows.size()) {
          frame = std::move(smaller);
          layout = std::move(smaller_layout);
        }
      }
    }
  }
  return {std::move(frame), std::move(layout)};
}

void keep_labels_off(LabellingSettings& labelling, const AnnotationLayout& layout,
                     std::span<const glm::uvec4> kept) {
  labelling.placement.keep_out.assign(kept.begin(), kept.end());
  labelling.placement.keep_out.insert(labelling.placement.keep_out.end(), layout.keep_out.begin(),
                                      layout.keep_out.end());
  labelling.annotations = layout.boxes();
}

}  // namespace strata::app
