// `strata view`: the interactive viewer in a GLFW window (app/viewer.h), driven by the mouse and
// keys or by an input script that feeds it the same events (tests, demos).
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <nlohmann/json.hpp>

#include <backends/imgui_impl_glfw.h>

#include "app/commands.h"
#include "app/viewer.h"
#include "engine/core/text_file.h"
#include "engine/graph/graph_runner.h"
#include "engine/graph/window_target.h"
#include "engine/scene/io/scene_loader.h"
#include "labeling/camera_path.h"
#include "passes/test_pattern.h"

namespace strata::app {
namespace {

struct ViewOptions {
  SceneInput scene;
  std::string camera;
  std::string size = "960x720";
  std::string script;
  std::string screenshot_dir = ".";
  uint32_t frames = 0;
  uint32_t tidy_rounds = kViewerTidyRounds;
  uint32_t blur = 12;
  uint32_t frames_in_flight = 2;
  bool no_optimize = false;
  bool no_panel = false;
  float label_scale = 1.0f;  // times the display's content scale
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

// --- input scripts -----------------------------------------------------------------------------

// One line of an input script: a command and its words ('#' starts a comment).
struct ScriptLine {
  size_t number = 0;
  std::vector<std::string> words;
};

std::vector<ScriptLine> read_script(const std::string& path) {
  std::istringstream in(read_text_file(path));
  std::vector<ScriptLine> lines;
  std::string text;
  for (size_t n = 1; std::getline(in, text); ++n) {
    if (const size_t hash = text.find('#'); hash != std::string::npos) text.resize(hash);
    std::istringstream words(text);
    ScriptLine line{n, {}};
    for (std::string w; words >> w;) line.words.push_back(w);
    if (!line.words.empty()) lines.push_back(std::move(line));
  }
  return lines;
}

int key_code(const std::string& name) {
  static const std::map<std::string, int> named = {
      {"left", GLFW_KEY_LEFT}, {"right", GLFW_KEY_RIGHT},   {"up", GLFW_KEY_UP},
      {"down", GLFW_KEY_DOWN}, {"escape", GLFW_KEY_ESCAPE}, {"f12", GLFW_KEY_F12},
      {"F12", GLFW_KEY_F12},   {"space", GLFW_KEY_SPACE},
  };
  if (const auto it = named.find(name); it != named.end()) return it->second;
  if (name.size() == 1 && name[0] >= 'a' && name[0] <= 'z') return GLFW_KEY_A + (name[0] - 'a');
  if (name.size() == 1 && name[0] >= '0' && name[0] <= '9') return GLFW_KEY_0 + (name[0] - '0');
  throw Error("no key '" + name + "' (a-z, 0-9, left, right, up, down, escape, f12, space)");
}

int mouse_code(const std::string& name) {
  if (name == "left") return GLFW_MOUSE_BUTTON_LEFT;
  if (name == "right") return GLFW_MOUSE_BUTTON_RIGHT;
  if (name == "middle") return GLFW_MOUSE_BUTTON_MIDDLE;
  throw Error("no mouse button '" + name + "' (left, right, middle)");
}

float script_number(const std::string& word) {
  size_t used = 0;
  float v = 0.0f;
  try {
    v = std::stof(word, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != word.size()) throw Error("'" + word + "' is not a number");
  return v;
}

AnatomicalView view_named(const std::string& name) {
  if (const auto view = anatomical_view_named(name)) return *view;
  throw Error("no view '" + name + "' (anterior, posterior, left, right, superior, inferior)");
}

// Runs the script's commands, each once the viewer has settled (nothing moves, no frame due), so
// a script does the same whatever the device's speed.
class Script {
 public:
  Script(std::string path, std::vector<ScriptLine> lines)
      : path_(std::move(path)), lines_(std::move(lines)) {}

  bool done() const { return next_ >= lines_.size(); }
  // Frames the last command asked for that are still due.
  uint32_t frames_due() const { return frames_; }
  void frame_drawn() {
    if (frames_ > 0) --frames_;
  }
  // Whether a `sleep` is still running (the viewer processes events meanwhile).
  bool sleeping() const { return std::chrono::steady_clock::now() < wake_; }

  void run_next(Viewer& viewer);

 private:
  void run(Viewer& viewer, const std::vector<std::string>& w);
  std::string path_;
  std::vector<ScriptLine> lines_;
  size_t next_ = 0;
  uint32_t frames_ = 0;
  std::chrono::steady_clock::time_point wake_{};
};

void Script::run_next(Viewer& viewer) {
  const ScriptLine& line = lines_[next_++];
  try {
    run(viewer, line.words);
  } catch (const Error& e) {
    throw Error(path_ + ":" + std::to_string(line.number) + ": " + e.what());
  }
}

void Script::run(Viewer& viewer, const std::vector<std::string>& w) {
  const std::string& c = w[0];
  const auto need = [&](size_t n, const char* form) {
    if (w.size() != n) throw Error("'" + c + "' takes the form: " + form);
  };
  if (c == "drag") {
    // drag BUTTON X0 Y0 X1 Y1 [shift]: press, move in 8 steps, release
    if (w.size() != 6 && !(w.size() == 7 && w[6] == "shift")) {
      throw Error("'drag' takes the form: drag left|right|middle X0 Y0 X1 Y1 [shift]");
    }
    const int button = mouse_code(w[1]);
    const glm::vec2 from{script_number(w[2]), script_number(w[3])};
    const glm::vec2 to{script_number(w[4]), script_number(w[5])};
    const int mods = w.size() == 7 ? GLFW_MOD_SHIFT : 0;
    viewer.cursor(from);
    viewer.mouse_button(button, GLFW_PRESS, mods);
    for (int i = 1; i <= 8; ++i) viewer.cursor(from + (to - from) * (float(i) / 8.0f));
    viewer.mouse_button(button, GLFW_RELEASE, mods);
  } else if (c == "scroll") {
    need(2, "scroll TICKS");
    viewer.scroll(script_number(w[1]));
  } else if (c == "key") {
    need(2, "key NAME");
    viewer.key(key_code(w[1]), 0);
  } else if (c == "view") {
    need(2, "view anterior|posterior|left|right|superior|inferior");
    viewer.view_from(view_named(w[1]));
  } else if (c == "preset") {
    if (w.size() != 2 && w.size() != 3)
      throw Error("'preset' takes the form: preset NAME [VOLUME]");
    viewer.set_preset(w.size() == 3 ? uint32_t(script_number(w[2])) : 0u, w[1]);
  } else if (c == "set") {
    need(3, "set PARAMETER VALUE");
    viewer.set_parameter(w[1], w[2]);
  } else if (c == "hide" || c == "show") {
    need(2, "hide|show LABEL_ID");
    viewer.set_label_hidden(int(script_number(w[1])), c == "hide");
  } else if (c == "screenshot") {
    need(2, "screenshot FILE.png");
    viewer.screenshot(w[1]);
  } else if (c == "capture") {
    need(2, "capture FILE.png");
    viewer.capture(w[1]);
  } else if (c == "layout") {
    need(2, "layout FILE.json");
    viewer.write_layout(w[1]);
  } else if (c == "record") {
    if (w.size() == 3 && w[1] == "start") {
      viewer.start_recording(w[2]);
    } else if (w.size() == 2 && w[1] == "stop") {
      viewer.stop_recording();
    } else {
      throw Error("'record' takes the form: record start FILE.mp4 | record stop");
    }
  } else if (c == "frames") {
    need(2, "frames N");
    frames_ = uint32_t(script_number(w[1]));
  } else if (c == "sleep") {
    need(2, "sleep SECONDS");
    wake_ = std::chrono::steady_clock::now() +
            std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                std::chrono::duration<double>(script_number(w[1])));
  } else if (c == "save-position") {
    need(2, "save-position NAME");
    viewer.save_position(w[1]);
  } else if (c == "report") {
    need(2, "report FILE.json");
    nlohmann::json view = nlohmann::json::array();
    for (int col = 0; col < 4; ++col) {
      for (int row = 0; row < 4; ++row) view.push_back(viewer.camera().view[col][row]);
    }
    const nlohmann::json report = {{"frames", viewer.summary().frames},
                                   {"settled", viewer.settled()},
                                   {"busy", viewer.busy()},
                                   {"trials", viewer.summary().trials},
                                   {"view", view}};
    write_text_file(w[1], report.dump() + "\n");
  } else if (c == "quit") {
    viewer.request_quit();
  } else {
    throw Error("no command '" + c +
                "' (drag, scroll, key, view, preset, set, hide, show, screenshot, capture, layout, "
                "record, frames, sleep, save-position, report, quit)");
  }
}

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

void view_scene(DeviceOptions& device, const ViewOptions& o, graph::Extent size) {
  Glfw glfw;
  ContextOptions context = device.context();
  context.instance_extensions = glfw.instance_extensions();
  context.presentation = true;
  Context ctx(context);
  Scene scene = load_scene_reporting(o.scene, ctx);  // volumes checked against the device
  const Camera camera = camera_for(scene, o.camera);
  std::optional<Script> script;
  if (!o.script.empty()) script.emplace(o.script, read_script(o.script));
  const std::string title = "strata - " + std::filesystem::path(o.scene.file).filename().string();
  Window window(size, o.size, title);
  float scale_x = 1.0f, scale_y = 1.0f;
  glfwGetWindowContentScale(window.handle, &scale_x, &scale_y);

  LabellingSettings settings;
  settings.layer_count = o.scene.layer_count(scene);
  settings.placement.weights = scene.settings.weights;
  settings.placement.tidy_rounds = o.tidy_rounds;
  // HiDPI: label text and boxes follow the display's content scale, as the panel does.
  settings.label_scale = std::clamp(o.label_scale * std::max(scale_x, scale_y), 0.25f, 4.0f);
  ViewerOptions options;
  options.scene_path = o.scene.file;
  options.screenshot_dir = o.screenshot_dir;
  options.optimize_on_idle = !o.no_optimize;
  options.ui_scale = std::max(scale_x, scale_y);
  options.show_panel = !o.no_panel;
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

  while (!viewer.quit_requested()) {
    glfwPollEvents();
    if (script && !viewer.busy() && script->frames_due() == 0 && !script->sleeping()) {
      if (script->done()) break;
      script->run_next(viewer);
      continue;
    }
    // (a recording draws every frame, at its fixed time step; under a script, only those the
    // script asks for, so that its frame count is known)
    const bool due = viewer.busy() || (script ? script->frames_due() > 0 : viewer.recording());
    if (due) {
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
      "shift+left pan; keys: arrows, r reset, 1-9 positions, F12 screenshot, h panel, q)");
  auto o = std::make_shared<ViewOptions>();
  cmd->add_option("scene", o->scene.file,
                  "scene file (.json, or .xml of the thesis program), or a volume file or DICOM "
                  "folder; none: a test pattern");
  add_scene_input_options(cmd, o->scene);
  cmd->add_option("--camera", o->camera, "named camera position of the scene to start at");
  cmd->add_option("--size", o->size, "window size in screen units, N or WxH")
      ->capture_default_str();
  cmd->add_option("--frames", o->frames,
                  "close after this many frames (0: when the window closes)");
  cmd->add_option("--tidy-rounds", o->tidy_rounds, "rounds of the layout tidy-up per frame")
      ->check(CLI::Range(0u, TIDY_ROUNDS_MAX))
      ->capture_default_str();
  cmd->add_option("--script", o->script,
                  "input script: events and actions run one by one, each once the view has "
                  "settled (docs/viewer.md)");
  cmd->add_option("--screenshot-dir", o->screenshot_dir,
                  "where F12, the screenshot button and recordings write")
      ->capture_default_str();
  cmd->add_option("--frames-in-flight", o->frames_in_flight,
                  "frames recorded before the earlier ones finished, 1 to 3")
      ->check(CLI::Range(1, 3))
      ->capture_default_str();
  cmd->add_flag("--no-optimize", o->no_optimize,
                "do not try random insertion orders when the camera rests");
  cmd->add_flag("--no-panel", o->no_panel, "start with the panel hidden (h shows it)");
  cmd->add_option("--label-scale", o->label_scale,
                  "label text and boxes times this and the display's content scale (0.25 to 4)")
      ->check(CLI::Range(0.25f, 4.0f))
      ->capture_default_str();
  cmd->add_option("--blur", o->blur, "test pattern only: box-filter radius of its right half")
      ->capture_default_str();
  cmd->callback([&device, o] {
    const graph::Extent size = parse_size(o->size, "--size");
    if (o->scene.file.empty()) {
      view_pattern(device, *o, size);
    } else {
      view_scene(device, *o, size);
    }
  });
}

}  // namespace strata::app
