// The interactive viewer's state and frame (`strata view`, `strata bench view`): the labelled
// scene every frame with the forces moving the labels, the camera by mouse and keys (3D Slicer's
// conventions), the Dear ImGui panel over it, screenshots, recording and optimisation on idle.
// Frames are recorded while earlier ones still run; what the GPU reports (layouts, costs,
// counters, timings) is read when a frame slot comes round again, a frame or two later. With
// nothing to do (camera still, labels settled, no input) the viewer asks for no frames.
// A job a file in app/viewer/: the frame here (viewer.cpp), input.cpp, panel.cpp, parameters.cpp,
// labels.cpp, cut_aways.cpp, settling.cpp (with idle_optimisation.h), recording.cpp (with
// recorder.h); the commands of scripts, keys and panel in script_commands.inc.
#pragma once

#include <array>
#include <chrono>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "app/annotation_options.h"
#include "app/viewer/camera_control.h"
#include "app/viewer/idle_optimisation.h"
#include "app/viewer/label_history.h"
#include "app/viewer/recorder.h"
#include "app/viewer/script.h"
#include "app/viewer/ui_layer.h"
#include "engine/graph/frame_slots.h"
#include "engine/graph/window_target.h"
#include "engine/scene/io/label_file_writer.h"
#include "frame/labelled_render.h"
#include "passes/debug_view.h"

namespace strata::app {

// Where the viewer's frames go: a window (presented) or nowhere (the benchmark).
class ViewerOutput {
 public:
  virtual ~ViewerOutput() = default;
  // Ends the graph after the UI was drawn onto `display`.
  virtual void add_to(graph::Graph& graph, graph::ResourceId display) = 0;
  // Records and submits one frame, prepared by `prepare` once its slot is free; false when
  // nothing was drawn (a minimised window).
  virtual bool draw(const WindowTarget::Prepare& prepare) = 0;
  virtual void wait_idle() = 0;
  // The picture's size now (the window's framebuffer).
  virtual graph::Extent extent() const = 0;
  virtual uint32_t frames_in_flight() const = 0;
};

// Frames without a window: submitted in turn over the frame slots, never presented.
class HeadlessOutput : public ViewerOutput {
 public:
  HeadlessOutput(Context& ctx, graph::Extent size, uint32_t frames_in_flight)
      : slots_(ctx, frames_in_flight), size_(size) {}
  void add_to(graph::Graph&, graph::ResourceId) override {}
  bool draw(const WindowTarget::Prepare& prepare) override;
  void wait_idle() override { slots_.wait_all(); }
  graph::Extent extent() const override { return size_; }
  // The picture's size from the next frame on (a window resized; the viewer follows).
  void resize(graph::Extent size) { size_ = size; }
  uint32_t frames_in_flight() const override { return slots_.count(); }

 private:
  FrameSlots slots_;
  graph::Extent size_;
};

// Frames presented to a GLFW window.
class WindowOutput : public ViewerOutput {
 public:
  WindowOutput(Context& ctx, GLFWwindow* window, uint32_t frames_in_flight)
      : target_(ctx, window, frames_in_flight), window_(window) {}
  void add_to(graph::Graph& graph, graph::ResourceId display) override {
    target_.add_output(graph, display);
  }
  bool draw(const WindowTarget::Prepare& prepare) override { return target_.draw(prepare); }
  void wait_idle() override { target_.wait_idle(); }
  graph::Extent extent() const override;
  uint32_t frames_in_flight() const override { return target_.frames_in_flight(); }

