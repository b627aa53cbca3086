#include "engine/graph/window_target.h"

#include <algorithm>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "engine/gpu/context.h"
#include "engine/gpu/vulkan_check.h"

namespace strata {
namespace {

graph::Extent framebuffer_size(GLFWwindow* window) {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window, &w, &h);
  return {static_cast<uint32_t>(std::max(w, 0)), static_cast<uint32_t>(std::max(h, 0))};
}

VkSurfaceFormatKHR choose_format(VkPhysicalDevice device, VkSurfaceKHR surface) {
  uint32_t count = 0;
  vkGetPhysicalDeviceSurfaceFormatsKHR(device, surface, &count, nullptr);
  std::vector<VkSurfaceFormatKHR> formats(count);
  vkGetPhysicalDeviceSurfaceFormatsKHR(device, surface, &count, formats.data());
  if (formats.empty()) throw Error("the window surface offers no formats");
  // strata's frames hold display-ready values: prefer a UNORM swapchain (no second sRGB encode).
  for (const auto& f : formats) {
    if (f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM) return f;
  }
  return formats[0];
}

}  // namespace

Glfw::Glfw() {
  if (!glfwInit()) {
    const char* why = nullptr;
    glfwGetError(&why);
    throw Error(std::string("cannot open a window: ") + (why ? why : "GLFW failed to initialise") +
                " (is DISPLAY set? without a display use 'strata render')");
  }
  if (!glfwVulkanSupported()) {
    glfwTerminate();
    throw Error("cannot open a window: GLFW finds no Vulkan loader");
  }
}

Glfw::~Glfw() {
  glfwTerminate();
}

std::vector<const char*> Glfw::instance_extensions() const {
  uint32_t count = 0;
  const char** names = glfwGetRequiredInstanceExtensions(&count);
  return {names, names + count};
}

