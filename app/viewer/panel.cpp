// The viewer's Dear ImGui panel: every parameter of the labelling, the forces and the rendering,
// live; the labels; the camera's positions; timings and statistics; debug views.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <numeric>

#include <imgui.h>

#include "app/viewer/viewer.h"
#include "engine/core/error.h"
#include "engine/scene/scene_bounds.h"
#include "engine/scene/transfer_function_presets.h"
#include "labeling/insertion_order.h"

namespace strata::app {
namespace {

// The panel's changes are the commands scripts write (`set NAME VALUE`, `hide ID`, ...), applied
// before the frame is drawn (Viewer::submit).
void panel_command(Viewer& viewer, const std::vector<std::string>& words) {
  viewer.submit(viewer_command(words));
}

void submit_number(Viewer& viewer, const char* parameter, float value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", double(value));  // (a float's every digit)
  panel_command(viewer, {"set", parameter, text});
}

bool slider(Viewer& viewer, const char* label, const char* parameter, float value, float lo,
            float hi, const char* format = "%.3g", ImGuiSliderFlags flags = 0) {
  if (!ImGui::SliderFloat(label, &value, lo, hi, format, flags)) return false;
  submit_number(viewer, parameter, value);
  return true;
}

bool checkbox(Viewer& viewer, const char* label, const char* parameter, bool value) {
  if (!ImGui::Checkbox(label, &value)) return false;
  panel_command(viewer, {"set", parameter, value ? "on" : "off"});
  return true;
}

}  // namespace

void Viewer::build_panel() {
  const float scale = ui_.scale();
  ImGui::SetNextWindowPos(ImVec2(8.0f * scale, 8.0f * scale), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(360.0f * scale, float(output_.extent().height) - 16.0f * scale),
                           ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.85f);
  const bool open = ImGui::Begin("strata");
  // (labels are placed off the panel: its rectangle, collapsed or not, is the placement's keep-out)
  const ImVec2 at = ImGui::GetWindowPos(), size = ImGui::GetWindowSize();
  panel_ = glm::uvec4(glm::max(glm::vec4(at.x, at.y, at.x + size.x, at.y + size.y), 0.0f));
  if (!open) {
    ImGui::End();
    return;
  }
  ImGui::PushItemWidth(ImGui::GetWindowWidth() * 0.45f);  // the rest for the parameter names
  try {
    if (ImGui::Button("Screenshot (F12)")) screenshot();
    ImGui::SameLine();
    if (!recording()) {
      if (ImGui::Button("Record")) {
        const std::string stem = scene_.source.empty() ? "strata" : scene_.source.stem().string();
        std::filesystem::path path;
        for (int i = 1; path.empty() || std::filesystem::exists(path); ++i) {
          path = options_.screenshot_dir / (stem + "-" + std::to_string(i) + ".mp4");
        }
        start_recording(path);
      }
    } else if (ImGui::Button("Stop recording")) {
      stop_recording();
    }
    if (!message_.empty()) ImGui::TextWrapped("%s", message_.c_str());
    if (ImGui::CollapsingHeader("Camera", ImGuiTreeNodeFlags_DefaultOpen)) panel_camera();
    if (ImGui::CollapsingHeader("Labelling (eq. 3.1)", ImGuiTreeNodeFlags_DefaultOpen)) {
      panel_labelling();
    }
    if (ImGui::CollapsingHeader("Forces")) panel_forces();
    if (ImGui::CollapsingHeader("Labels")) panel_labels();
    if (ImGui::CollapsingHeader("Rendering")) panel_rendering();
    if (ImGui::CollapsingHeader("Cut-aways")) panel_cut_aways();
    if (ImGui::CollapsingHeader("Timings", ImGuiTreeNodeFlags_DefaultOpen)) panel_statistics();
    if (ImGui::CollapsingHeader("Debug views")) panel_debug();
  } catch (const Error& e) {
    message_ = e.what();  // a value the panel cannot apply: said in the panel, nothing changes
  }
  ImGui::PopItemWidth();
  if (ImGui::IsAnyItemActive()) ui_frames_ = std::max(ui_frames_, 2);  // a slider held
  ImGui::End();
}

void Viewer::panel_camera() {
  ImGui::TextDisabled("left drag rotate, right drag / wheel zoom,");
  ImGui::TextDisabled("middle or shift+left drag pan, arrows, r reset");
  for (size_t i = 0; i < scene_.camera_positions.size(); ++i) {
    const std::string label = (i < 9 ? std::to_string(i + 1) + ": " : std::string("   ")) +
                              scene_.camera_positions[i].name;
    if (ImGui::Selectable(label.c_str(), false)) jump_to_position(i);
  }
  for (int v = 0; v < 6; ++v) {
    if (v % 3 != 0) ImGui::SameLine();
    if (ImGui::Button(kAnatomicalViewNames[v]))
      panel_command(*this, {"view", kAnatomicalViewNames[v]});
  }
  if (ImGui::Button("Reset (r)")) panel_command(*this, {"key", "r"});
  ImGui::SetNextItemWidth(140.0f * ui_.scale());
  ImGui::InputTextWithHint("##name", "position name", position_name_, sizeof position_name_);
  ImGui::SameLine();
  if (ImGui::Button("Save position")) {
    save_position(position_name_);
    position_name_[0] = '\0';
  }
}

void Viewer::panel_labelling() {
  const LabellingSettings s = labelled_->settings();
  const CostWeights& w = s.placement.weights;
  const ImGuiSliderFlags log = ImGuiSliderFlags_Logarithmic;
  slider(*this, "label shadow", "weights.label_shadow", w.label_shadow, 1.0f, 1e7f, "%.3g", log);
  slider(*this, "anchor constraint", "weights.anchor_constraint", w.anchor_constraint, 1.0f, 1e8f,
         "%.3g", log);
  slider(*this, "connector shadow", "weights.connector_shadow", w.connector_shadow, 0.0f, 1e4f,
         "%.3g", log);
  slider(*this, "leader crossing", "weights.leader_crossing", w.leader_crossing, 0.0f, 1e5f, "%.3g",
         log);
  slider(*this, "illegible box", "weights.illegible", w.illegible, 0.0f, 1e6f, "%.3g", log);
  slider(*this, "integral costs", "weights.integral_costs", w.integral_costs, 0.0f, 1000.0f, "%.3g",
         log);
  slider(*this, "distance to anchor", "weights.distance_to_anchor", w.distance_to_anchor, 0.0f,
         1.0f, "%.4f", log);
  slider(*this, "connector direction", "weights.connector_direction", w.connector_direction, 0.0f,
         100.0f, "%.3g", log);
  slider(*this, "previous position (eta)", "weights.previous_position", s.forces.previous_weight,
         0.0f, 20.0f);
  ImGui::Separator();
  ImGui::TextDisabled("integral costs (eq. 3.3, 3.4)");
  slider(*this, "saliency", "integral.saliency", s.placement.saliency_weight, 0.0f, 1.0f);
  slider(*this, "occlusion (1 layer)", "integral.occlusion", s.placement.occlusion_weight, 0.0f,
         1.0f);
  slider(*this, "saliency (1 layer)", "integral.single_saliency",
         s.placement.single_saliency_weight, 0.0f, 1.0f);
  ImGui::Separator();
  slider(*this, "margin (text sizes)", "margin_em", s.placement.margin_em, 0.0f, 2.0f, "%.2f");
  int layers = int(s.layer_count);
  if (ImGui::SliderInt("layers", &layers, 1, 8)) submit_number(*this, "layers", float(layers));
  ImGui::Text("layers used: %u", labelled_->layering().layer_count);
  int tidy_rounds = int(s.placement.tidy_rounds);
  if (ImGui::SliderInt("tidy-up rounds", &tidy_rounds, 0, 64)) {
    submit_number(*this, "tidy_rounds", float(tidy_rounds));
  }
  const char* orders[] = {"scene", "Apollonius (when the camera rests)"};
  if (ImGui::Combo("insertion order", &insertion_order_, orders, 2)) {
    labelled_->set_order(scene_order(uint32_t(scene_.labels.size())));
    changed();
  }
  checkbox(*this, "optimise on idle (random orders)", "optimize", options_.optimize_on_idle);
  ImGui::Text("orders tried %llu, adopted %llu", static_cast<unsigned long long>(summary_.trials),
              static_cast<unsigned long long>(summary_.adopted));
  checkbox(*this, "hard constraints", "hard", s.placement.hard);
  checkbox(*this, "internal labelling", "internal", s.internal);
  checkbox(*this, "legend", "legend", options_.legend);
  checkbox(*this, "borders in layer colours", "layer_colors", s.layer_colors);
  float ghost = s.ghost.strength;
  ImGui::SliderFloat("ghosting", &ghost, 0.0f, 1.0f, "%.2f");
  if (ImGui::IsItemDeactivatedAfterEdit()) submit_number(*this, "ghost", ghost);
  float lens = s.ghost.radius;
  ImGui::SliderFloat("ghosting lens", &lens, kGhostRadiusMin, kGhostRadiusMax, "%.3f");
  if (ImGui::IsItemDeactivatedAfterEdit()) submit_number(*this, "ghost.radius", lens);
  // (applied when the slider is let go: the glyphs and the graph are rebuilt)
  float font = s.font_pixels;
  ImGui::SliderFloat("font size (px)", &font, 8.0f, 40.0f, "%.0f");
  if (ImGui::IsItemDeactivatedAfterEdit()) submit_number(*this, "font", font);
  float scale = s.label_scale;
  ImGui::SliderFloat("label scale", &scale, 0.25f, 4.0f, "%.2f");
  if (ImGui::IsItemDeactivatedAfterEdit()) submit_number(*this, "label_scale", scale);
}

void Viewer::panel_forces() {
  const ForceSettings f = labelled_->settings().forces;
  checkbox(*this, "held as anchor offsets (off: on screen)", "forces.anchor_relative",
           f.anchor_relative);
  slider(*this, "speed (widths/s)", "forces.speed_widths", f.speed_widths, 0.005f, 2.0f, "%.3f",
         ImGuiSliderFlags_Logarithmic);
  slider(*this, "epsilon (widths)", "forces.epsilon_widths", f.epsilon_widths, 0.001f, 0.1f, "%.4f",
         ImGuiSliderFlags_Logarithmic);
  slider(*this, "ease-in (s)", "forces.ease_in", f.ease_in_seconds, 0.0f, 2.0f, "%.2f");
  slider(*this, "snap (px)", "forces.snap", f.snap, 0.0f, 5.0f, "%.2f");
  slider(*this, "hold: share of cost", "forces.hold_share", f.hold_share, 0.0f, 4.0f);
  slider(*this, "hold: fixed", "forces.hold_cost", f.hold_cost, 0.0f, 50.0f);
  slider(*this, "fade (s)", "forces.fade", f.fade_seconds, 0.0f, 2.0f, "%.2f");
  checkbox(*this, "keep drawn labels apart", "forces.keep_apart", f.keep_apart);
  slider(*this, "wait (s)", "forces.wait", f.wait_seconds, 0.0f, 2.0f, "%.2f");
}

void Viewer::panel_labels() {
  ImGui::InputTextWithHint("##filter", "search", label_filter_, sizeof label_filter_);
  std::string filter = label_filter_;
  std::transform(filter.begin(), filter.end(), filter.begin(), ::tolower);
  if (ImGui::BeginChild("labels", ImVec2(0.0f, 200.0f * ui_.scale()), true)) {
    for (size_t i = 0; i < scene_.labels.size(); ++i) {
      const Label& l = scene_.labels[i];
      std::string text = l.text;
      std::transform(text.begin(), text.end(), text.begin(), ::tolower);
      if (!filter.empty() && text.find(filter) == std::string::npos) continue;
      ImGui::PushID(int(i));
      bool shown = !labelled_->label_hidden(i);
      if (ImGui::Checkbox("##shown", &shown))
        panel_command(*this, {shown ? "show" : "hide", std::to_string(l.id)});
      ImGui::SameLine();
      if (ImGui::Selectable(l.text.c_str(), picked_label_ == int(i))) {
        picked_label_ = int(i);
        std::snprintf(edit_text_, sizeof edit_text_, "%s", l.text.c_str());
      }
      ImGui::PopID();
    }
  }
  ImGui::EndChild();
  if (ImGui::Button("Show all")) {
    for (const Label& l : scene_.labels) panel_command(*this, {"show", std::to_string(l.id)});
  }
  // Labels of one's own: place mode, the selected label's text, delete, undo, redo, save.
  bool placing = place_mode_;
  if (ImGui::Checkbox("Place labels (P)", &placing)) set_place_mode(placing);
  if (picked_label_ >= 0 && size_t(picked_label_) < scene_.labels.size()) {
    const int id = scene_.labels[size_t(picked_label_)].id;
    if (ImGui::InputText("text", edit_text_, sizeof edit_text_,
                         ImGuiInputTextFlags_EnterReturnsTrue) &&
        edit_text_[0] != '\0') {
      panel_command(*this, {"text", std::to_string(id), edit_text_});
    }
    if (ImGui::Button("Delete")) {
      panel_command(*this, {"delete", std::to_string(id)});
      picked_label_ = -1;
    }
    ImGui::SameLine();
  }
  ImGui::BeginDisabled(!history_.can_undo());
  if (ImGui::Button("Undo")) panel_command(*this, {"undo"});
  ImGui::EndDisabled();
  ImGui::SameLine();
  ImGui::BeginDisabled(!history_.can_redo());
  if (ImGui::Button("Redo")) panel_command(*this, {"redo"});
  ImGui::EndDisabled();
  ImGui::SameLine();
  if (ImGui::Button("Save labels (Ctrl+S)"))
    panel_command(*this, {"save", default_labels_path().string()});
}

void Viewer::panel_rendering() {
  for (size_t v = 0; v < scene_.volumes.size(); ++v) {
    ImGui::PushID(int(v));
    ImGui::TextUnformatted(scene_.volumes[v].name.c_str());
    VolumeLook& look = looks_[v];
    if (ImGui::BeginCombo("preset", original_tfs_[v].name.c_str())) {
      for (const TransferFunctionPreset& p : transfer_function_presets()) {
        if (ImGui::Selectable(p.name, original_tfs_[v].name == p.name))
          panel_command(*this, {"preset", p.name, std::to_string(v)});
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", p.description);
      }
      ImGui::EndCombo();
    }
    // Level and window in the volume's own values (Hounsfield units for CT), as radiology sets
    // them.
    const glm::vec2 range = scene_.volumes[v].value_range;
    const float span = std::max(range.y - range.x, 1e-6f);
    bool edited = ImGui::SliderFloat("level", &look.level, range.x, range.y, "%.5g");
    edited |= ImGui::SliderFloat("window", &look.window, 0.01f * span, 2.0f * span, "%.5g");
    look.window = std::max(look.window, 0.01f * span);
    edited |= ImGui::SliderFloat("opacity", &look.opacity, 0.0f, 4.0f, "%.2f");
    if (ImGui::Button("Reset")) {
      look = default_look(scene_.volumes[v]);
      edited = true;
    }
    if (edited) set_transfer(uint32_t(v));
    ImGui::PopID();
  }
  const RenderSettings& r = labelled_->renderer().settings();
  slider(*this, "sampling step (0: auto)", "render.step", r.step, 0.0f, 4.0f, "%.3f");
  checkbox(*this, "empty-space skipping", "render.skip_empty", r.skip_empty);
}

void Viewer::panel_statistics() {
  const auto plot = [](const char* label, const std::deque<float>& values) {
    if (values.empty()) return;
    const std::vector<float> v(values.begin(), values.end());
    const float top = *std::max_element(v.begin(), v.end());
    char overlay[64];
    std::snprintf(overlay, sizeof overlay, "%.2f ms", double(v.back()));
    ImGui::PlotLines(label, v.data(), int(v.size()), 0, overlay, 0.0f, top * 1.1f,
                     ImVec2(0.0f, 40.0f));
  };
  plot("frame", frame_times_);
  plot("GPU", gpu_times_);
  std::map<std::string, double> groups;
  for (const graph::PassTiming& t : last_timings_) {
    groups[t.group.empty() ? t.name : t.group] += t.ms;
  }
  for (const auto& [name, ms] : groups) ImGui::Text("%-12s %7.3f ms", name.c_str(), ms);
  const RenderStats& s = labelled_->stats();
  ImGui::Text("HA-Buffer: %u fragments, load %.2f, overflow %u", s.fragments, s.load_factor(),
              s.overflow);
  ImGui::Text("frames %llu, %s", static_cast<unsigned long long>(summary_.frames),
              settled_ ? "settled" : "moving");
}

void Viewer::panel_debug() {
  const char* views[] = {
      "off",         "saliency",           "integral costs", "constraints (picked label)",
      "layer image", "HA-Buffer fragments"};
  int mode = debug_choice_ ? int(debug_choice_->buffer) + 1 : 0;
  if (ImGui::Combo("show", &mode, views, 6)) {
    if (mode == 0) {
      debug_choice_.reset();
    } else {
      DebugViewChoice c = debug_choice_.value_or(DebugViewChoice{});
      c.buffer = DebugBuffer(mode - 1);
      c.scale = default_scale(c.buffer);
      debug_choice_ = c;
    }
    ui_event();
  }
  if (!debug_choice_) return;
  int layer = int(debug_choice_->layer);
  if (ImGui::SliderInt("layer", &layer, 0, int(labelled_->layering().layer_count) - 1)) {
    debug_choice_->layer = uint32_t(layer);
  }
  ImGui::SliderFloat("scale", &debug_choice_->scale, 1e-3f, 100.0f, "%.3g",
                     ImGuiSliderFlags_Logarithmic);
  const size_t picked =
      std::min(size_t(std::max(0, picked_label_)), std::max<size_t>(scene_.labels.size(), 1) - 1);
  debug_choice_->label = uint32_t(picked);
  if (!scene_.labels.empty()) {
    ImGui::Text("picked label: %s (Labels list)", scene_.labels[picked].text.c_str());
  }
}

}  // namespace strata::app
