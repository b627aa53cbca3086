#include "app/viewer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <utility>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "engine/core/png.h"
#include "engine/core/text_file.h"
#include "engine/gpu/context.h"
#include "engine/gpu/vulkan_check.h"
#include "engine/scene/atlas.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/transfer_function_presets.h"
#include "engine/scene/value_limits.h"
#include "labeling/camera_path.h"
#include "labeling/insertion_order.h"

namespace strata::app {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

constexpr double kMaxStep = 0.25;          // a frame's time step at most (slow devices)
constexpr double kPlotSeconds = 5.0;       // the timing plots' span
constexpr double kAnimationSeconds = 1.0;  // moves to named positions and anatomical views
// Label slots beyond the scene's: this many labels of one's own are placed without a new graph.
constexpr uint32_t kSpareLabelSlots = 64;

bool same_view(const Camera& a, const Camera& b) {
  return a.view == b.view;
}

// A transfer function seen through a window of intensities: the function's [0, 1] spread over
// [level - window / 2, level + window / 2], its opacity times `opacity`.
TransferFunction windowed(const TransferFunction& tf, float level, float window, float opacity) {
  TransferFunction out = tf;
  for (auto& stop : out.stops) {
    stop.position = level - 0.5f * window + stop.position * window;
    stop.color.a = std::clamp(stop.color.a * opacity, 0.0f, 1.0f);
  }
  return out;
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
// panel's slider ranges (app/viewer_panel.cpp).
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
      // (speed / epsilon bounds the force steps of a frame: at most 2,000 in a 0.1 s frame)
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

// What a label file can hold (label_file_writer.h decides UTF-8 by nlohmann's rules too).
bool is_utf8(const std::string& text) {
  try {
    (void)nlohmann::json(text).dump();
    return true;
  } catch (const nlohmann::json::type_error&) {
    return false;
  }
}

}  // namespace

bool HeadlessOutput::draw(const WindowTarget::Prepare& prepare) {
  const uint32_t slot = slots_.next();
  graph::GraphRunner& runner = prepare(slot, size_);
  runner.set_viewport(size_);
  const VkCommandBuffer cmd = slots_.begin(slot);
  runner.record(cmd, slot);
  const graph::FrameSubmission& extra = runner.submission();
  slots_.submit(slot, extra.wait, extra.signal);
  if (extra.submitted) extra.submitted();
  return true;
}

graph::Extent WindowOutput::extent() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  return {uint32_t(std::max(w, 0)), uint32_t(std::max(h, 0))};
}

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

Viewer::Viewer(Context& ctx, Scene& scene, const Camera& camera, const LabellingSettings& settings,
               const ViewerOptions& options, ViewerOutput& output, GLFWwindow* window)
    : ctx_(ctx),
      scene_(scene),
      options_(options),
      output_(output),
      ui_(ctx, window, options.ui_scale, output.frames_in_flight()),
      control_(scene, camera),
      debug_(ctx),
      applied_camera_(camera),
      last_change_(Clock::now()),
      last_frame_(Clock::now()),
      slots_(output.frames_in_flight()) {
  graph::Extent size = output.extent();
  if (size.width == 0 || size.height == 0) size = {64, 64};  // (a minimised window: resized later)
  LabellingSettings labelling = settings;
  labelling.render.interactive = options.frame_budget_ms > 0.0;
  labelling.spare_label_slots = kSpareLabelSlots;
  labelled_ = std::make_unique<LabelledRenderer>(ctx, scene, camera, size, labelling);
  labelled_->set_extension([this](graph::Graph& graph, const LabelledRenderer::GraphIds& ids) {
    extend_graph(graph, ids);
  });
  labelled_->set_frames_in_flight(output.frames_in_flight());
  for (const Volume& v : scene.volumes) {
    original_tfs_.push_back(v.transfer_function >= 0 ? scene.transfer_functions[v.transfer_function]
                                                     : TransferFunction{});
  }
  looks_.resize(scene.volumes.size());
  const size_t own = scene.labels.size() - std::min(scene.added_labels, scene.labels.size());
  for (size_t i = 0; i < own; ++i) {
    scene_labels_.push_back(
        {.id = scene.labels[i].id, .text = scene.labels[i].text, .anchor = scene.labels[i].anchor});
  }
  for (const Volume& v : scene.volumes) scene_cuts_.push_back(v.cut);
}

Viewer::~Viewer() {
  try {
    output_.wait_idle();
    if (video_) stop_recording();
  } catch (const std::exception&) {
    // (a lost or hung device, a full disk: the error that ended the run is being reported)
  }
}

