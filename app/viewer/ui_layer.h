// Dear ImGui over the viewer's picture (Debian's libimgui with its GLFW and Vulkan backends): one
// graphics pass of the frame's graph draws the UI built since begin_frame() onto an rgba8 image.
// Without a window (`strata bench view`) the same UI is built and drawn, sized by hand.
#pragma once

#include <deque>

#include <vulkan/vulkan.h>

#include "engine/graph/render_graph.h"

struct GLFWwindow;

namespace strata {
class Context;
}

namespace strata::app {

class UiLayer {
 public:
  // `scale`: the monitor's content scale (HiDPI), applied to the font and every size.
  UiLayer(Context& ctx, GLFWwindow* window, float scale, uint32_t frames_in_flight);
  ~UiLayer();
  UiLayer(const UiLayer&) = delete;
  UiLayer& operator=(const UiLayer&) = delete;

  // Starts a UI frame of `size` pixels, `seconds` after the last (input from the window's
  // backend when there is one); ImGui calls follow until end_frame().
  void begin_frame(graph::Extent size, double seconds);
  void end_frame();
  // The pass that draws the last ended UI frame onto `image` (rgba8, viewport-sized).
  void add_to(graph::Graph& graph, graph::ResourceId image);

  // Whether the UI takes the mouse or keyboard input (over the panel, typing in a field).
  bool wants_mouse() const;
  bool wants_keyboard() const;
  float scale() const { return scale_; }

 private:
  void record(VkCommandBuffer cmd, VkImageView view, graph::Extent size);

  Context& ctx_;
  GLFWwindow* window_;
  float scale_;
  VkDescriptorPool descriptors_ = VK_NULL_HANDLE;
  VkRenderPass render_pass_ = VK_NULL_HANDLE;
  // Framebuffers of recent frames, destroyed once no frame in flight can use them.
  std::deque<VkFramebuffer> framebuffers_;
  uint32_t frames_in_flight_;
};

}  // namespace strata::app
