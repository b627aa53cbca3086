// The viewer's title and legend: laid out as stills and videos lay them out, kept free of labels
// with the panel, and drawn in Dear ImGui's background list (under the panel) in the label font.
#include <imgui.h>

#include "app/viewer/viewer.h"
#include "shared/label_drawing.h"

namespace strata::app {
namespace {

ImU32 colour(glm::vec4 c) {
  return ImGui::ColorConvertFloat4ToU32(ImVec4(c.x, c.y, c.z, c.w));
}

// A box as a label's: its fill, its border inside it.
void draw_box(ImDrawList* draw, glm::vec4 r) {
  draw->AddRectFilled(ImVec2(r.x, r.y), ImVec2(r.z, r.w), colour(gpu::LABEL_BOX_COLOR),
                      gpu::LABEL_BOX_RADIUS);
  draw->AddRect(ImVec2(r.x + 0.5f, r.y + 0.5f), ImVec2(r.z - 0.5f, r.w - 0.5f),
                colour(gpu::LABEL_BORDER_COLOR), gpu::LABEL_BOX_RADIUS, 0, gpu::LABEL_BORDER_WIDTH);
}

// (ImGui places text by its line's top: the baseline less the font's ascent)
void draw_text(ImDrawList* draw, const Font& font, const TextRun& run) {
  const float top = run.origin.y - font.ascent();
  draw->AddText(nullptr, run.font_pixels, ImVec2(run.origin.x, top), colour(run.colour),
                run.text.c_str());
}

}  // namespace

void Viewer::update_annotations(graph::Extent extent) {
  if (options_.title.empty() && !options_.legend) {
    annotations_.reset();
    annotation_layout_ = {};
    return;
  }
  const LabellingSettings& settings = labelled_->settings();
  std::string key = options_.title + '\n' + (options_.legend ? "legend" : "") + '\n' +
                    std::to_string(extent.width) + 'x' + std::to_string(extent.height) + '\n' +
                    std::to_string(settings.font_pixels * settings.label_scale);
  if (options_.legend) {
    for (const Label& label : scene_.labels) key += '\n' + label.text;
  }
  if (key == annotations_key_) return;
  annotations_key_ = key;
  annotations_ = std::make_unique<Annotations>(AnnotationOptions{options_.title, options_.legend},
                                               settings, glm::uvec2(extent.width, extent.height));
  annotation_layout_ = annotations_->layout(legend_entries(scene_));
}

void Viewer::draw_annotations() const {
  if (!annotations_) return;
  ImDrawList* draw = ImGui::GetBackgroundDrawList();
  if (const auto& title = annotation_layout_.title) {
    draw_box(draw, title->box.rect);
    draw_text(draw, annotations_->title, title->text);
  }
  if (const auto& legend = annotation_layout_.legend) {
    draw_box(draw, legend->box.rect);
    for (const LegendRow& row : legend->rows) {
      if (row.swatch) {
        const glm::vec4 s = *row.swatch;
        draw->AddRectFilled(ImVec2(s.x, s.y), ImVec2(s.z, s.w),
                            colour(glm::vec4(row.colour, 1.0f)));
        draw->AddRect(ImVec2(s.x, s.y), ImVec2(s.z, s.w), colour(gpu::LABEL_BORDER_COLOR));
      }
      draw_text(draw, annotations_->text, row.text);
    }
  }
}

}  // namespace strata::app