// The viewer's end of the frame's graph: the picture (or a debug view) copied into the display
// image, the UI drawn onto it, then the output (the window's present).
void Viewer::extend_graph(graph::Graph& graph, const LabelledRenderer::GraphIds& ids) {
  ++generation_;
  // (beside the frames, the placement's buffers are not in the frame's graph: no debug view)
  const graph::ResourceId debug_image =
      !ids.placement_in_frame ? ids.labelled
                              : debug_.add_to(graph, {.saliency = ids.placed.saliency,
                                                      .costs = ids.placed.costs,
                                                      .labels = ids.placed.labels,
                                                      .placements = ids.placed.placements,
                                                      .order = ids.placed.order,
                                                      .layers = ids.rendered.layers,
                                                      .frame = ids.rendered.frame,
                                                      .keys = ids.rendered.keys,
                                                      .layer_count = ids.layer_count,
                                                      .label_count = ids.label_slots});
  display_id_ = graph.add_image("view.display", {VK_FORMAT_R8G8B8A8_UNORM});
  const graph::ResourceId labelled = ids.labelled, display = display_id_;
  graph.add_pass({"view.copy",
                  graph::PassKind::transfer,
                  {{labelled, graph::Use::transfer_src},
                   {debug_image, graph::Use::transfer_src},
                   {display, graph::Use::transfer_dst}},
                  [this, labelled, debug_image, display](graph::PassContext& pc) {
                    VkImageCopy region{};
                    region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                    region.dstSubresource = region.srcSubresource;
                    region.extent = {pc.viewport.width, pc.viewport.height, 1};
                    const graph::ResourceId from = debug_choice_ ? debug_image : labelled;
                    vkCmdCopyImage(pc.cmd, pc.image(from), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                   pc.image(display), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                                   &region);
                  },
                  "ui"});
  ui_.add_to(graph, display);
  output_.add_to(graph, display);
}

// --- input -------------------------------------------------------------------------------------

void Viewer::mouse_button(int button, int action, int mods) {
  const bool left = button == GLFW_MOUSE_BUTTON_LEFT && !(mods & GLFW_MOD_SHIFT);
  try {
    // A press on a cut-away's handle drags it (before placing labels and turning the camera).
    if (!(mods & GLFW_MOD_SHIFT) && press_cut_handle(button, action)) return;
    // Place mode: a press on an anchor drags it along the surface under the pointer, elsewhere
    // a press places a label (both once the frame's pick comes back: no wait).
    if (place_mode_ && left && action == GLFW_PRESS && drag_button_ < 0) {
      anchor_drag_.reset();
      if (const std::optional<size_t> i = label_near(mouse_, true)) {
        anchor_drag_ = scene_.labels[*i].id;
        anchor_drag_from_ = mouse_;
        drag_undone_ = false;
        select_label(*i);
      } else {
        ask_pick({mouse_, {}, false});
      }
      return;
    }
    if (left && action == GLFW_RELEASE && anchor_drag_) {
      if (glm::distance(mouse_, anchor_drag_from_) > 2.0f) ask_pick({mouse_, *anchor_drag_, true});
      anchor_drag_.reset();
      return;
    }
    if (place_mode_ && left) return;
    // Otherwise the camera; a click (no movement) on a label's box or anchor selects it.
    if (left && action == GLFW_RELEASE && button == drag_button_ &&
        glm::distance(mouse_, press_at_) <= 2.0f) {
      std::optional<size_t> i = label_near(mouse_, false);
      if (!i) i = label_near(mouse_, true);
      if (i) select_label(*i);
    }
  } catch (const Error& e) {
    message_ = e.what();
    ui_event();
    anchor_drag_.reset();
    return;
  }
  if (action == GLFW_PRESS && drag_button_ < 0) {
    press_at_ = mouse_;
    drag_button_ = button;
    drag_pan_ = button == GLFW_MOUSE_BUTTON_MIDDLE ||
                (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_SHIFT));
  } else if (action == GLFW_RELEASE && button == drag_button_) {
    drag_button_ = -1;
  }
}

void Viewer::cursor(glm::vec2 position) {
  const glm::vec2 delta = position - mouse_;
  mouse_ = position;
  // (an anchor follows the pointer: one pick in flight at a time, the newest position next)
  if (anchor_drag_ && delta != glm::vec2(0.0f) && glm::distance(mouse_, anchor_drag_from_) > 2.0f &&
      std::none_of(pending_picks_.begin(), pending_picks_.end(),
                   [](const PendingPick& p) { return p.drag; })) {
    ask_pick({mouse_, *anchor_drag_, true});
  }
  if (handle_drag_) return drag_cut_handle(delta);
  if (cuts_.crop || !cuts_.planes.empty()) {  // (the handle under the pointer is drawn larger)
    const std::optional<int> hovered = cut_handle_near(mouse_);
    if (hovered != hovered_handle_) hovered_handle_ = hovered, ui_event();
  }
  if (drag_button_ < 0 || delta == glm::vec2(0.0f)) return;
  const graph::Extent e = output_.extent();
  const glm::uvec2 viewport{std::max(1u, e.width), std::max(1u, e.height)};
  if (drag_pan_) {
    control_.pan(delta, viewport);
  } else if (drag_button_ == GLFW_MOUSE_BUTTON_LEFT) {
    control_.rotate(delta, viewport);
  } else if (drag_button_ == GLFW_MOUSE_BUTTON_RIGHT) {
    control_.zoom_drag(delta.y, viewport);
  }
}

void Viewer::scroll(double ticks) {
  control_.zoom_wheel(ticks);
}