 private:
  WindowTarget target_;
  GLFWwindow* window_;
};

// Rounds of the tidy-up a viewer frame runs at most (stills: PlacementSettings'
// default): a frame's labels are held where the last frame's tidy-up put them, so the work
// spreads over frames.
inline constexpr uint32_t kViewerTidyRounds = 4;

struct ViewerOptions {
  std::filesystem::path scene_path;  // where "save position" writes the scene back
  std::filesystem::path screenshot_dir = ".";
  bool optimize_on_idle = true;  // the thesis program's option
  uint32_t optimize_tries = 8;   // random insertion orders tried each time the camera rests
  double idle_seconds = 0.5;     // how long the camera rests before they are tried
  double record_fps = 30.0;
  float ui_scale = 1.0f;
  bool show_panel = true;
  // ViewerSummary::gpu_span_ms gets every frame's span (for `bench view`'s quantiles); off, a
  // viewer left running for hours keeps no per-frame list.
  bool keep_frame_spans = false;
  // The placement beside the frames (LabelledRenderer::set_placement_beside): frames never wait
  // for it. Off while a debug view of the placement's buffers is shown. The optimisation on
  // idle's trials are then placements beside the frames too, never adopted.
  bool placement_beside = false;
  // Interactive rendering (a CPU device's default): while the camera moves, rays are cast for
  // every d-th pixel each way only, d chosen so that a frame takes about this long, and the
  // placement beside the frames waits until the camera rests; at rest, full resolution again.
  // 0: off.
  double frame_budget_ms = 0.0;
  // Labels placed are printed ("view: placed ..."); off where stdout holds a report (bench view).
  bool print_actions = true;
  // A title along the top (--title) and a legend of the scene's labels (--legend, `set legend`),
  // drawn over the picture and kept free of labels (labeling/annotations.h).
  std::string title;
  bool legend = false;
};

// Totals over a run, printed when the viewer closes and by `strata bench view`.
struct ViewerSummary {
  uint64_t frames = 0;
  double busy_seconds = 0.0;             // wall-clock time spent in frames
  std::map<std::string, double> gpu_ms;  // per pass: summed over the frames read back
  uint64_t timed_frames = 0;             // frames whose timings were read
  std::vector<double> gpu_span_ms;  // per frame read (keep_frame_spans): first to last pass's end
  uint64_t trials = 0;              // optimisation on idle: orders tried ...
  uint64_t adopted = 0;             // ... and kept
  // The placement beside the frames: placements the frames took up, their GPU time (first pass's
  // start to last pass's end) and the frames from each one's start to its take-up.
  uint64_t placements = 0;
  double placement_gpu_ms = 0.0;
  std::vector<uint32_t> placement_latency_frames;
  // Frames drawn while the camera moved, and their time; for each rest, the seconds from the
  // camera's last move to the first frame at full resolution with the placement of the rest.
  uint64_t moving_frames = 0;
  double moving_seconds = 0.0;
  uint32_t largest_divisor = 1;
  std::vector<double> refine_seconds;
};

// The viewer's own cut-aways (world mm, LPS), on every volume besides its scene's.
struct ViewerCuts {
  std::optional<std::array<glm::vec3, 2>> crop;  // a box; what lies outside it is cut away
  std::vector<glm::vec4> planes;  // clipping planes (n, w), |n| = 1: each keeps dot(n,p)+w >= 0
};
inline constexpr size_t kViewerPlanes = 6;  // clipping planes the viewer adds at most

class Viewer {
 public:
  Viewer(Context& ctx, Scene& scene, const Camera& camera, const LabellingSettings& settings,
         const ViewerOptions& options, ViewerOutput& output, GLFWwindow* window);
  ~Viewer();

  // Input, from the window's callbacks or an input script; positions in framebuffer pixels.
  // GLFW's codes: GLFW_MOUSE_BUTTON_*, GLFW_PRESS / GLFW_RELEASE, GLFW_MOD_*, GLFW_KEY_*.
  void mouse_button(int button, int action, int mods);
  void cursor(glm::vec2 position);
  void scroll(double ticks);
  void key(int key, int mods);
  // A command of the viewer's table (app/viewer/script_commands.inc, the commands scripts write),
  // applied once the next frame's UI is built, before the frame is drawn: what the keys and the
  // panel do. An Error it gives is shown in the panel.
  void submit(ScriptCommand command) { submitted_.push_back(std::move(command)); }
  // What a key does (the `key` command; GLFW_KEY_*).
  void press_key(int key);
  // Any event the UI took (it needs a frame or two to show its answer).
  void ui_event() { ui_frames_ = 3; }
  bool ui_wants_mouse() const { return ui_.wants_mouse(); }
  bool ui_wants_keyboard() const { return ui_.wants_keyboard(); }

