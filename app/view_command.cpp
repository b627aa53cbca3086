#include <cstdio>
#include <functional>
#include <optional>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "app/commands.h"
#include "engine/graph/graph_runner.h"
#include "engine/graph/window_target.h"
#include "engine/scene/io/scene_loader.h"
#include "passes/test_pattern.h"
#include "passes/volume_renderer.h"

namespace strata::app {
namespace {

struct ViewOptions {
  std::string scene;
  std::string camera;
  std::string size = "960x720";
  uint32_t frames = 0;
  uint32_t layers = 4;
  uint32_t blur = 12;
};

struct Window {
  GLFWwindow* handle = nullptr;
  Window(graph::Extent size, const std::string& text) {
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    glfwWindowHint(GLFW_SCALE_TO_MONITOR, GLFW_TRUE);  // HiDPI: the framebuffer follows the scale
    handle = glfwCreateWindow(int(size.width), int(size.height), "strata", nullptr, nullptr);
    if (!handle) throw Error("cannot create a window of " + text);
  }
  ~Window() { glfwDestroyWindow(handle); }
};

// Draws until the window closes (or `frames` frames); `before_frame` runs once the previous
// frame has finished, so it may read that frame's counters.
uint32_t run_loop(GLFWwindow* window, WindowTarget& target, graph::GraphRunner& runner,
                  uint32_t frames, const std::function<void()>& before_frame) {
  uint32_t drawn = 0;
  while (!glfwWindowShouldClose(window) && (frames == 0 || drawn < frames)) {
    glfwPollEvents();
    if (before_frame && drawn > 0) {
      target.wait_for_last_frame();
      before_frame();
    }
    if (target.draw(runner)) {
      ++drawn;
    } else {
      glfwWaitEventsTimeout(0.1);  // minimised: sleep until something happens
    }
  }
  return drawn;
}

void view(DeviceOptions& device, const ViewOptions& o) {
  const graph::Extent size = parse_size(o.size, "--size");
  std::optional<Scene> scene;
  if (!o.scene.empty()) {
    scene = load_scene_reporting(o.scene);
  }
  Glfw glfw;
  ContextOptions context = device.context();
  context.instance_extensions = glfw.instance_extensions();
  context.presentation = true;
  Context ctx(context);
  Window window(size, o.size);
  WindowTarget target(ctx, window.handle);
  graph::Graph graph;
  std::optional<TestPattern> pattern;
  std::optional<VolumeRenderer> renderer;
  if (scene) {
    RenderSettings settings;
    settings.layer_count = o.layers;
    renderer.emplace(ctx, *scene, settings);
    renderer->set_camera(camera_for(*scene, o.camera));
    target.add_output(graph, renderer->add_to(graph).final);
  } else {
    pattern.emplace(ctx);
    target.add_output(graph, pattern->add_to(graph, o.blur));
  }
  graph::GraphRunner runner(ctx, std::move(graph));
  RenderStats stats;
  char title[256] = "strata";
  const auto before_frame = [&] {
    if (!renderer) return;
    // The statistics of the frame that just finished; the table grows before the next one.
    stats = renderer->collect(runner);
    const graph::Extent e = runner.viewport();
    std::snprintf(title, sizeof title,
                  "strata - %u fragments, HA-Buffer load %.2f, overflow %u, %.1f samples per ray",
                  stats.fragments, stats.load_factor(), stats.overflow,
                  double(stats.samples) / (double(e.width) * e.height));
    glfwSetWindowTitle(window.handle, title);
  };
  if (renderer) runner.set_viewport(target.extent().width ? target.extent() : size);
  const uint32_t drawn = run_loop(window.handle, target, runner, o.frames, before_frame);
  vkDeviceWaitIdle(ctx.device());
  if (renderer) before_frame();
  double gpu_ms = 0.0;
  if (drawn > 0) {
    for (const auto& t : runner.timings()) gpu_ms += t.ms;
  }
  std::printf("view: %u frames at %ux%u, last frame %.3f ms on the GPU%s%s\n", drawn,
              target.extent().width, target.extent().height, gpu_ms, renderer ? "; " : "",
              renderer ? title + 9 : "");
}

}  // namespace

void add_view_command(CLI::App& app, DeviceOptions& device) {
  CLI::App* cmd = app.add_subcommand("view", "Open the interactive viewer");
  auto o = std::make_shared<ViewOptions>();
  cmd->add_option("scene", o->scene,
                  "scene file (.json, or .xml of the thesis program); none: a test pattern");
  cmd->add_option("--camera", o->camera, "named camera position of the scene");
  cmd->add_option("--size", o->size, "window size in screen units, N or WxH")
      ->capture_default_str();
  cmd->add_option("--frames", o->frames,
                  "close after this many frames (0: when the window closes)");
  cmd->add_option("--layers", o->layers, "depth layers, 1 to 8")->capture_default_str();
  cmd->add_option("--blur", o->blur, "test pattern only: box-filter radius of its right half")
      ->capture_default_str();
  cmd->callback([&device, o] { view(device, *o); });
}

}  // namespace strata::app