void Viewer::key(int key, int mods) {
  if (mods & GLFW_MOD_CONTROL) {
    if (key == GLFW_KEY_Z && !(mods & GLFW_MOD_SHIFT)) undo_labels();
    if (key == GLFW_KEY_Y || (key == GLFW_KEY_Z && (mods & GLFW_MOD_SHIFT))) redo_labels();
    if (key == GLFW_KEY_S) save_labels(default_labels_path());
    return;
  }
  switch (key) {
    case GLFW_KEY_P:
      set_place_mode(!place_mode_);
      break;
    case GLFW_KEY_Q:
    case GLFW_KEY_ESCAPE:
      quit_ = true;
      break;
    case GLFW_KEY_LEFT:
      control_.rotate_step(-1, 0);
      break;
    case GLFW_KEY_RIGHT:
      control_.rotate_step(1, 0);
      break;
    case GLFW_KEY_UP:
      control_.rotate_step(0, 1);
      break;
    case GLFW_KEY_DOWN:
      control_.rotate_step(0, -1);
      break;
    case GLFW_KEY_R:
      reset_camera();
      break;
    case GLFW_KEY_F12:
      screenshot();
      break;
    case GLFW_KEY_H:
      options_.show_panel = !options_.show_panel;
      ui_event();
      break;
    default:
      if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9) jump_to_position(size_t(key - GLFW_KEY_1));
      break;
  }
}

// --- actions -----------------------------------------------------------------------------------

void Viewer::jump_to_position(size_t index) {
  const std::optional<Camera> goal = numbered_position(scene_, index);
  if (!goal) {
    message_ = "the scene has no position " + std::to_string(index + 1);
    ui_event();
    return;
  }
  control_.animate_to(*goal, kAnimationSeconds);
}

void Viewer::view_from(AnatomicalView view) {
  control_.animate_to(control_.view_from(view), kAnimationSeconds);
}

void Viewer::reset_camera() {
  control_.reset();
}

std::filesystem::path Viewer::screenshot(const std::filesystem::path& path) {
  std::filesystem::path out = path;
  if (out.empty()) {
    const std::string stem = scene_.source.empty() ? "strata" : scene_.source.stem().string();
    do {
      char name[64];
      std::snprintf(name, sizeof name, "-%03u.png", ++screenshots_);
      out = options_.screenshot_dir / (stem + name);
    } while (std::filesystem::exists(out));
  }
  const std::vector<uint8_t> pixels = download(labelled_->labelled_image());
  write_png(out.string(), labelled_->size().width, labelled_->size().height, pixels);
  message_ = "wrote " + out.string();
  std::printf("view: screenshot %s\n", out.string().c_str());
  std::fflush(stdout);
  ui_event();
  return out;
}

void Viewer::capture(const std::filesystem::path& path) {
  write_png(path.string(), labelled_->size().width, labelled_->size().height,
            download(display_id_));
}

// An rgba8 image of the last frame, once the frames in flight have finished.
std::vector<uint8_t> Viewer::download(graph::ResourceId image) {
  output_.wait_idle();
  const std::vector<std::byte> bytes = labelled_->runner().download_image(image);
  const auto* p = reinterpret_cast<const uint8_t*>(bytes.data());
  return {p, p + bytes.size()};
}

// After the frames in flight finished: the results of the last one.
void Viewer::read_latest() {
  output_.wait_idle();
  labelled_->use_slot(last_slot_);
}

void Viewer::write_layout(const std::filesystem::path& path) {
  read_latest();
  write_text_file(path, layout_json(labelled_->result()));
}

void Viewer::start_recording(const std::filesystem::path& path) {
  if (video_) stop_recording();
  const graph::Extent e = labelled_->size();
  video_ = std::make_unique<VideoFile>(path.string(), e.width & ~1u, e.height & ~1u,
                                       options_.record_fps);
  video_path_ = path;
  video_frames_ = 0;
  message_ = "recording " + path.string();
}

void Viewer::stop_recording() {
  if (!video_) return;
  video_->finish();
  video_.reset();
  message_ = "wrote " + video_path_.string() + " (" + std::to_string(video_frames_) + " frames)";
  std::printf("view: video %s, %llu frames\n", video_path_.string().c_str(),
              static_cast<unsigned long long>(video_frames_));
  std::fflush(stdout);
}

void Viewer::set_label_hidden(int id, bool hidden) {
  for (size_t i = 0; i < scene_.labels.size(); ++i) {
    if (scene_.labels[i].id != id) continue;
    labelled_->set_label_hidden(i, hidden);
    changed();
    return;
  }
  throw Error("the scene has no label " + std::to_string(id));
}

// --- labels of one's own -------------------------------------------------------------------------

void Viewer::ask_pick(const PendingPick& pick) {
  const graph::Extent e = labelled_->size();
  const glm::vec2 at = pick.at;
  if (!(at.x >= 0.0f && at.y >= 0.0f && at.x < float(e.width) && at.y < float(e.height))) {
    throw Error("pixel " + value_limits::shown(at.x) + "," + value_limits::shown(at.y) +
                " lies outside the " + std::to_string(e.width) + "x" + std::to_string(e.height) +
                " picture");
  }
  labelled_->request_pick(at);
  pending_picks_.push_back(pick);
}