  // Whether a frame is due: the camera moves, labels move or fade, trials run, the UI answers.
  // False: the viewer may sleep until the next event (or wake_in()); a recording draws anyway.
  // (Beside the frames a trial placement runs without frames: none is due meanwhile.)
  bool busy() const;
  // Nothing will change without input: no frame due, the optimisation on idle finished (or off,
  // or paused by a recording). Scripts run their next command at rest.
  bool at_rest() const { return !busy() && !optimisation_pending(); }
  // Seconds until something happens without input (the optimisation on idle), if anything will.
  std::optional<double> wake_in() const;
  // What keeps the viewer busy, in words ("2 labels moving or fading (Thalamus R, Insula L)").
  std::string unsettled() const;
  // The panel's rectangle in the last frame, [x0, y0, x1, y1] in pixels; empty when hidden.
  std::vector<uint32_t> panel_rect() const {
    if (panel_.x >= panel_.z) return {};
    return {panel_.x, panel_.y, panel_.z, panel_.w};
  }
  // One frame: UI, camera, labels, drawn and handed to the output. `seconds`: the time step
  // (default: the wall clock since the last frame, at most 0.25 s; a recording's 1 / fps).
  // A lost device is a DeviceLost naming the frame; a wait past the GPU timeout a GpuTimeout.
  void frame(std::optional<double> seconds = {});
  bool quit_requested() const { return quit_; }
  void request_quit() { quit_ = true; }

  // Actions (panel buttons, keys and scripts).
  void jump_to_position(size_t index);  // the scene's named position (keys 1-9), animated
  void view_from(AnatomicalView view);
  void reset_camera();
  // Volume `volume`'s transfer function becomes the preset `name` (transfer_function_presets.h),
  // seen through the volume's level, window and opacity.
  void set_preset(uint32_t volume, const std::string& name);
  // Volume `volume`'s level and window (centre and width in its own values: HU for CT).
  void set_window(uint32_t volume, float level, float window);
  // The labelled picture without the UI (PNG); the path written.
  std::filesystem::path screenshot(const std::filesystem::path& path = {});
  // The window's picture, UI included (PNG).
  void capture(const std::filesystem::path& path);
  // The layout of the last finished frame (layout JSON of `strata render --layout`).
  void write_layout(const std::filesystem::path& path);
  // Records every frame from now on into an MP4 (through `strata video`'s encoder) at a fixed
  // time step of 1 / fps, until stop_recording().
  void start_recording(const std::filesystem::path& path);
  void stop_recording();
  bool recording() const { return recorder_.on(); }
  // Sets a parameter by the name the panel and input scripts use (`viewer_parameters()`): from
  // text (scripts), a number or a flag (the panel). A bad name or value changes nothing.
  void set_parameter(const std::string& name, const std::string& value);
  void set_number(const std::string& name, float value);
  void set_flag(const std::string& name, bool value);
  void set_label_hidden(int id, bool hidden);
  void save_position(const std::string& name);

  // Labels of one's own (docs/viewer.md, "Your own labels"): anchored where the volume rendering
  // first becomes opaque under a pixel (picking, passes/picking.h), edited, undone, saved as 3D
  // Slicer markups. place_label: a new label at the point under `at` (framebuffer pixels), named
  // after the atlas region there, else "Label ID"; returns its id. An Error where the ray meets
  // only background (move_label too) or no label has the id.
  int place_label(glm::vec2 at);
  // The viewer's own cut-aways on every volume, besides its scene's (app/viewer/cut_aways.cpp): a
  // crop box (world mm, LPS) and up to six clipping planes; none: only the scene's. The panel's
  // Cut-aways section sets them; while on they are drawn over the picture with a handle on each
  // box face and each plane, which a left drag moves.
  void set_crop(std::optional<std::array<glm::vec3, 2>> box);
  void add_clip(glm::vec4 plane);  // (the normal is made unit length; an Error past six)
  void clear_clips();
  const ViewerCuts& cuts() const { return cuts_; }
  void set_label_text(int id, const std::string& text);
  void move_label(int id, glm::vec2 at);  // its anchor to the point under `at`
  void delete_label(int id);
  // Every edit above, undone and redone; false when there is nothing to.
  bool undo_labels();
  bool redo_labels();
  // The labels placed or edited (and those a label file opened with the scene added) as
  // .mrk.json or .fcsv (by extension), LPS or RAS; the scene's own labels, as its file holds
  // them, are left out (they load with the scene).
  void save_labels(const std::filesystem::path& path, LabelAxes axes = LabelAxes::lps);
  // Place mode (key P, the panel): a left click places a label instead of turning the view.
  bool place_mode() const { return place_mode_; }
  void set_place_mode(bool on);
  // The current camera (input scripts, tests), and a jump to another (benchmark paths).
  const Camera& camera() const { return control_.camera(); }
  void set_camera(const Camera& camera) { control_.set_camera(camera); }
  // Timestamps around every pass (the default), only where pass groups begin and end, or only
  // where the frame begins and ends (GraphRunner).
  graph::GraphRunner& runner() { return labelled_->runner(); }
  const ViewerSummary& summary() const { return summary_; }
  // The renderer's counters of the last frame read back.
  const RenderStats& render_stats() const { return labelled_->stats(); }
  // The HA-Buffer's slots from the next frame on (it grows from there when fragments overflow;
  // tests and `strata bench soak --habuffer-slots`). Waits for the frames in flight.
  void set_habuffer_slots(uint32_t slots);
  bool settled() const { return settled_; }
  // The picture's size now.
  graph::Extent extent() const { return output_.extent(); }

