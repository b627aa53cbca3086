// `strata view`: the interactive viewer in a GLFW window (app/viewer/viewer.h), driven by the mouse and
// keys or by an input script that feeds it the same events (tests, demos).
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <nlohmann/json.hpp>

#include <backends/imgui_impl_glfw.h>

#include "app/annotation_options.h"
#include "app/commands.h"
#include "app/output_files.h"
#include "app/viewer/viewer.h"
#include "app/viewer/script_run.h"
#include "engine/core/text_file.h"
#include "engine/graph/graph_runner.h"
#include "engine/graph/window_target.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/value_limits.h"
#include "labeling/camera_path.h"
#include "passes/test_pattern.h"

namespace strata::app {
namespace {

struct ViewOptions {
  SceneInput scene;
  AnnotationOptions notes;
  std::string camera;
  std::string size = "960x720";
  std::string script;
  std::string screenshot_dir = ".";
  uint32_t frames = 0;
  uint32_t tidy_rounds = kViewerTidyRounds;
  uint32_t blur = 12;
  uint32_t frames_in_flight = 2;
  double settle_limit = 120.0;  // seconds a script waits for the view to settle
  bool no_optimize = false;
  bool no_panel = false;
  std::string placement = "auto";
  std::optional<double> frame_budget;  // ms; none: by the device's type
  float label_scale = 1.0f;            // times the display's content scale
  Background background;
};

struct Window {
  GLFWwindow* handle = nullptr;
  Window(graph::Extent size, const std::string& text, const std::string& title) {
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    glfwWindowHint(GLFW_SCALE_TO_MONITOR, GLFW_TRUE);  // HiDPI: the framebuffer follows the scale
    handle = glfwCreateWindow(int(size.width), int(size.height), title.c_str(), nullptr, nullptr);
    if (!handle) throw Error("cannot create a window of " + text);
  }
  ~Window() { glfwDestroyWindow(handle); }
};

// --- the window's events -----------------------------------------------------------------------

Viewer* g_viewer = nullptr;  // the GLFW callbacks' viewer (one window)

void on_mouse_button(GLFWwindow* window, int button, int action, int mods) {
  ImGui_ImplGlfw_MouseButtonCallback(window, button, action, mods);
  if (!g_viewer) return;
  g_viewer->ui_event();
  // (a drag that starts over the panel belongs to it; a release always ends the view's drag)
  if (action == GLFW_PRESS && g_viewer->ui_wants_mouse()) return;
  g_viewer->mouse_button(button, action, mods);
}

void on_cursor(GLFWwindow* window, double x, double y) {
  if (!g_viewer) return;
  // Window coordinates to framebuffer pixels (they differ where the platform scales windows).
  int w = 0, h = 0, fw = 0, fh = 0;
  glfwGetWindowSize(window, &w, &h);
  glfwGetFramebufferSize(window, &fw, &fh);
  const float sx = w > 0 ? float(fw) / float(w) : 1.0f, sy = h > 0 ? float(fh) / float(h) : 1.0f;
  g_viewer->cursor({float(x) * sx, float(y) * sy});
  if (g_viewer->ui_wants_mouse()) g_viewer->ui_event();
}

void on_scroll(GLFWwindow* window, double dx, double dy) {
  ImGui_ImplGlfw_ScrollCallback(window, dx, dy);
  if (!g_viewer) return;
  g_viewer->ui_event();
  if (!g_viewer->ui_wants_mouse()) g_viewer->scroll(dy);
}

void on_key(GLFWwindow* window, int key, int scancode, int action, int mods) {
  ImGui_ImplGlfw_KeyCallback(window, key, scancode, action, mods);
  if (!g_viewer) return;
  g_viewer->ui_event();
  if (action == GLFW_RELEASE || g_viewer->ui_wants_keyboard()) return;
  g_viewer->key(key, mods);
}

void on_char(GLFWwindow* window, unsigned int c) {
  ImGui_ImplGlfw_CharCallback(window, c);
  if (g_viewer) g_viewer->ui_event();
}

void on_close(GLFWwindow*) {
  if (g_viewer) g_viewer->request_quit();
}

void on_refresh(GLFWwindow*) {
  if (g_viewer) g_viewer->ui_event();  // exposed, resized, restored: draw again
}

// --- the labelled scene ------------------------------------------------------------------------

// A CPU device draws a frame of 512 x 512 in seconds: it renders fewer pixels while the camera
// moves, for 8 frames a second; a GPU renders every pixel.
double default_frame_budget_ms(const Context& ctx) {
  return ctx.report().type == VK_PHYSICAL_DEVICE_TYPE_CPU ? 125.0 : 0.0;
}

// Seconds between two pictures of the display (60 Hz where it does not say). FIFO presentation
// waits for them on a real display; a virtual one (Xvfb, a remote X server) takes pictures as
// fast as they come, and frames drawn faster than a display shows them are never seen.
double display_period() {
  const GLFWvidmode* mode = glfwGetVideoMode(glfwGetPrimaryMonitor());
  return 1.0 / double(mode && mode->refreshRate > 0 ? mode->refreshRate : 60);
}

void print_summary(const Viewer& viewer, const std::string& scene) {
  const ViewerSummary& s = viewer.summary();
  const graph::Extent e = viewer.extent();
  const RenderStats& stats = viewer.render_stats();
  std::printf(
      "view: %s, %llu frames at %ux%u, %.1f frames/s while drawing; HA-Buffer load %.2f, "
      "overflow %u\n",
      scene.c_str(), static_cast<unsigned long long>(s.frames), e.width, e.height,
      s.busy_seconds > 0 ? double(s.frames) / s.busy_seconds : 0.0, stats.load_factor(),
      stats.overflow);
  if (s.moving_frames > 0 || !s.refine_seconds.empty()) {
    double refine = 0.0, worst = 0.0;
    for (const double r : s.refine_seconds) {
      refine += r;
      worst = std::max(worst, r);
    }
    std::printf(
        "view: while the camera moved %llu frames, %.1f frames/s, %u x %u pixels to a ray at "
        "most; full quality %.2f s after it rested (mean of %zu, at most %.2f)\n",
        static_cast<unsigned long long>(s.moving_frames),
        s.moving_seconds > 0 ? double(s.moving_frames) / s.moving_seconds : 0.0, s.largest_divisor,
        s.largest_divisor,
        s.refine_seconds.empty() ? 0.0 : refine / double(s.refine_seconds.size()),
        s.refine_seconds.size(), worst);
  }
  if (s.placements > 0) {
    uint64_t latency = 0;
    for (const uint32_t l : s.placement_latency_frames) latency += l;
    std::printf(
        "view: placement beside the frames: %llu placements taken up, %.3f GPU ms each, %.2f "
        "frames from start to take-up\n",
        static_cast<unsigned long long>(s.placements), s.placement_gpu_ms / double(s.placements),
        double(latency) / double(s.placement_latency_frames.size()));
  }
  if (s.timed_frames == 0) return;
  double total = 0.0;
  std::printf("view: mean GPU ms per pass over %llu frames:",
              static_cast<unsigned long long>(s.timed_frames));
  for (const auto& [name, ms] : s.gpu_ms) {
    std::printf(" %s %.3f", name.c_str(), ms / double(s.timed_frames));
    total += ms;
  }
  std::printf("; whole frame %.3f\n", total / double(s.timed_frames));
  std::fflush(stdout);
}

// Events, script commands and frames until the viewer quits: a frame only when one is due, and
// no sooner than the display shows the last one.
void run_viewer(Viewer& viewer, std::optional<Script>& script, const ViewOptions& o) {
  const double period = display_period();
  auto last_drawn = std::chrono::steady_clock::now() - std::chrono::hours(1);
  while (!viewer.quit_requested()) {
    glfwPollEvents();
    if (script && script->frames_due() == 0 && !script->sleeping()) {
      if (viewer.at_rest()) {
        if (script->done()) break;
        script->run_next(viewer);
        continue;
      }
      script->wait_for(viewer);
    }
    // (a recording draws every frame, at its fixed time step; under a script, only those the
    // script asks for, so that its frame count is known)
    const bool due = viewer.busy() || (script ? script->frames_due() > 0 : viewer.recording());
    if (due) {
      const auto now = std::chrono::steady_clock::now();
      const double early = period - std::chrono::duration<double>(now - last_drawn).count();
      if (early > 0.001) {  // (not before the display shows the last frame; events meanwhile)
        glfwWaitEventsTimeout(early);
        continue;
      }
      last_drawn = now;
      viewer.frame();
      if (script) script->frame_drawn();
      if (o.frames > 0 && viewer.summary().frames >= o.frames) break;
      continue;
    }
    // Nothing to draw: sleep until an event (or the rest that starts the optimisation on idle).
    const std::optional<double> wake = viewer.wake_in();
    if (script && script->sleeping()) {
      glfwWaitEventsTimeout(0.02);
    } else if (wake) {
      glfwWaitEventsTimeout(std::max(0.01, *wake));
    } else {
      // (a timeout all the same: events that the presentation engine's own X requests read off
      // the connection while a frame was drawn wake no wait; the next poll finds them)
      glfwWaitEventsTimeout(0.25);
    }
  }
}

void view_scene(DeviceOptions& device, const ViewOptions& o, graph::Extent size) {
  std::optional<Script> script;  // (a script's mistakes are found before the window opens)
  if (!o.script.empty()) script.emplace(o.script, read_script(o.script), o.settle_limit);
  Glfw glfw;
  ContextOptions context = device.context();
  context.instance_extensions = glfw.instance_extensions();
  context.presentation = true;
  Context ctx(context);
  Scene scene = load_scene_reporting(o.scene, ctx);  // volumes checked against the device
  if (script) script->check_outputs(o.scene.labels);
  const Camera camera = option_camera(scene, o.camera);
  const std::string title = "strata - " + std::filesystem::path(o.scene.file).filename().string();
  Window window(size, o.size, title);
  float scale_x = 1.0f, scale_y = 1.0f;
  glfwGetWindowContentScale(window.handle, &scale_x, &scale_y);

  LabellingSettings settings;
  settings.layer_count = o.scene.layer_count(scene);
  settings.placement.weights = scene.settings.weights;
  settings.placement.tidy_rounds = o.tidy_rounds;
  settings.ghost.strength = scene.settings.ghost;
  settings.ghost.radius = scene.settings.ghost_radius;
  // HiDPI: label text and boxes follow the display's content scale, as the panel does.
  settings.label_scale = std::clamp(o.label_scale * std::max(scale_x, scale_y), 0.25f, 4.0f);
  settings.background = o.background;
  ViewerOptions options;
  options.scene_path = o.scene.file;
  options.screenshot_dir = o.screenshot_dir;
  options.optimize_on_idle = !o.no_optimize;
  options.ui_scale = std::max(scale_x, scale_y);
  options.show_panel = !o.no_panel;
  options.title = o.notes.title;
  options.legend = o.notes.legend;
  options.placement_beside = placement_beside(o.placement, ctx);
  options.frame_budget_ms = o.frame_budget.value_or(default_frame_budget_ms(ctx));
  WindowOutput output(ctx, window.handle, o.frames_in_flight);
  Viewer viewer(ctx, scene, camera, settings, options, output, window.handle);
  g_viewer = &viewer;
  struct Unset {
    ~Unset() { g_viewer = nullptr; }
  } unset;
  glfwSetMouseButtonCallback(window.handle, on_mouse_button);
  glfwSetCursorPosCallback(window.handle, on_cursor);
  glfwSetScrollCallback(window.handle, on_scroll);
  glfwSetKeyCallback(window.handle, on_key);
  glfwSetCharCallback(window.handle, on_char);
  glfwSetWindowCloseCallback(window.handle, on_close);
  glfwSetWindowRefreshCallback(window.handle, on_refresh);

  run_viewer(viewer, script, o);
  output.wait_idle();
  print_summary(viewer, o.scene.file);
}

// --- no scene: the test pattern ----------------------------------------------------------------

void view_pattern(DeviceOptions& device, const ViewOptions& o, graph::Extent size) {
  Glfw glfw;
  ContextOptions context = device.context();
  context.instance_extensions = glfw.instance_extensions();
  context.presentation = true;
  Context ctx(context);
  Window window(size, o.size, "strata - test pattern");
  WindowTarget target(ctx, window.handle);
  graph::Graph graph;
  TestPattern pattern(ctx);
  target.add_output(graph, pattern.add_to(graph, o.blur));
  graph::GraphRunner runner(ctx, std::move(graph));
  runner.set_frames_in_flight(target.frames_in_flight());
  glfwSetKeyCallback(window.handle, [](GLFWwindow* w, int key, int, int action, int) {
    if (action == GLFW_PRESS && (key == GLFW_KEY_Q || key == GLFW_KEY_ESCAPE)) {
      glfwSetWindowShouldClose(w, GLFW_TRUE);
    }
  });
  uint32_t drawn = 0;
  while (!glfwWindowShouldClose(window.handle) && (o.frames == 0 || drawn < o.frames)) {
    glfwPollEvents();
    if (target.draw(runner)) {
      ++drawn;
    } else {
      glfwWaitEventsTimeout(0.1);  // minimised: sleep until something happens
    }
    if (o.frames == 0) glfwWaitEvents();  // a still picture: drawn again on events only
  }
  target.wait_idle();
  std::printf("view: test pattern, %u frames at %ux%u\n", drawn, target.extent().width,
              target.extent().height);
}

}  // namespace

void add_view_command(CLI::App& app, DeviceOptions& device) {
  CLI::App* cmd = app.add_subcommand(
      "view",
      "Open the interactive viewer (mouse: left rotate, right/wheel zoom, middle or "
      "shift+left pan; keys: arrows, r reset, 1-9 positions, F12 screenshot, h panel, p place "
      "labels, ctrl+z/y undo/redo, ctrl+s save labels, q)");
  auto o = std::make_shared<ViewOptions>();
  cmd->add_option("scene", o->scene.file,
                  "scene file (.json, or .xml of the thesis program), or a volume file or DICOM "
                  "folder; none: a test pattern");
  add_scene_input_options(cmd, o->scene);
  cmd->add_option("--camera", o->camera, "named camera position of the scene to start at");
  cmd->add_option("--size", o->size, "window size in screen units, N or WxH")
      ->capture_default_str();
  cmd->add_option("--frames", o->frames, "close after this many frames (0: when the window closes)")
      ->check(whole_range(0, 1e9));
  add_tidy_rounds_option(cmd, o->tidy_rounds, "per frame");
  cmd->add_option("--script", o->script,
                  "input script: events and actions run one by one, each once the view has "
                  "settled (docs/viewer.md)");
  cmd->add_option("--settle-limit", o->settle_limit,
                  "seconds a script step waits for the view to settle before the script stops "
                  "with an error")
      ->check(finite_range(0.001, kScriptMaxSettle))
      ->capture_default_str();
  cmd->add_option("--screenshot-dir", o->screenshot_dir,
                  "where F12, the screenshot button and recordings write")
      ->capture_default_str();
  cmd->add_option("--frames-in-flight", o->frames_in_flight,
                  "frames recorded before the earlier ones finished, 1 to 3")
      ->check(whole_range(1, 3))
      ->capture_default_str();
  cmd->add_flag("--no-optimize", o->no_optimize,
                "do not try random insertion orders when the camera rests");
  cmd->add_flag("--no-panel", o->no_panel, "start with the panel hidden (h shows it)");
  add_annotation_options(cmd, o->notes);
  add_placement_option(cmd, o->placement);
  cmd->add_option("--frame-budget", o->frame_budget,
                  "ms a frame may take while the camera moves: rays for fewer pixels then, full "
                  "resolution at rest (default: 125 on a CPU device, 0 = off on a GPU)")
      ->check(finite_range(0.0, 10000.0));
  cmd->add_option("--label-scale", o->label_scale,
                  "label text and boxes times this and the display's content scale (0.25 to 4)")
      ->check(finite_range(0.25, 4.0))
      ->capture_default_str();
  add_background_option(cmd, o->background);
  cmd->add_option("--blur", o->blur, "test pattern only: box-filter radius of its right half")
      ->check(whole_range(0, 16384))
      ->capture_default_str();
  cmd->callback([cmd, &device, o] {
    const graph::Extent size = parse_size(o->size, "--size");
    if (o->background.transparent)
      throw UsageError("--background transparent: a window shows no alpha; give a colour");
    check_options_apply(cmd, !o->scene.file.empty(), {"--size", "--frames", "--frames-in-flight"},
                        {"--blur"});
    if (o->scene.file.empty()) {
      view_pattern(device, *o, size);
    } else {
      view_scene(device, *o, size);
    }
  });
}

}  // namespace strata::app