// The picks come back with their frame's slot: each places or moves its label now. Where the ray
// met only background the message says so (and pick_now throws it).
void Viewer::apply_picks() {
  for (const PickHit& hit : labelled_->take_picks()) {
    if (pending_picks_.empty()) break;
    const PendingPick pick = pending_picks_.front();
    pending_picks_.pop_front();
    if (!hit.hit) {
      const std::string what =
          !pick.move_id
              ? "nothing under the pixel to place a label on (background)"
              : "nothing under the pixel to move label " + std::to_string(*pick.move_id) + " to";
      missed_pick_ = what;
      if (!pick.drag) message_ = what;  // (a drag over the background: the anchor waits)
      ui_event();
      continue;
    }
    if (!pick.move_id) {
      add_label(hit.point);
    } else if (std::any_of(scene_.labels.begin(), scene_.labels.end(),
                           [&](const Label& l) { return l.id == *pick.move_id; })) {
      // (a drag is one edit to undo: the labels before its first move)
      const size_t i = label_index(*pick.move_id);
      edit_labels([&](std::vector<Label>& labels) { labels[i].anchor = hit.point; },
                  !pick.drag || !drag_undone_);
      drag_undone_ = drag_undone_ || pick.drag;
    }
  }
}

// A pick for a script or a benchmark: asked, then frames until it comes back.
void Viewer::pick_now(const PendingPick& pick) {
  ask_pick(pick);
  missed_pick_.reset();
  for (int frames = 0; !pending_picks_.empty(); ++frames) {
    if (frames > 16) throw Error("the pick did not come back within 16 frames");
    frame();
  }
  if (missed_pick_) throw Error(*missed_pick_);
}

size_t Viewer::label_index(int id) const {
  for (size_t i = 0; i < scene_.labels.size(); ++i)
    if (scene_.labels[i].id == id) return i;
  throw Error("the scene has no label " + std::to_string(id));
}

void Viewer::edit_labels(const std::function<void(std::vector<Label>&)>& edit, bool undoable) {
  std::vector<Label> before = scene_.labels;
  edit(scene_.labels);
  if (undoable) {
    undo_.push_back(std::move(before));
    redo_.clear();
  }
  labelled_->labels_changed();
  moving_labels_.clear();
  if (picked_label_ >= int(scene_.labels.size())) picked_label_ = -1;
  changed();
  ui_event();
}

int Viewer::place_label(glm::vec2 at) {
  const size_t labels = scene_.labels.size();
  pick_now({at, {}, false});
  if (scene_.labels.size() == labels) throw Error("no label was placed");
  return scene_.labels.back().id;
}

void Viewer::add_label(glm::vec3 point) {
  Label label;
  label.id = unused_label_ids(scene_.labels, 1).front();
  label.anchor = point;
  label.text = atlas_region_at(scene_, point);
  if (label.text.empty()) label.text = "Label " + std::to_string(label.id);
  edit_labels([&](std::vector<Label>& labels) { labels.push_back(label); });
  picked_label_ = int(scene_.labels.size()) - 1;  // (selected: its text ready to edit)
  std::snprintf(edit_text_, sizeof edit_text_, "%s", label.text.c_str());
  message_ = "placed '" + label.text + "' (label " + std::to_string(label.id) + ")";
  if (options_.print_actions) {
    std::printf("view: %s\n", message_.c_str());
    std::fflush(stdout);
  }
}

void Viewer::set_label_text(int id, const std::string& text) {
  const size_t i = label_index(id);
  if (text.empty()) throw Error("a label's text cannot be empty");
  if (!is_utf8(text)) throw Error("label " + std::to_string(id) + ": the text is not UTF-8");
  edit_labels([&](std::vector<Label>& labels) { labels[i].text = text; });
}

void Viewer::move_label(int id, glm::vec2 at) {
  label_index(id);  // (an Error when there is no such label)
  pick_now({at, id, false});
}

void Viewer::delete_label(int id) {
  const size_t i = label_index(id);
  edit_labels([&](std::vector<Label>& labels) { labels.erase(labels.begin() + ptrdiff_t(i)); });
}

// Undo and redo: the labels on top of `from` come back, the ones they replace go onto `to`.
bool Viewer::restore_labels(std::vector<std::vector<Label>>& from,
                            std::vector<std::vector<Label>>& to) {
  if (from.empty()) return false;
  to.push_back(scene_.labels);
  scene_.labels = std::move(from.back());
  from.pop_back();
  if (picked_label_ >= int(scene_.labels.size())) picked_label_ = -1;
  labelled_->labels_changed();
  changed();
  return true;
}

bool Viewer::undo_labels() {
  return restore_labels(undo_, redo_);
}

bool Viewer::redo_labels() {
  return restore_labels(redo_, undo_);
}

void Viewer::save_labels(const std::filesystem::path& path, LabelAxes axes) {
  // (the scene's own labels stay in its file: loaded with it, the saved ones are not doubled)
  std::vector<Label> own;
  for (const Label& label : scene_.labels) {
    if (std::none_of(scene_labels_.begin(), scene_labels_.end(),
                     [&](const Label& l) { return l.id == label.id && same_label(l, label); }))
      own.push_back(label);
  }
  write_label_file(path, own, axes);
  message_ = "wrote " + std::to_string(own.size()) + " labels to " + path.string() +
             (axes == LabelAxes::lps ? " (LPS)" : " (RAS)") + ", placed or edited; the scene's " +
             std::to_string(scene_.labels.size() - own.size()) + " stay in its file";
  std::printf("view: %s\n", message_.c_str());
  std::fflush(stdout);
  ui_event();
}

