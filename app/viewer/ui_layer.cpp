#include "app/viewer/ui_layer.h"

#include <imgui.h>

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_vulkan.h>

#include "engine/core/error.h"
#include "engine/core/font.h"
#include "engine/gpu/context.h"
#include "engine/gpu/vulkan_check.h"
#include "engine/graph/graph_runner.h"

namespace strata::app {
namespace {

void check_imgui_vk(VkResult result) {
  if (result < 0) check_vk(result, "Dear ImGui's Vulkan backend");
}

}  // namespace

UiLayer::UiLayer(Context& ctx, GLFWwindow* window, float scale, uint32_t frames_in_flight)
    : ctx_(ctx), window_(window), scale_(scale), frames_in_flight_(frames_in_flight) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // the panel's layout is not saved between runs
  ImGui::StyleColorsDark();
  ImGui::GetStyle().ScaleAllSizes(scale);
  ImFontConfig config;
  config.OversampleH = 2;
  const std::string font = font_file();  // the labels' font
  if (!io.Fonts->AddFontFromFileTTF(font.c_str(), 15.0f * scale, &config)) {
    ImGui::DestroyContext();
    throw Error("cannot load the UI font " + font);
  }
  if (window_) ImGui_ImplGlfw_InitForVulkan(window_, false);  // the viewer forwards events

  const VkDescriptorPoolSize sizes[] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 8}};
  VkDescriptorPoolCreateInfo pool{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
  pool.maxSets = 8;
  pool.poolSizeCount = 1;
  pool.pPoolSizes = sizes;
  STRATA_VK(vkCreateDescriptorPool(ctx.device(), &pool, nullptr, &descriptors_));

  // Drawn over the picture the graph made: loaded, blended, stored, in the layout the graph
  // leaves it in for a color_blend use.
  VkAttachmentDescription color{};
  color.format = VK_FORMAT_R8G8B8A8_UNORM;
  color.samples = VK_SAMPLE_COUNT_1_BIT;
  color.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
  color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  color.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  color.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  color.initialLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  color.finalLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 1;
  subpass.pColorAttachments = &ref;
  VkRenderPassCreateInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  rp.attachmentCount = 1;
  rp.pAttachments = &color;
  rp.subpassCount = 1;
  rp.pSubpasses = &subpass;
  STRATA_VK(vkCreateRenderPass(ctx.device(), &rp, nullptr, &render_pass_));

  ImGui_ImplVulkan_InitInfo init{};
  init.Instance = ctx.instance();
  init.PhysicalDevice = ctx.physical_device();
  init.Device = ctx.device();
  init.QueueFamily = ctx.queue_family();
  init.Queue = ctx.queue();
  init.DescriptorPool = descriptors_;
  // Its vertex buffers, one per frame in flight, are rewritten when their frame comes round.
  init.MinImageCount = std::max(2u, frames_in_flight);
  init.ImageCount = std::max(2u, frames_in_flight);
  init.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
  init.CheckVkResultFn = check_imgui_vk;
  ImGui_ImplVulkan_Init(&init, render_pass_);
  ctx.run_now([](VkCommandBuffer cmd) { ImGui_ImplVulkan_CreateFontsTexture(cmd); });
  ImGui_ImplVulkan_DestroyFontUploadObjects();
}

UiLayer::~UiLayer() {
  // A lost or hung device: what the GPU may still use is left, not destroyed (Context::drain).
  if (!ctx_.drain()) return;
  for (VkFramebuffer f : framebuffers_) vkDestroyFramebuffer(ctx_.device(), f, nullptr);
  ImGui_ImplVulkan_Shutdown();
  if (window_) ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  vkDestroyRenderPass(ctx_.device(), render_pass_, nullptr);
  vkDestroyDescriptorPool(ctx_.device(), descriptors_, nullptr);
}

void UiLayer::begin_frame(graph::Extent size, double seconds) {
  ImGui_ImplVulkan_NewFrame();
  if (window_) {
    ImGui_ImplGlfw_NewFrame();
  }
  ImGuiIO& io = ImGui::GetIO();
  // The picture is drawn at framebuffer size: the UI too (its sizes carry the content scale).
  io.DisplaySize = ImVec2(float(size.width), float(size.height));
  io.DisplayFramebufferScale = ImVec2(1.0f, 1.0f);
  io.DeltaTime = float(std::max(seconds, 1e-4));
  ImGui::NewFrame();
}

void UiLayer::end_frame() {
  ImGui::Render();
}

bool UiLayer::wants_mouse() const {
  return ImGui::GetIO().WantCaptureMouse;
}

bool UiLayer::wants_keyboard() const {
  return ImGui::GetIO().WantCaptureKeyboard;
}

void UiLayer::add_to(graph::Graph& graph, graph::ResourceId image) {
  graph.add_pass(
      {"ui.draw",
       graph::PassKind::graphics,
       {{image, graph::Use::color_blend}},
       [this, image](graph::PassContext& pc) { record(pc.cmd, pc.view(image), pc.viewport); },
       "ui"});
}

void UiLayer::record(VkCommandBuffer cmd, VkImageView view, graph::Extent size) {
  // A framebuffer per frame: the image's view changes when the graph is rebuilt or resized.
  if (framebuffers_.size() > frames_in_flight_) {
    vkDestroyFramebuffer(ctx_.device(), framebuffers_.front(), nullptr);
    framebuffers_.pop_front();
  }
  VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  fb.renderPass = render_pass_;
  fb.attachmentCount = 1;
  fb.pAttachments = &view;
  fb.width = size.width;
  fb.height = size.height;
  fb.layers = 1;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  STRATA_VK(vkCreateFramebuffer(ctx_.device(), &fb, nullptr, &framebuffer));
  framebuffers_.push_back(framebuffer);

  VkRenderPassBeginInfo begin{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  begin.renderPass = render_pass_;
  begin.framebuffer = framebuffer;
  begin.renderArea = {{0, 0}, {size.width, size.height}};
  vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
  if (ImDrawData* data = ImGui::GetDrawData()) ImGui_ImplVulkan_RenderDrawData(data, cmd);
  vkCmdEndRenderPass(cmd);
}

}  // namespace strata::app