WindowTarget::WindowTarget(Context& ctx, GLFWwindow* window, uint32_t frames_in_flight)
    : ctx_(ctx), window_(window), slots_(ctx, frames_in_flight) {
  STRATA_VK(glfwCreateWindowSurface(ctx.instance(), window, nullptr, &surface_));
  VkBool32 supported = VK_FALSE;
  vkGetPhysicalDeviceSurfaceSupportKHR(ctx.physical_device(), ctx.queue_family(), surface_,
                                       &supported);
  if (!supported) throw Error("device '" + ctx.report().name + "' cannot present to this window");
  acquired_.resize(frames_in_flight);
  VkSemaphoreCreateInfo sem{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  for (VkSemaphore& s : acquired_) STRATA_VK(vkCreateSemaphore(ctx.device(), &sem, nullptr, &s));
}

WindowTarget::~WindowTarget() {
  VkDevice device = ctx_.device();
  if (!ctx_.drain() && !ctx_.may_destroy()) return;  // (a hung GPU may still use them)
  destroy_swapchain_images();
  vkDestroySwapchainKHR(device, swapchain_, nullptr);
  for (VkSemaphore s : acquired_) vkDestroySemaphore(device, s, nullptr);
  vkDestroySurfaceKHR(ctx_.instance(), surface_, nullptr);
}

void WindowTarget::add_output(graph::Graph& graph, graph::ResourceId frame) {
  // (bound to the acquired image before each frame)
  swapchain_id_ = graph.import_image(
      "swapchain",
      {.final_use = graph::Use::present, .initial_stage = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT});
  const graph::ResourceId target = swapchain_id_;
  graph.add_pass({"present.blit",
                  graph::PassKind::transfer,
                  {{frame, graph::Use::transfer_src}, {target, graph::Use::transfer_dst}},
                  [frame, target](graph::PassContext& pc) {
                    const auto w = static_cast<int32_t>(pc.viewport.width);
                    const auto h = static_cast<int32_t>(pc.viewport.height);
                    VkImageBlit region{};
                    region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                    region.srcOffsets[1] = {w, h, 1};
                    region.dstSubresource = region.srcSubresource;
                    region.dstOffsets[1] = {w, h, 1};
                    vkCmdBlitImage(pc.cmd, pc.image(frame), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                   pc.image(target), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                                   &region, VK_FILTER_NEAREST);
                  }});
}

void WindowTarget::destroy_swapchain_images() {
  for (VkSemaphore s : rendered_) vkDestroySemaphore(ctx_.device(), s, nullptr);
  rendered_.clear();
  images_.clear();
}

void WindowTarget::create_swapchain(graph::Extent framebuffer) {
  VkDevice device = ctx_.device();
  ctx_.wait_idle("the frames in flight (the swapchain is replaced)");
  VkSurfaceCapabilitiesKHR caps;
  STRATA_VK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(ctx_.physical_device(), surface_, &caps));
  const VkSurfaceFormatKHR format = choose_format(ctx_.physical_device(), surface_);
  graph::Extent extent = framebuffer;
  if (caps.currentExtent.width != UINT32_MAX)
    extent = {caps.currentExtent.width, caps.currentExtent.height};
  extent.width = std::clamp(extent.width, caps.minImageExtent.width, caps.maxImageExtent.width);
  extent.height = std::clamp(extent.height, caps.minImageExtent.height, caps.maxImageExtent.height);

  VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  info.surface = surface_;
  info.minImageCount = caps.maxImageCount ? std::min(caps.minImageCount + 1, caps.maxImageCount)
                                          : caps.minImageCount + 1;
  info.imageFormat = format.format;
  info.imageColorSpace = format.colorSpace;
  info.imageExtent = {extent.width, extent.height};
  info.imageArrayLayers = 1;
  info.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  info.presentMode = VK_PRESENT_MODE_FIFO_KHR;
  info.clipped = VK_TRUE;
  info.oldSwapchain = swapchain_;
  VkSwapchainKHR created = VK_NULL_HANDLE;
  STRATA_VK(vkCreateSwapchainKHR(device, &info, nullptr, &created));
  destroy_swapchain_images();
  vkDestroySwapchainKHR(device, swapchain_, nullptr);
  swapchain_ = created;
  format_ = format.format;
  extent_ = extent;
  out_of_date_ = false;
  ++recreations_;

  uint32_t count = 0;
  vkGetSwapchainImagesKHR(device, swapchain_, &count, nullptr);
  images_.resize(count);
  vkGetSwapchainImagesKHR(device, swapchain_, &count, images_.data());
  rendered_.resize(count);
  VkSemaphoreCreateInfo sem{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  for (VkSemaphore& s : rendered_) STRATA_VK(vkCreateSemaphore(device, &sem, nullptr, &s));
}

void WindowTarget::wait_idle() {
  slots_.wait_all();
}

bool WindowTarget::draw(graph::GraphRunner& runner) {
  return draw([&runner](uint32_t, graph::Extent) -> graph::GraphRunner& { return runner; });
}

bool WindowTarget::draw(const Prepare& prepare) {
  const graph::Extent framebuffer = framebuffer_size(window_);
  if (framebuffer.width == 0 || framebuffer.height == 0) return false;  // minimised
  if (!swapchain_ || out_of_date_ || !(framebuffer == extent_)) create_swapchain(framebuffer);

  const uint32_t slot = slots_.next();
  VkDevice device = ctx_.device();
  uint32_t index = 0;
  const VkResult acquired =
      vkAcquireNextImageKHR(device, swapchain_, static_cast<uint64_t>(ctx_.gpu_timeout().count()),
                            acquired_[slot], VK_NULL_HANDLE, &index);
  if (acquired == VK_TIMEOUT || acquired == VK_NOT_READY) {
    throw GpuTimeout(
        "the window's presentation engine gave no image to draw into within the GPU "
        "timeout (" +
        std::string(to_string(acquired)) + ")");
  }
  if (acquired == VK_ERROR_OUT_OF_DATE_KHR) {
    out_of_date_ = true;
    return false;
  }
  if (acquired != VK_SUBOPTIMAL_KHR) check_vk(acquired, "vkAcquireNextImageKHR");

  graph::GraphRunner& runner = prepare(slot, extent_);
  if (runner.frames_in_flight() < slots_.count()) {
    throw Error("window: the render graph keeps " + std::to_string(runner.frames_in_flight()) +
                " frames in flight, the window " + std::to_string(slots_.count()));
  }
  runner.set_viewport(extent_);
  runner.bind_image(swapchain_id_, images_[index], VK_NULL_HANDLE, format_);
  const VkCommandBuffer cmd = slots_.begin(slot);
  runner.record(cmd, slot);

  const graph::FrameSubmission& extra = runner.submission();
  std::vector<VkSemaphoreSubmitInfo> waits = extra.wait, signals = extra.signal;
  VkSemaphoreSubmitInfo& wait =
      waits.emplace_back(VkSemaphoreSubmitInfo{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO});
  wait.semaphore = acquired_[slot];
  wait.stageMask = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT;  // the blit; matches initial_stage
  VkSemaphoreSubmitInfo& signal =
      signals.emplace_back(VkSemaphoreSubmitInfo{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO});
  signal.semaphore = rendered_[index];
  signal.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  slots_.submit(slot, waits, signals);
  if (extra.submitted) extra.submitted();

  VkPresentInfoKHR present{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  present.waitSemaphoreCount = 1;
  present.pWaitSemaphores = &rendered_[index];
  present.swapchainCount = 1;
  present.pSwapchains = &swapchain_;
  present.pImageIndices = &index;
  const VkResult presented = vkQueuePresentKHR(ctx_.queue(), &present);
  if (presented == VK_ERROR_OUT_OF_DATE_KHR || presented == VK_SUBOPTIMAL_KHR) {
    out_of_date_ = true;
  } else {
    check_vk(presented, "vkQueuePresentKHR");
  }
  return true;
}

}  // namespace strata