std::filesystem::path Viewer::default_labels_path() const {
  std::filesystem::path path = options_.scene_path;
  std::string stem = path.filename().string();
  for (const char* extension : {".json", ".nii.gz", ".nii", ".nrrd", ".mhd", ".mha", ".xml"}) {
    const std::string e = extension;
    if (stem.size() > e.size() && stem.compare(stem.size() - e.size(), e.size(), e) == 0) {
      stem.resize(stem.size() - e.size());
      break;
    }
  }
  return path.replace_filename(stem + "-labels.mrk.json");
}

// The label whose anchor (an enabled label's, within 6 pixels; the nearest) or drawn box (as the
// last frame read back drew it) holds `at`.
std::optional<size_t> Viewer::label_near(glm::vec2 at, bool anchor) const {
  const std::vector<gpu::LabelGpu>& labels = labelled_->labels();
  const std::span<const gpu::PlacementGpu> drawn = labelled_->drawn();
  std::optional<size_t> found;
  float nearest = 6.0f;
  for (size_t i = 0; i < labels.size(); ++i) {
    if ((labels[i].flags & LABEL_ENABLED) == 0u) continue;
    if (anchor) {
      const float d = glm::distance(at, labels[i].anchor);
      if (d <= nearest) {
        nearest = d;
        found = i;
      }
    } else if (i < drawn.size() && drawn[i].shown == PLACEMENT_SHOWN && drawn[i].opacity > 0.0f &&
               glm::all(
                   glm::lessThanEqual(glm::abs(at - drawn[i].position), 0.5f * labels[i].size))) {
      found = i;
    }
  }
  return found;
}

void Viewer::select_label(size_t index) {
  if (index >= scene_.labels.size()) return;
  picked_label_ = int(index);
  std::snprintf(edit_text_, sizeof edit_text_, "%s", scene_.labels[index].text.c_str());
  message_ = "selected '" + scene_.labels[index].text + "' (label " +
             std::to_string(scene_.labels[index].id) + ")";
  ui_event();
}

void Viewer::set_place_mode(bool on) {
  place_mode_ = on;
  message_ = on ? "place mode: a click places a label (P: off)" : "place mode off";
  ui_event();
}

namespace {

// A new scene file beside `opened` (a volume, a DICOM folder, a thesis .xml scene), named after
// it and clashing with no file there: scan.nii.gz gives scan.scene.json, else scan.scene-2.json...
// Written with Replace::no, so a file that appears meanwhile is not replaced either.
std::filesystem::path save_new_scene_file(const std::filesystem::path& opened, const Scene& scene) {
  std::filesystem::path normal = opened.lexically_normal();
  if (normal.filename().empty()) normal = normal.parent_path();  // "ct/": the folder ct
  const std::string file = normal.filename().string();
  const std::string stem = file.substr(0, file.find('.'));
  for (int n = 1; n < 1000; ++n) {
    const std::filesystem::path path =
        normal.parent_path() /
        (stem + ".scene" + (n == 1 ? "" : "-" + std::to_string(n)) + ".json");
    std::error_code error;
    if (std::filesystem::exists(std::filesystem::symlink_status(path, error))) continue;
    try {
      save_scene_json(path, scene, AtomicFile::Replace::no);
      return path;
    } catch (const Error&) {
      if (!std::filesystem::exists(std::filesystem::symlink_status(path, error))) throw;
    }
  }
  throw Error(normal.string() + ": no free name for a new scene file beside it");
}

}  // namespace

// A strata .json scene is written back to itself; anything else gets a new scene file of its
// own (never a file that is there already: scan.json may be a transfer function).
void Viewer::save_position(const std::string& name) {
  const std::string chosen = name.empty() ? new_position_name(scene_) : name;
  for (const CameraPose& p : scene_.camera_positions) {
    if (p.name == chosen) throw Error("the scene already has a position '" + chosen + "'");
  }
  scene_.camera_positions.push_back(control_.pose(chosen));
  try {
    if (!saved_scene_path_.empty()) {
      save_scene_json(saved_scene_path_, scene_);
      message_ = "saved position '" + chosen + "' in " + saved_scene_path_.string();
    } else if (!scene_.source_json.empty()) {
      save_scene_json(options_.scene_path, scene_);
      saved_scene_path_ = options_.scene_path;
      message_ = "saved position '" + chosen + "' in " + saved_scene_path_.string();
    } else {
      saved_scene_path_ = save_new_scene_file(options_.scene_path, scene_);
      message_ = "saved position '" + chosen + "' in a new scene file " +
                 saved_scene_path_.string() + " (" + options_.scene_path.string() +
                 " is not a strata scene)";
    }
  } catch (const Error&) {
    scene_.camera_positions.pop_back();  // not saved: a later save must not write it unasked
    throw;
  }
  std::printf("view: %s\n", message_.c_str());
  ui_event();
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
  set_transfer(volume);
  message_ = "volume '" + scene_.volumes[volume].name + "': preset " + name;
}

