// The parameters the panel and scripts set (`set NAME VALUE`), with their ranges, and the
// volumes' looks: presets, level, window and opacity.
#include "app/viewer/viewer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "app/viewer/parameters.h"
#include "engine/core/error.h"
#include "engine/scene/transfer_function_presets.h"

namespace strata::app {
namespace {

// A transfer function seen through a window of intensities: the function's [0, 1] spread over
// [level - window / 2, level + window / 2] (shares of the value range), its opacity times
// `opacity`.
TransferFunction windowed(const TransferFunction& tf, float level, float window, float opacity) {
  TransferFunction out = tf;
  for (auto& stop : out.stops) {
    stop.position = level - 0.5f * window + stop.position * window;
    stop.color.a = std::clamp(stop.color.a * opacity, 0.0f, 1.0f);
  }
  return out;
}

// The function `volume` is drawn with under `look` (level and window in its values), in 0..1 of
// its value range as the renderer takes it.
TransferFunction looked(const TransferFunction& tf, const Volume& volume, float level, float window,
                        float opacity) {
  const float lo = volume.value_range.x, span = std::max(volume.value_range.y - lo, 1e-6f);
  return windowed(tf, (level - lo) / span, window / span, opacity);
}

float parse_float(const std::string& name, const std::string& value) {
  try {
    size_t used = 0;
    const float v = std::stof(value, &used);
    if (used == value.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw Error("parameter " + name + ": '" + value + "' is not a number");
}

bool parse_bool(const std::string& name, const std::string& value) {
  if (value == "1" || value == "true" || value == "on") return true;
  if (value == "0" || value == "false" || value == "off") return false;
  throw Error("parameter " + name + ": '" + value + "' is not on or off");
}

// Where a panel or script parameter lives: a number or a flag of the labelling, rendering or
// viewer settings. `layers` (a count) and `font` (a font rebuild) are set by hand.
struct SettingsRef {
  LabellingSettings& labels;
  RenderSettings& render;
  ViewerOptions& viewer;
};

// A parameter: a number in [lo, hi] or (with `flag`) on or off. The ranges keep a frame's work
// bounded (render.step has a lower bound from the volumes too: Viewer::set_number) and hold the
// panel's slider ranges (app/viewer/panel.cpp).
struct Parameter {
  const char* name;
  const char* what;
  float lo = 0.0f, hi = 0.0f;
  float* (*number)(const SettingsRef&) = nullptr;
  bool* (*flag)(const SettingsRef&) = nullptr;
  bool reproject = false;  // the anchors are projected and layered again
};

const std::vector<Parameter>& parameters() {
  using S = const SettingsRef&;
  constexpr float kMaxWeight = 1e9f;
  static const std::vector<Parameter> all = {
      {"weights.label_shadow", "eq. 3.1: a box over an earlier box or its leader", 0.0f, kMaxWeight,
       [](S s) { return &s.labels.placement.weights.label_shadow; }},
      {"weights.anchor_constraint", "eq. 3.1: a box or leader over an anchor", 0.0f, kMaxWeight,
       [](S s) { return &s.labels.placement.weights.anchor_constraint; }},
      {"weights.connector_shadow", "eq. 3.1: a leader over an earlier box or leader", 0.0f,
       kMaxWeight, [](S s) { return &s.labels.placement.weights.connector_shadow; }},
      {"weights.leader_crossing", "tidy-up: a leader crossing a leader or through a box", 0.0f,
       kMaxWeight, [](S s) { return &s.labels.placement.weights.leader_crossing; }},
      {"weights.illegible", "a box the layers in front hide (hard mode: never)", 0.0f, kMaxWeight,
       [](S s) { return &s.labels.placement.weights.illegible; }},
      {"weights.integral_costs", "eq. 3.1: the occlusion and saliency under the box", 0.0f,
       kMaxWeight, [](S s) { return &s.labels.placement.weights.integral_costs; }},
      {"weights.distance_to_anchor", "eq. 3.1: leader length", 0.0f, kMaxWeight,
       [](S s) { return &s.labels.placement.weights.distance_to_anchor; }},
      {"weights.connector_direction", "eq. 3.1: connector direction", 0.0f, kMaxWeight,
       [](S s) { return &s.labels.placement.weights.connector_direction; }},
      {"weights.previous_position", "eq. 3.1 eta: per pixel of distance to the last target", 0.0f,
       1e6f, [](S s) { return &s.labels.forces.previous_weight; }},
      {"integral.saliency", "eq. 3.3: how much saliency modulates occlusion", 0.0f, 1.0f,
       [](S s) { return &s.labels.placement.saliency_weight; }},
      {"integral.occlusion", "eq. 3.4: occlusion weight with one layer", 0.0f, 1.0f,
       [](S s) { return &s.labels.placement.occlusion_weight; }},
      {"integral.single_saliency", "eq. 3.4: saliency weight with one layer", 0.0f, 1.0f,
       [](S s) { return &s.labels.placement.single_saliency_weight; }},
      {"margin_em", "label text sizes around boxes in the constraints", 0.0f, 16.0f,
       [](S s) { return &s.labels.placement.margin_em; }},
      {"layers", "depth layers asked for, 1 to 8", 1.0f, 8.0f},
      {"tidy_rounds", "rounds of the tidy-up per frame, 0 to 256", 0.0f, float(TIDY_ROUNDS_MAX)},
      {"hard", "on: no constraint violations (labels may be hidden)", 0.0f, 0.0f, nullptr,
       [](S s) { return &s.labels.placement.hard; }},
      {"internal", "on: each label on its anchor", 0.0f, 0.0f, nullptr,
       [](S s) { return &s.labels.internal; }, true},
      {"font", "label font size in pixels, 4 to 128", 4.0f, 128.0f},
      {"label_scale", "label text and boxes times this (0.25 to 4)", 0.25f, 4.0f},
      {"layer_colors", "on: label borders in their layer's colour", 0.0f, 0.0f, nullptr,
       [](S s) { return &s.labels.layer_colors; }},
      // (ghosting on or off changes the graph: set_camera rebuilds it)
      {"ghost", "ghosting: how far the layers in front of a rear anchor open, 0 (off) to 1", 0.0f,
       1.0f, [](S s) { return &s.labels.ghost.strength; }, nullptr, true},
      {"ghost.radius", "the ghosting lens, a share of the picture's shorter side", kGhostRadiusMin,
       kGhostRadiusMax, [](S s) { return &s.labels.ghost.radius; }},
      {"ghost.leaders", "the lens along rear connectors, a share of the shorter side (0: none)",
       0.0f, kGhostRadiusMax, [](S s) { return &s.labels.ghost.leader; }},
      // (speed / epsilon bounds the force steps of a frame: at most 5,000 in a 0.25 s frame)
      {"forces.speed_widths", "image widths per second at full force", 0.001f, 10.0f,
       [](S s) { return &s.labels.forces.speed_widths; }},
      {"forces.epsilon_widths", "image widths: nearer than this the force shrinks", 0.0005f, 1.0f,
       [](S s) { return &s.labels.forces.epsilon_widths; }},
      {"forces.ease_in", "seconds a label takes to get up to full speed", 0.0f, 10.0f,
       [](S s) { return &s.labels.forces.ease_in_seconds; }},
      {"forces.snap", "pixels: nearer than this a label lands on its target", 0.0f, 100.0f,
       [](S s) { return &s.labels.forces.snap; }},
      {"forces.hold_share", "hold: this share of the target's cost ...", 0.0f, 100.0f,
       [](S s) { return &s.labels.forces.hold_share; }},
      {"forces.hold_cost", "... plus this", 0.0f, kMaxWeight,
       [](S s) { return &s.labels.forces.hold_cost; }},
      {"forces.fade", "seconds a label takes to fade in or out", 0.0f, 60.0f,
       [](S s) { return &s.labels.forces.fade_seconds; }},
      {"forces.anchor_relative", "on: labels held as offsets from their anchors", 0.0f, 0.0f,
       nullptr, [](S s) { return &s.labels.forces.anchor_relative; }},
      {"forces.keep_apart", "on: drawn labels never overlap or leave the image", 0.0f, 0.0f,
       nullptr, [](S s) { return &s.labels.forces.keep_apart; }},
      {"forces.wait", "seconds a label whose way is taken waits before it fades out", 0.0f, 60.0f,
       [](S s) { return &s.labels.forces.wait_seconds; }},
      {"optimize", "on: try random insertion orders when the camera rests", 0.0f, 0.0f, nullptr,
       [](S s) { return &s.viewer.optimize_on_idle; }},
      {"legend", "on: a legend of the scene's labels in the bottom-right corner", 0.0f, 0.0f,
       nullptr, [](S s) { return &s.viewer.legend; }},
      {"render.step",
       "world units between ray samples (0: half the finest voxel; else at least a sixteenth of "
       "it)",
       0.0f, 1000.0f, [](S s) { return &s.render.step; }},
      {"render.skip_empty", "on: empty-space skipping", 0.0f, 0.0f, nullptr,
       [](S s) { return &s.render.skip_empty; }},
  };
  return all;
}

const Parameter& parameter(const std::string& name) {
  for (const Parameter& p : parameters()) {
    if (name == p.name) return p;
  }
  // Pixels once; now relative to the image's width or to the label text's size.
  static const std::pair<const char*, const char*> renamed[] = {
      {"margin", "margin_em (label text sizes: 6 px at a 14 px font is 0.43)"},
      {"forces.speed",
       "forces.speed_widths (image widths per second: 90 px/s at 1024 px is 0.088)"},
      {"forces.epsilon", "forces.epsilon_widths (image widths: 24 px at 1024 px is 0.0234)"}};
  for (const auto& [old_name, now] : renamed) {
    if (name == old_name) throw Error("parameter " + name + " (pixels) is now " + now);
  }
  std::string names;
  for (const Parameter& p : parameters())
    names += (names.empty() ? "" : ", ") + std::string(p.name);
  throw Error("no parameter '" + name + "' (parameters: " + names + ")");
}

std::string number_text(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

// The value in the parameter's range (a whole number for layers and tidy_rounds), else an Error
// naming the parameter and its range.
void check_range(const Parameter& p, float value) {
  const bool whole =
      std::string_view(p.name) == "layers" || std::string_view(p.name) == "tidy_rounds";
  if (std::isfinite(value) && value >= p.lo && value <= p.hi &&
      (!whole || value == std::floor(value))) {
    return;
  }
  throw Error("parameter " + std::string(p.name) + ": " + number_text(value) + " is not " +
              (whole ? "a whole number" : "a number") + " in [" + number_text(p.lo) + ", " +
              number_text(p.hi) + "]");
}

}  // namespace

void check_viewer_parameter(const std::string& name, const std::string& value) {
  const Parameter& p = parameter(name);
  if (p.flag) {
    parse_bool(name, value);
  } else {
    check_range(p, parse_float(name, value));
  }
}

std::vector<std::pair<std::string, std::string>> viewer_parameters() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Parameter& p : parameters()) out.emplace_back(p.name, p.what);
  return out;
}

void Viewer::set_parameter(const std::string& name, const std::string& value) {
  if (parameter(name).flag) {
    set_flag(name, parse_bool(name, value));
  } else {
    set_number(name, parse_float(name, value));
  }
}

void Viewer::set_number(const std::string& name, float value) {
  const Parameter& p = parameter(name);
  if (p.flag) throw Error("parameter " + name + " is on or off, not a number");
  check_range(p, value);
  if (name == "font" || name == "label_scale") {  // (the renderer checks the value)
    if (name == "font") {
      labelled_->set_font_pixels(value);
    } else {
      labelled_->set_label_scale(value);
    }
    settings_changed(false);
    return;
  }
  // Copies first: a value that the checks refuse changes nothing.
  LabellingSettings labels = labelled_->settings();
  RenderSettings render = labelled_->renderer().settings();
  ViewerOptions viewer = options_;
  if (name == "layers") {
    labels.layer_count = uint32_t(value);
  } else if (name == "tidy_rounds") {
    labels.placement.tidy_rounds = uint32_t(value);
  } else {
    // A step far below the voxels multiplies a frame's samples without showing more.
    const float finest = labelled_->renderer().inputs().finest_spacing;
    if (name == "render.step" && value != 0.0f && value < finest / 16.0f) {
      throw Error("parameter render.step: " + number_text(value) + " is below " +
                  number_text(finest / 16.0f) +
                  ", a sixteenth of the finest voxel spacing (0: half of it)");
    }
    *p.number({labels, render, viewer}) = value;
  }
  commit_settings(labels, render, viewer, p.reproject || name == "layers");
}

void Viewer::set_flag(const std::string& name, bool value) {
  const Parameter& p = parameter(name);
  if (!p.flag) throw Error("parameter " + name + " is a number, not on or off");
  LabellingSettings labels = labelled_->settings();
  RenderSettings render = labelled_->renderer().settings();
  ViewerOptions viewer = options_;
  *p.flag({labels, render, viewer}) = value;
  commit_settings(labels, render, viewer, p.reproject);
}

void Viewer::commit_settings(const LabellingSettings& labels, const RenderSettings& render,
                             const ViewerOptions& viewer, bool reproject) {
  forces_params(labels.forces, labelled_->units(), 1, 0.0,
                labels.placement.hard);  // (throws on a bad force)
  labelled_->settings() = labels;
  labelled_->renderer().settings() = render;
  options_ = viewer;
  settings_changed(reproject);
}

void Viewer::settings_changed(bool reproject) {
  if (reproject) labelled_->set_camera(control_.camera());
  labelled_->place_afresh();  // the new settings' layout, reached smoothly
  changed();
}

void Viewer::set_preset(uint32_t volume, const std::string& name) {
  if (volume >= scene_.volumes.size()) {
    throw Error("no volume " + std::to_string(volume) + " (the scene has " +
                std::to_string(scene_.volumes.size()) + ")");
  }
  original_tfs_[volume] = make_transfer_function_preset(name, scene_.volumes[volume]);
  scene_.volumes[volume].preset = name;
  scene_.volumes[volume].window.reset();
  scene_.volumes[volume].look_edited = true;
  set_transfer(volume);
  message_ = "volume '" + scene_.volumes[volume].name + "': preset " + name;
}

void Viewer::set_window(uint32_t volume, float level, float window) {
  if (volume >= scene_.volumes.size()) {
    throw Error("no volume " + std::to_string(volume) + " (the scene has " +
                std::to_string(scene_.volumes.size()) + ")");
  }
  const Volume& v = scene_.volumes[volume];
  const float span = std::max(v.value_range.y - v.value_range.x, 1e-6f);
  looks_[volume].level = level;
  looks_[volume].window = std::clamp(window, 0.01f * span, 2.0f * span);
  set_transfer(volume);
}

Viewer::VolumeLook Viewer::default_look(const Volume& volume) {
  const glm::vec2 range = volume.value_range;
  return {0.5f * (range.x + range.y), std::max(range.y - range.x, 1e-6f), 1.0f};
}

void Viewer::set_transfer(uint32_t volume) {
  const VolumeLook& look = looks_[volume];
  Volume& v = scene_.volumes[volume];
  const TransferFunction tf =
      looked(original_tfs_[volume], v, look.level, look.window, look.opacity);
  // What a saved scene writes (scene_writer.cpp, in the volume's values): a preset by its name
  // while the look is its own, else the function as drawn.
  const VolumeLook plain = default_look(v);
  const bool own = look.level == plain.level && look.window == plain.window && look.opacity == 1.0f;
  if (v.transfer_function >= 0) {
    scene_.transfer_functions[size_t(v.transfer_function)] = tf;
    if (!own) {
      v.preset.clear();
      v.window.reset();
      v.look_edited = true;
    }
  }
  // (the table goes with each frame; the empty-space grid is copied at the start of the next,
  // after the frames in flight: a slider dragged waits for no frame)
  Uploads uploads;
  labelled_->renderer().set_transfer_function(volume, tf, &uploads);
  labelled_->runner().upload_in_next_frame(std::move(uploads));
  settings_changed(false);
}

}  // namespace strata::app