 private:
  struct SlotFrame {
    uint64_t generation = 0;  // LabelledRenderer's graph when recorded (0: never used)
    uint64_t serial = 0;      // the change serial the frame was made for
    int trial = -1;           // a trial frame's index, or -1
    uint32_t divisor = 1;     // every divisor-th pixel each way cast (interactive rendering)
  };
  void changed();
  void apply_camera();
  // Picks (LabelledRenderer::request_pick): a pixel whose point places a new label (no move_id)
  // or moves label move_id's anchor, as a drag (one undo for all its moves) or not.
  struct PendingPick {
    glm::vec2 at{0.0f};
    std::optional<int> move_id;  // (0 is a label's id too)
    bool drag = false;
  };
  void ask_pick(const PendingPick& pick);
  void apply_picks();
  void pick_now(const PendingPick& pick);
  void add_label(glm::vec3 point);
  std::optional<size_t> label_near(glm::vec2 at, bool anchor) const;
  void select_label(size_t index);
  size_t label_index(int id) const;
  // A label edit: the labels before it kept for undo, the scene's labels changed by `edit`, the
  // renderer made again for them.
  void edit_labels(const std::function<void(std::vector<Label>&)>& edit, bool undoable = true);
  bool restored_labels(bool done);
  graph::GraphRunner& prepare(uint32_t slot, graph::Extent extent, double seconds);
  void read_slot(uint32_t slot);
  int next_trial();
  // The optimisation on idle is pending (not every trial has come back), and due (the view has
  // rested since the last change).
  bool optimisation_pending() const;
  bool optimisation_due() const;
  // Trial `trial`'s cost came back; after the last one the cheapest order is kept if it beats
  // the baseline.
  void trial_back(int trial, double cost);
  void build_panel();
  void panel_labelling();
  void panel_forces();
  void panel_labels();
  void panel_rendering();
  void panel_camera();
  void panel_statistics();
  void panel_debug();
  void set_transfer(uint32_t volume);
  void commit_settings(const LabellingSettings& labels, const RenderSettings& render,
                       const ViewerOptions& viewer, bool reproject);
  // After a setting changed: anchors again if asked, the labels placed afresh, a new serial.
  void settings_changed(bool reproject);
  void extend_graph(graph::Graph& graph, const LabelledRenderer::GraphIds& ids);
  void read_latest();
  void draw_frame(std::optional<double> seconds);
  void apply_submitted();
  std::vector<uint8_t> download(graph::ResourceId image);

  Context& ctx_;
  Scene& scene_;
  ViewerOptions options_;
  ViewerOutput& output_;
  UiLayer ui_;
  CameraControl control_;
  std::unique_ptr<LabelledRenderer> labelled_;
  DebugView debug_;
  std::optional<DebugViewChoice> debug_choice_;
  graph::ResourceId display_id_ = 0;
  uint64_t generation_ = 0;  // bumped whenever the graph is rebuilt

  // Input.
  int drag_button_ = -1;  // GLFW button of the drag in progress
  bool drag_pan_ = false;
  glm::vec2 mouse_{0.0f};
  bool quit_ = false;
  std::vector<ScriptCommand> submitted_;  // commands from the keys and the panel (submit)
  int ui_frames_ = 3;                     // frames the UI still needs
  glm::uvec4 panel_{0u};  // the panel's rectangle this frame, x0 y0 x1 y1 (none: hidden)
  std::vector<uint32_t> moving_labels_;  // labels not yet on their targets (the last frame's)
  uint64_t checked_serial_ = ~0ull;      // the serial of that frame
  // Beside the frames: the first frame after the last change (LabelledRenderer::frame_number);
  // the view is not settled before a placement started from it or later is taken up.
  uint64_t change_frame_ = 0;
  bool placement_due_ = false;  // the last frame read had no such placement yet