void Viewer::set_transfer(uint32_t volume) {
  const VolumeLook& look = looks_[volume];
  // (the table goes with each frame; the empty-space grid is copied at the start of the next,
  // after the frames in flight: a slider dragged waits for no frame)
  Uploads uploads;
  labelled_->renderer().set_transfer_function(
      volume, windowed(original_tfs_[volume], look.level, look.window, look.opacity), &uploads);
  labelled_->runner().upload_in_next_frame(std::move(uploads));
  settings_changed(false);
}

// --- frames ------------------------------------------------------------------------------------

void Viewer::changed() {
  ++serial_;
  change_frame_ = labelled_->frame_number() + 1;
  labelled_->placement_due();
  settled_ = false;
  last_change_ = Clock::now();
  optimisation_ = {};  // (trials of an earlier serial are ignored when they come back)
}

void Viewer::apply_camera() {
  const Camera& camera = control_.camera();
  if (same_view(camera, applied_camera_)) return;
  applied_camera_ = camera;
  labelled_->set_camera(camera);  // (the order goes back to the scene's)
  last_move_ = Clock::now();
  changed();
}

bool Viewer::busy() const {
  if (quit_) return false;
  if (ui_frames_ > 0 || !settled_ || control_.animating()) return true;
  if (!same_view(control_.camera(), applied_camera_)) return true;  // moved since the last frame
  if (drag_button_ >= 0) return false;  // a still mouse button: nothing moves
  if (!optimisation_due()) return false;
  // (trial frames; beside the frames, a frame starts each trial placement and takes it up)
  return !labelled_->placement_beside() || optimisation_.in_flight < 0 ||
         labelled_->trial_finished();
}

// (not while recording: a video's frames are a fixed time step apart, trials would be in them)
bool Viewer::optimisation_pending() const {
  return options_.optimize_on_idle && !optimisation_.done && scene_.labels.size() >= 2 && !video_;
}

// (baseline: a settled normal frame's cost)
bool Viewer::optimisation_due() const {
  return optimisation_pending() && optimisation_.baseline >= 0.0 &&
         seconds_between(last_change_, Clock::now()) >= options_.idle_seconds;
}

std::string Viewer::unsettled() const {
  std::vector<std::string> parts;
  if (ui_frames_ > 0) parts.push_back("the panel's frames");
  if (control_.animating()) parts.push_back("the camera's animation");
  if (!same_view(control_.camera(), applied_camera_)) parts.push_back("the camera's last move");
  if (!settled_ && checked_serial_ != serial_) {
    parts.push_back("the first frames after the last change");
  } else if (!settled_ && placement_due_) {
    parts.push_back("the placement beside the frames since the last change");
  } else if (!settled_) {
    std::string text = std::to_string(moving_labels_.size()) + " label" +
                       (moving_labels_.size() == 1 ? "" : "s") + " moving or fading (";
    for (size_t k = 0; k < moving_labels_.size() && k < 3; ++k) {
      text += (k ? ", " : "") + scene_.labels[moving_labels_[k]].text;
    }
    parts.push_back(text + (moving_labels_.size() > 3 ? ", ...)" : ")"));
  }
  if (settled_ && optimisation_pending()) {
    const Optimisation& o = optimisation_;
    const auto back =
        std::count_if(o.costs.begin(), o.costs.end(), [](double c) { return !std::isnan(c); });
    parts.push_back("the optimisation on idle (" + std::to_string(back) + " of " +
                    std::to_string(options_.optimize_tries) + " trials back)");
  }
  std::string out;
  for (size_t k = 0; k < parts.size(); ++k) out += (k ? ", " : "") + parts[k];
  return out.empty() ? "nothing" : out;
}

std::optional<double> Viewer::wake_in() const {
  if (!optimisation_pending()) return {};
  constexpr double kTrialPoll = 0.01;  // (a trial placement beside the frames: is it back?)
  if (optimisation_.in_flight >= 0) return kTrialPoll;
  return std::max(0.0, options_.idle_seconds - seconds_between(last_change_, Clock::now()));
}

int Viewer::next_trial() {
  Optimisation& o = optimisation_;
  const size_t n = scene_.labels.size();
  if (!optimisation_due() || drag_button_ >= 0 || control_.animating()) return -1;
  if (o.orders.empty()) {
    for (uint32_t t = 0; t < options_.optimize_tries; ++t) {
      o.orders.push_back(random_order(uint32_t(n), serial_ * 131 + t + 1));
    }
    o.costs.assign(o.orders.size(), std::nan(""));
  }
  if (o.submitted >= o.orders.size()) return -1;
  ++summary_.trials;
  return int(o.submitted++);
}

