// The window target under a display (Xvfb in CI): frames are presented with validation silent,
// and the swapchain and the graph follow a resize.
#include <doctest/doctest.h>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "engine/graph/graph_runner.h"
#include "engine/graph/window_target.h"
#include "gpu_fixture.h"
#include "passes/test_pattern.h"

namespace strata {

TEST_SUITE("window") {
  TEST_CASE("window_presents_frames_and_follows_a_resize") {
    Glfw glfw;
    ContextOptions options;
    options.validation = true;
    options.quiet = true;
    options.presentation = true;
    options.instance_extensions = glfw.instance_extensions();
    Context ctx(options);
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    GLFWwindow* window = glfwCreateWindow(160, 120, "strata test", nullptr, nullptr);
    REQUIRE(window != nullptr);
    {
      TestPattern pattern(ctx);
      WindowTarget target(ctx, window);
      graph::Graph g;
      target.add_output(g, pattern.add_to(g, 4));
      graph::GraphRunner runner(ctx, std::move(g));
      runner.set_frames_in_flight(target.frames_in_flight());
      for (int i = 0; i < 3; ++i) CHECK(target.draw(runner));
      CHECK(target.extent() == graph::Extent{160, 120});
      CHECK(runner.viewport() == graph::Extent{160, 120});

      glfwSetWindowSize(window, 200, 90);
      for (int i = 0; i < 50; ++i) {
        glfwPollEvents();
        int w = 0, h = 0;
        glfwGetFramebufferSize(window, &w, &h);
        if (w == 200 && h == 90) break;
        glfwWaitEventsTimeout(0.02);
      }
      for (int i = 0; i < 3; ++i) target.draw(runner);
      CHECK(target.extent() == graph::Extent{200, 90});
      CHECK(runner.viewport() == graph::Extent{200, 90});
      CHECK(target.swapchain_recreations() >= 2);
      vkDeviceWaitIdle(ctx.device());
    }
    glfwDestroyWindow(window);
    for (const std::string& m : ctx.validation_log().take()) FAIL_CHECK("validation layer: " << m);
  }
}

}  // namespace strata