  // Change tracking and idle.
  uint64_t serial_ = 1;
  Camera applied_camera_;
  std::chrono::steady_clock::time_point last_change_;
  std::chrono::steady_clock::time_point last_frame_;
  bool settled_ = false;
  std::vector<SlotFrame> slots_;
  uint32_t last_slot_ = 0;
  void count_placements();
  uint64_t beside_counted_ = 0;  // placements of the current PlacementBeside in the summary
  // Interactive rendering: whether the camera moves now, and the divisor for this frame.
  bool camera_moving() const;
  void choose_divisor(bool moving);
  double full_frame_ms_ = 0.0;  // the estimated time of a frame at full resolution
  uint32_t divisor_ = 1;
  std::chrono::steady_clock::time_point last_move_;
  bool refining_ = false;  // the camera rested; its full-quality frame has not come back yet

  // Optimisation on idle: random orders tried in trial frames (beside the frames: trial
  // placements, one at a time), the cheapest kept.
  IdleOptimisation optimisation_;
  bool trials_beside_ = false;  // the placement was beside the frames in the last frame

  // Panel state.
  std::vector<TransferFunction> original_tfs_;  // per volume: the scene's, or the preset chosen
  // The transfer function's 0..1 spread over [level - window / 2, level + window / 2] in the
  // volume's own values (HU for CT), as radiology sets them; the default spans its value range.
  struct VolumeLook {
    float level = 0.0f, window = 0.0f, opacity = 1.0f;
  };
  static VolumeLook default_look(const Volume& volume);
  std::vector<VolumeLook> looks_;
  std::vector<std::vector<glm::vec4>> scene_cuts_;  // each volume's cut-aways from the scene
  ViewerCuts cuts_;
  // The cut-aways while a face, a plane or a panel value is dragged: drawn at once, applied when
  // the button is let go.
  std::optional<ViewerCuts> cuts_dragged_;
  std::optional<int> hovered_handle_;  // the handle under the pointer
  // The handle dragged: 0-5 the box's faces (axis * 2 + high), 6 on the planes in their order.
  std::optional<int> handle_drag_;
  struct CutHandle {
    glm::vec3 at;         // world
    glm::vec3 direction;  // the way it moves: a face's axis, the plane's normal
  };
  std::vector<std::optional<CutHandle>> cut_handles(const ViewerCuts& cuts) const;
  std::optional<int> cut_handle_near(glm::vec2 at) const;
  bool press_cut_handle(int button, int action);  // true: a handle took the press or release
  void drag_cut_handle(glm::vec2 delta);
  void apply_cuts(const ViewerCuts& cuts);
  void panel_cut_aways();
  void draw_cut_aways();
  // The title and legend: their layout for this frame's size, font and labels (the same as the
  // last frame's unless one of those changed), drawn over the picture (and into screenshots).
  void update_annotations(graph::Extent extent);
  void draw_annotations() const;
  std::unique_ptr<Annotations> annotations_;
  std::string annotations_key_;  // what annotation_layout_ was made for
  AnnotationLayout annotation_layout_;
  char label_filter_[64] = "";
  char position_name_[64] = "";
  std::string message_;
  int picked_label_ = -1;    // the label selected in the panel (its index), -1: none
  int insertion_order_ = 0;  // 0 scene, 1 Apollonius (on rest)
  uint64_t apollonius_serial_ = 0;
  std::deque<float> frame_times_, gpu_times_;
  std::vector<graph::PassTiming> last_timings_;

  // Labels of one's own.
  bool place_mode_ = false;
  std::optional<int> anchor_drag_;          // the label (id) whose anchor the left button drags
  bool drag_undone_ = false;                // the drag's first move is on the undo stack
  std::deque<PendingPick> pending_picks_;   // asked, in the order asked
  std::optional<std::string> missed_pick_;  // the last pick that met only background
  glm::vec2 anchor_drag_from_{0.0f};
  glm::vec2 press_at_{0.0f};  // where the last button press was (a click selects a label)
  char edit_text_[256] = "";  // the panel's text of the selected label
  std::filesystem::path default_labels_path() const;  // Ctrl+S: SCENE-labels.mrk.json beside it
  LabelHistory history_;
  std::vector<Label> scene_labels_;  // the scene file's own labels (id, text and anchor)

  // Output.
  Recorder recorder_;
  // Where "save position" wrote the scene: the opened .json, or the new file made for a scene
  // from elsewhere (a volume, a thesis .xml); later saves go there too.
  std::filesystem::path saved_scene_path_;
  uint32_t screenshots_ = 0;
  ViewerSummary summary_;
};

}  // namespace strata::app