void Viewer::trial_back(int trial, double cost) {
  Optimisation& o = optimisation_;
  if (trial < 0 || size_t(trial) >= o.costs.size()) return;  // (one of an earlier serial)
  o.costs[size_t(trial)] = cost;
  const bool all =
      std::none_of(o.costs.begin(), o.costs.end(), [](double c) { return std::isnan(c); });
  if (!all || o.done) return;
  const size_t best = size_t(std::min_element(o.costs.begin(), o.costs.end()) - o.costs.begin());
  o.done = true;
  if (!(o.costs[best] < o.baseline * (1.0 - 1e-4))) return;
  labelled_->set_order(o.orders[best]);
  // (beside the frames, a placement in the new order: not settled before it is taken up)
  labelled_->placement_due();
  change_frame_ = labelled_->frame_number() + 1;
  ++summary_.adopted;
  settled_ = false;  // the labels move to the cheaper layout
  char text[96];
  std::snprintf(text, sizeof text, "optimised on idle: cost %.6g -> %.6g", o.baseline,
                o.costs[best]);
  message_ = text;
}

// The results of the frame that last used `slot` (it has finished).
void Viewer::read_slot(uint32_t slot) {
  const SlotFrame done = slots_[slot];
  const bool ours = done.generation == generation_;  // (else never used, or another graph's)
  labelled_->use_slot(slot, ours);
  if (!ours) return;
  last_timings_ = labelled_->runner().timings(slot);
  double gpu = 0.0;
  for (const graph::PassTiming& t : last_timings_) {
    summary_.gpu_ms[t.name] += t.ms;
    gpu += t.ms;
  }
  ++summary_.timed_frames;
  if (options_.keep_frame_spans && !last_timings_.empty()) {
    summary_.gpu_span_ms.push_back(last_timings_.back().end_ms - last_timings_.front().begin_ms);
  }
  gpu_times_.push_back(float(gpu));
  if (done.serial != serial_) return;  // made before the last change

  Optimisation& o = optimisation_;
  if (done.trial >= 0) return trial_back(done.trial, labelled_->total_cost());
  // Beside the frames, the labels head for a placement made before the last change: not settled.
  placement_due_ = labelled_->placed_frame_number() < change_frame_;
  if (placement_due_) {
    checked_serial_ = serial_;
    return;
  }
  if (refining_ && done.divisor == 1 && !camera_moving()) {
    refining_ = false;
    summary_.refine_seconds.push_back(seconds_between(last_move_, Clock::now()));
  }
  // A normal frame: settled when every label is on its target and fully faded in or out.
  const auto targets = labelled_->placement_results();
  const auto drawn = labelled_->drawn();
  const auto& labels = labelled_->labels();
  moving_labels_.clear();
  checked_serial_ = serial_;
  for (size_t i = 0; i < drawn.size(); ++i) {
    if ((labels[i].flags & LABEL_ENABLED) == 0u && drawn[i].opacity == 0.0f) continue;
    // (a held label keeps its exact offset from its anchor: within half a pixel per axis of
    // the placement's pixel-centred position)
    const bool on_target = glm::length(drawn[i].position - targets[i].position) < 0.75f ||
                           (drawn[i].opacity == 0.0f && targets[i].shown != PLACEMENT_SHOWN);
    // (a label kept apart that may soon appear again is not settled: PLACEMENT_PENDING)
    const bool still = on_target && (drawn[i].opacity == 0.0f || drawn[i].opacity == 1.0f) &&
                       (drawn[i].pad & PLACEMENT_PENDING) == 0u;
    if (!still) moving_labels_.push_back(uint32_t(i));
  }
  if (moving_labels_.empty()) {
    settled_ = true;
    if (o.orders.empty()) o.baseline = labelled_->total_cost();  // the kept order's cost
  }
}

graph::GraphRunner& Viewer::prepare(uint32_t slot, graph::Extent extent, double seconds) {
  if (!(extent == labelled_->size())) {
    labelled_->set_size(extent);
    changed();
  }
  read_slot(slot);
  apply_picks();
  // Stein & Decoret's order needs the picture: computed once the camera rests (a wait for the
  // frames in flight, once per rest).
  if (insertion_order_ == 1 && settled_ && apollonius_serial_ != serial_ && !control_.animating()) {
    output_.wait_idle();
    labelled_->set_order(labelled_->apollonius_layers_order());
    apollonius_serial_ = serial_;
    settled_ = false;
  }
  const bool interactive = options_.frame_budget_ms > 0.0;
  labelled_->set_placement_beside((options_.placement_beside || interactive) && !debug_choice_);
  // (beside the frames, trials are placements of their own, one at a time; those in flight when
  // the placement moves are lost, and the trials start again)
  const bool beside = labelled_->placement_beside();
  if (beside != trials_beside_) optimisation_ = {};
  trials_beside_ = beside;
  const int trial = !beside || labelled_->trial_ready() ? next_trial() : -1;
  if (trial >= 0) labelled_->set_trial_order(optimisation_.orders[size_t(trial)]);
  labelled_->prepare_frame(seconds, trial >= 0);
  if (beside) {
    if (const std::optional<double> cost = labelled_->take_trial_cost())
      trial_back(std::exchange(optimisation_.in_flight, -1), *cost);
    if (trial >= 0) optimisation_.in_flight = trial;
  }
  count_placements();
  debug_.set_enabled(debug_choice_.has_value());
  if (debug_choice_) {
    debug_.set(*debug_choice_);
    debug_.set_placement(uint32_t(labelled_->placement_order_count()),
                         labelled_->settings().placement.margin_em * labelled_->units().em);
  }
  slots_[slot] = {generation_, serial_, beside ? -1 : trial,
                  labelled_->renderer().settings().divisor};
  last_slot_ = slot;
  return labelled_->runner();
}

