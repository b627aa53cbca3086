// Rendering to a GLFW window: a surface, a swapchain that follows the framebuffer (resize, HiDPI
// scale, minimise), and frames in flight (FrameSlots: two by default). The graph's final rgba8
// image is blitted to the acquired swapchain image by a transfer pass, so the same graph feeds this
// and HeadlessTarget.
#pragma once

#include <functional>
#include <vector>

#include "engine/graph/frame_slots.h"
#include "engine/graph/graph_runner.h"

struct GLFWwindow;

namespace strata {

class Context;

// GLFW itself: initialised on construction, terminated on destruction.
class Glfw {
 public:
  Glfw();
  ~Glfw();
  Glfw(const Glfw&) = delete;
  Glfw& operator=(const Glfw&) = delete;
  // The instance extensions a Vulkan surface needs on this platform.
  std::vector<const char*> instance_extensions() const;
};

class WindowTarget {
 public:
  WindowTarget(Context& ctx, GLFWwindow* window, uint32_t frames_in_flight = 2);
  ~WindowTarget();
  WindowTarget(const WindowTarget&) = delete;
  WindowTarget& operator=(const WindowTarget&) = delete;

  // Adds the pass that blits `frame` (viewport-sized rgba8) to the swapchain image.
  void add_output(graph::Graph& graph, graph::ResourceId frame);
  // Draws and presents one frame, sizing the runner's viewport to the framebuffer. Returns false,
  // drawing nothing, while the window is minimised (framebuffer of zero size).
  bool draw(graph::GraphRunner& runner);
  // The same, with the frame prepared in between: once the frame slot is free (its last frame
  // finished: read its results now), `prepare(slot, extent)` sets the frame up and returns the
  // runner to record (it may build a new one); the runner has frames_in_flight() slots.
  using Prepare = std::function<graph::GraphRunner&(uint32_t slot, graph::Extent extent)>;
  bool draw(const Prepare& prepare);

  // Waits until every submitted frame has finished.
  void wait_idle();
  uint32_t frames_in_flight() const { return slots_.count(); }

  graph::Extent extent() const { return extent_; }
  uint32_t swapchain_recreations() const { return recreations_; }

 private:
  void create_swapchain(graph::Extent framebuffer);
  void destroy_swapchain_images();

  Context& ctx_;
  GLFWwindow* window_;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  graph::Extent extent_{};
  std::vector<VkImage> images_;
  std::vector<VkSemaphore> rendered_;  // one per swapchain image
  std::vector<VkSemaphore> acquired_;  // one per frame slot
  FrameSlots slots_;
  graph::ResourceId swapchain_id_ = 0;
  bool out_of_date_ = false;
  uint32_t recreations_ = 0;
};

}  // namespace strata
