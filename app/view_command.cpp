#include <cstdio>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "app/commands.h"
#include "engine/graph_runner.h"
#include "engine/window_target.h"
#include "passes/test_pattern.h"

namespace strata::app {

void add_view_command(CLI::App& app, DeviceOptions& device) {
  CLI::App* cmd = app.add_subcommand("view", "Open the interactive viewer");
  struct Options {
    std::string size = "960x720";
    uint32_t frames = 0;
    uint32_t blur = 12;
  };
  auto options = std::make_shared<Options>();
  cmd->add_option("--size", options->size, "window size in screen units, N or WxH")
      ->capture_default_str();
  cmd->add_option("--frames", options->frames,
                  "close after this many frames (0: when the window closes)");
  cmd->add_option("--blur", options->blur, "box-filter radius of the demo's right half")
      ->capture_default_str();
  cmd->callback([&device, options] {
    const graph::Extent size = parse_size(options->size, "--size");
    Glfw glfw;
    ContextOptions context = device.context();
    context.instance_extensions = glfw.instance_extensions();
    context.presentation = true;
    Context ctx(context);

    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    glfwWindowHint(GLFW_SCALE_TO_MONITOR, GLFW_TRUE);  // HiDPI: the framebuffer follows the scale
    GLFWwindow* window = glfwCreateWindow(
        static_cast<int>(size.width), static_cast<int>(size.height), "strata", nullptr, nullptr);
    if (!window) throw strata::Error("cannot create a window of " + options->size);
    struct Closer {
      GLFWwindow* w;
      ~Closer() { glfwDestroyWindow(w); }
    } closer{window};

    TestPattern pattern(ctx);
    WindowTarget target(ctx, window);
    graph::Graph graph;
    target.add_output(graph, pattern.add_to(graph, options->blur));
    graph::GraphRunner runner(ctx, std::move(graph));
    uint32_t frames = 0;
    while (!glfwWindowShouldClose(window) && (options->frames == 0 || frames < options->frames)) {
      glfwPollEvents();
      if (target.draw(runner)) {
        ++frames;
      } else {
        glfwWaitEventsTimeout(0.1);  // minimised: sleep until something happens
      }
    }
    vkDeviceWaitIdle(ctx.device());
    double gpu_ms = 0.0;
    if (frames > 0) {
      for (const auto& t : runner.timings()) gpu_ms += t.ms;
    }
    std::printf("view: %u frames at %ux%u, last frame %.3f ms on the GPU\n", frames,
                target.extent().width, target.extent().height, gpu_ms);
  });
}

}  // namespace strata::app