// The camera moves: an animation, a drag in progress, or a move in the last quarter second (the
// frames between a drag's events keep the interactive resolution).
bool Viewer::camera_moving() const {
  return control_.animating() || drag_button_ >= 0 ||
         seconds_between(last_move_, Clock::now()) < 0.25;
}

// While the camera moves, the divisor that keeps a frame within the budget; at rest, 1 (and the
// placement beside the frames, paused while moving, places the resting view).
void Viewer::choose_divisor(bool moving) {
  if (options_.frame_budget_ms <= 0.0) return;
  uint32_t d = 1;
  if (moving && full_frame_ms_ > options_.frame_budget_ms) {
    d = uint32_t(std::ceil(std::sqrt(full_frame_ms_ / options_.frame_budget_ms)));
  }
  divisor_ = std::clamp(d, 1u, 8u);
  summary_.largest_divisor = std::max(summary_.largest_divisor, divisor_);
  labelled_->renderer().settings().divisor = debug_choice_ ? 1u : divisor_;
  labelled_->pause_placement(moving);
  if (moving) refining_ = true;
}

// The placements beside the frames taken up since the last frame: their GPU time and latency.
void Viewer::count_placements() {
  const PlacementBeside* beside = labelled_->beside();
  if (beside && beside->stats().adopted < beside_counted_) beside_counted_ = 0;  // (a new one)
  if (!beside || beside->stats().adopted == beside_counted_) return;
  summary_.placements += beside->stats().adopted - beside_counted_;
  beside_counted_ = beside->stats().adopted;
  summary_.placement_latency_frames.push_back(beside->stats().latency_frames.back());
  const auto& timings = beside->placement_timings();
  if (!timings.empty())
    summary_.placement_gpu_ms += timings.back().end_ms - timings.front().begin_ms;
}

void Viewer::set_habuffer_slots(uint32_t slots) {
  output_.wait_idle();
  labelled_->renderer().set_table_size(slots);
  labelled_->runner().reallocate();
  changed();
}

void Viewer::frame(std::optional<double> step) {
  try {
    draw_frame(step);
  } catch (const DeviceLost& lost) {
    throw DeviceLost("during frame " + std::to_string(summary_.frames + 1) + " (" + lost.when() +
                     ")");
  }
}

void Viewer::draw_frame(std::optional<double> step) {
  const Clock::time_point now = Clock::now();
  double seconds = std::min(seconds_between(last_frame_, now), kMaxStep);
  if (video_) seconds = 1.0 / options_.record_fps;
  if (step) seconds = *step;
  frame_times_.push_back(float(seconds_between(last_frame_, now) * 1e3));
  last_frame_ = now;
  const size_t plot = size_t(kPlotSeconds * 60.0);
  while (frame_times_.size() > plot) frame_times_.pop_front();
  while (gpu_times_.size() > plot) gpu_times_.pop_front();

  // The UI first: what it changes applies to this frame.
  graph::Extent extent = output_.extent();
  if (extent.width == 0 || extent.height == 0) return;  // minimised
  ui_.begin_frame(extent, seconds);
  panel_ = glm::uvec4(0u);
  if (options_.show_panel) build_panel();
  draw_cut_aways();
  ui_.end_frame();
  if (panel_ != labelled_->settings().placement.keep_out) {
    labelled_->settings().placement.keep_out = panel_;  // (the panel moved, or was shown or hidden)
    changed();
  }
  if (ui_frames_ > 0) --ui_frames_;

  control_.update(seconds);
  apply_camera();
  const bool moving = camera_moving();
  choose_divisor(moving);
  const bool drawn =
      output_.draw([this, seconds](uint32_t slot, graph::Extent e) -> graph::GraphRunner& {
        return prepare(slot, e, seconds);
      });
  if (!drawn) return;
  ++summary_.frames;
  const double busy = seconds_between(now, Clock::now());
  summary_.busy_seconds += busy;
  if (moving) {
    ++summary_.moving_frames;
    summary_.moving_seconds += busy;
  }
  if (options_.frame_budget_ms > 0.0) {
    // (a frame of d-th pixels costs about 1 / d^2 of a full one, and a little more)
    const double full = 1e3 * busy * double(divisor_) * double(divisor_);
    full_frame_ms_ = full_frame_ms_ > 0.0 ? 0.5 * (full_frame_ms_ + full) : full;
  }
  if (video_) {
    const std::vector<uint8_t> pixels = download(labelled_->labelled_image());
    const graph::Extent e = labelled_->size();
    // (the encoder takes even sizes: the last row and column of an odd size are left out)
    std::vector<uint8_t> even;
    const uint32_t w = e.width & ~1u, h = e.height & ~1u;
    even.reserve(size_t(w) * h * 4);
    for (uint32_t y = 0; y < h; ++y) {
      const auto row = pixels.begin() + long(size_t(y) * e.width * 4);
      even.insert(even.end(), row, row + long(w) * 4);
    }
    video_->write(even);
    ++video_frames_;
  }
}

}  // namespace strata::app
