#include "engine/gpu/shader_library.h"

#include <algorithm>
#include <future>
#include <memory>
#include <utility>

#include <spirv_cross/spirv_cross_c.h>

#include "engine/gpu/context.h"
#include "engine/gpu/vulkan_check.h"

namespace strata {

// Defined in the build's generated embedded_shaders.cpp (cmake/Shaders.cmake).
const std::vector<std::pair<std::string_view, std::span<const uint32_t>>>& embedded_shaders();

std::span<const uint32_t> shader_code(std::string_view name) {
  for (const auto& [shader, code] : embedded_shaders()) {
    if (shader == name) return code;
  }
  throw Error("no shader named '" + std::string(name) + "' is built into strata");
}

std::vector<std::string_view> shader_names() {
  std::vector<std::string_view> names;
  for (const auto& entry : embedded_shaders()) names.push_back(entry.first);
  return names;
}

namespace {

struct SpvcContext {
  spvc_context handle = nullptr;
  SpvcContext() { spvc_context_create(&handle); }
  ~SpvcContext() { spvc_context_destroy(handle); }
};

struct ResourceKind {
  spvc_resource_type spvc;
  VkDescriptorType vulkan;
};

constexpr ResourceKind kResourceKinds[] = {
    {SPVC_RESOURCE_TYPE_UNIFORM_BUFFER, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
    {SPVC_RESOURCE_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SPVC_RESOURCE_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE},
    {SPVC_RESOURCE_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER},
    {SPVC_RESOURCE_TYPE_SEPARATE_IMAGE, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE},
    {SPVC_RESOURCE_TYPE_SEPARATE_SAMPLERS, VK_DESCRIPTOR_TYPE_SAMPLER},
};

}  // namespace

ShaderReflection reflect(std::span<const uint32_t> spirv, VkShaderStageFlags stage,
                         std::string_view name) {
  const std::string who = "shader '" + std::string(name) + "'";
  SpvcContext ctx;
  spvc_parsed_ir ir = nullptr;
  spvc_compiler compiler = nullptr;
  spvc_resources resources = nullptr;
  if (spvc_context_parse_spirv(ctx.handle, spirv.data(), spirv.size(), &ir) != SPVC_SUCCESS ||
      spvc_context_create_compiler(ctx.handle, SPVC_BACKEND_NONE, ir,
                                   SPVC_CAPTURE_MODE_TAKE_OWNERSHIP, &compiler) != SPVC_SUCCESS ||
      spvc_compiler_create_shader_resources(compiler, &resources) != SPVC_SUCCESS) {
    throw Error(who +
                ": SPIR-V reflection failed: " + spvc_context_get_last_error_string(ctx.handle));
  }

  ShaderReflection out;
  for (const ResourceKind& kind : kResourceKinds) {
    const spvc_reflected_resource* list = nullptr;
    size_t count = 0;
    spvc_resources_get_resource_list_for_type(resources, kind.spvc, &list, &count);
    for (size_t i = 0; i < count; ++i) {
      if (spvc_compiler_get_decoration(compiler, list[i].id, SpvDecorationDescriptorSet) != 0) {
        throw Error(who + ": '" + list[i].name + "' is outside descriptor set 0");
      }
      spvc_type type = spvc_compiler_get_type_handle(compiler, list[i].type_id);
      uint32_t array_size = 1;
      for (unsigned d = 0; d < spvc_type_get_num_array_dimensions(type); ++d) {
        array_size *= spvc_type_get_array_dimension(type, d);
      }
      VkDescriptorSetLayoutBinding binding{};
      binding.binding = spvc_compiler_get_decoration(compiler, list[i].id, SpvDecorationBinding);
      binding.descriptorType = kind.vulkan;
      binding.descriptorCount = array_size;
      binding.stageFlags = stage;
      out.bindings.push_back(binding);
    }
  }
  std::sort(out.bindings.begin(), out.bindings.end(),
            [](const auto& a, const auto& b) { return a.binding < b.binding; });

  const spvc_reflected_resource* push = nullptr;
  size_t push_count = 0;
  spvc_resources_get_resource_list_for_type(resources, SPVC_RESOURCE_TYPE_PUSH_CONSTANT, &push,
                                            &push_count);
  if (push_count > 0) {
    size_t size = 0;
    spvc_compiler_get_declared_struct_size(
        compiler, spvc_compiler_get_type_handle(compiler, push[0].base_type_id), &size);
    out.push_constant_size = static_cast<uint32_t>(size);
  }
  if (stage == VK_SHADER_STAGE_COMPUTE_BIT) {
    for (unsigned axis = 0; axis < 3; ++axis) {
      out.local_size[axis] = spvc_compiler_get_execution_mode_argument_by_index(
          compiler, SpvExecutionModeLocalSize, axis);
    }
  }
  return out;
}

namespace {

// Bindings of two stages merged: the same binding must have the same type and count in both.
ShaderReflection merge(const ShaderReflection& a, const ShaderReflection& b,
                       const std::string& name) {
  ShaderReflection out = a;
  for (const VkDescriptorSetLayoutBinding& binding : b.bindings) {
    auto it = std::find_if(out.bindings.begin(), out.bindings.end(),
                           [&](const auto& x) { return x.binding == binding.binding; });
    if (it == out.bindings.end()) {
      out.bindings.push_back(binding);
    } else if (it->descriptorType != binding.descriptorType ||
               it->descriptorCount != binding.descriptorCount) {
      throw Error(name + ": binding " + std::to_string(binding.binding) +
                  " differs between the vertex and fragment shaders");
    } else {
      it->stageFlags |= binding.stageFlags;
    }
  }
  std::sort(out.bindings.begin(), out.bindings.end(),
            [](const auto& x, const auto& y) { return x.binding < y.binding; });
  out.push_constant_size = std::max(a.push_constant_size, b.push_constant_size);
  return out;
}

}  // namespace

Pipeline::Pipeline(Context& ctx, std::string name, ShaderReflection reflection,
                   VkShaderStageFlags stages, VkPipelineBindPoint bind_point)
    : ctx_(&ctx),
      device_(ctx.device()),
      name_(std::move(name)),
      reflection_(std::move(reflection)),
      stages_(stages),
      bind_point_(bind_point) {
  VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set_info.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
  set_info.bindingCount = static_cast<uint32_t>(reflection_.bindings.size());
  set_info.pBindings = reflection_.bindings.data();
  STRATA_VK(vkCreateDescriptorSetLayout(device_, &set_info, nullptr, &set_layout_));

  const VkPushConstantRange range{stages_, 0, reflection_.push_constant_size};
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.setLayoutCount = 1;
  layout_info.pSetLayouts = &set_layout_;
  layout_info.pushConstantRangeCount = reflection_.push_constant_size > 0 ? 1 : 0;
  layout_info.pPushConstantRanges = &range;
  STRATA_VK(vkCreatePipelineLayout(device_, &layout_info, nullptr, &layout_));
  push_descriptor_set_ = reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(
      vkGetDeviceProcAddr(device_, "vkCmdPushDescriptorSetKHR"));
}

Pipeline::Pipeline(Pipeline&& other) noexcept
    : ctx_(other.ctx_),
      device_(other.device_),
      name_(std::move(other.name_)),
      reflection_(std::move(other.reflection_)),
      stages_(other.stages_),
      bind_point_(other.bind_point_),
      set_layout_(std::exchange(other.set_layout_, VK_NULL_HANDLE)),
      layout_(std::exchange(other.layout_, VK_NULL_HANDLE)),
      pipeline_(std::exchange(other.pipeline_, VK_NULL_HANDLE)),
      push_descriptor_set_(other.push_descriptor_set_) {}

Pipeline::~Pipeline() {
  if (!ctx_->may_destroy()) return;  // (a wait timed out: the GPU may still run it)
  vkDestroyPipeline(device_, pipeline_, nullptr);
  vkDestroyPipelineLayout(device_, layout_, nullptr);
  vkDestroyDescriptorSetLayout(device_, set_layout_, nullptr);
}

VkShaderModule Pipeline::create_module(std::span<const uint32_t> code) const {
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = code.size_bytes();
  info.pCode = code.data();
  VkShaderModule module = VK_NULL_HANDLE;
  STRATA_VK(vkCreateShaderModule(device_, &info, nullptr, &module));
  return module;
}

ComputePipeline::ComputePipeline(Context& ctx, std::string_view shader)
    : Pipeline(ctx, std::string(shader),
               reflect(shader_code(shader), VK_SHADER_STAGE_COMPUTE_BIT, shader),
               VK_SHADER_STAGE_COMPUTE_BIT, VK_PIPELINE_BIND_POINT_COMPUTE) {
  VkShaderModule module = create_module(shader_code(shader));
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module;
  info.stage.pName = "main";
  info.layout = layout_;
  captured_ = ctx.pipeline_statistics();
  if (captured_) info.flags = VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR;
  const VkResult result =
      vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_);
  vkDestroyShaderModule(device_, module, nullptr);
  check_vk(result, ("vkCreateComputePipelines(" + name_ + ")").c_str());
}

std::vector<PipelineStatistic> ComputePipeline::statistics() const {
  std::vector<PipelineStatistic> out;
  if (!captured_) return out;
  const auto get_executables = reinterpret_cast<PFN_vkGetPipelineExecutablePropertiesKHR>(
      vkGetDeviceProcAddr(device_, "vkGetPipelineExecutablePropertiesKHR"));
  const auto get_statistics = reinterpret_cast<PFN_vkGetPipelineExecutableStatisticsKHR>(
      vkGetDeviceProcAddr(device_, "vkGetPipelineExecutableStatisticsKHR"));
  if (!get_executables || !get_statistics) return out;
  const VkPipelineInfoKHR pipeline{VK_STRUCTURE_TYPE_PIPELINE_INFO_KHR, nullptr, pipeline_};
  uint32_t executables = 0;
  STRATA_VK(get_executables(device_, &pipeline, &executables, nullptr));
  for (uint32_t e = 0; e < executables; ++e) {
    const VkPipelineExecutableInfoKHR executable{VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR,
                                                 nullptr, pipeline_, e};
    uint32_t count = 0;
    STRATA_VK(get_statistics(device_, &executable, &count, nullptr));
    std::vector<VkPipelineExecutableStatisticKHR> stats(
        count, {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR});
    STRATA_VK(get_statistics(device_, &executable, &count, stats.data()));
    for (const VkPipelineExecutableStatisticKHR& s : stats) {
      std::string value;
      switch (s.format) {
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR:
          value = s.value.b32 ? "true" : "false";
          break;
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR:
          value = std::to_string(s.value.i64);
          break;
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR:
          value = std::to_string(s.value.u64);
          break;
        case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_FLOAT64_KHR:
          value = std::to_string(s.value.f64);
          break;
        default:
          continue;
      }
      out.push_back({s.name, value});
    }
  }
  return out;
}

ComputePipeline reuse_or_create(Context& ctx, ComputePipeline* from, std::string_view shader) {
  return from ? std::move(*from) : ComputePipeline(ctx, shader);
}

std::vector<ComputePipeline> create_compute_pipelines(Context& ctx,
                                                      std::span<const std::string_view> shaders) {
  std::vector<std::future<ComputePipeline>> pending;
  pending.reserve(shaders.size());
  for (std::string_view shader : shaders) {
    pending.push_back(
        std::async(std::launch::async, [&ctx, shader] { return ComputePipeline(ctx, shader); }));
  }
  // (a throw leaves the later futures to their destructors, which wait for their threads)
  std::vector<ComputePipeline> out;
  out.reserve(shaders.size());
  for (std::future<ComputePipeline>& p : pending) out.push_back(p.get());
  return out;
}

namespace {

VkPipelineShaderStageCreateInfo shader_stage(VkShaderStageFlagBits stage, VkShaderModule module) {
  VkPipelineShaderStageCreateInfo info{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  info.stage = stage;
  info.module = module;
  info.pName = "main";
  return info;
}

// Every colour attachment written whole; with state.blend, premultiplied "over".
std::vector<VkPipelineColorBlendAttachmentState> blend_attachments(const GraphicsState& state) {
  std::vector<VkPipelineColorBlendAttachmentState> attachments(state.color_formats.size());
  for (auto& a : attachments) {
    a.blendEnable = state.blend;
    a.srcColorBlendFactor = VK_BLEND_FACTOR_ONE;
    a.dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    a.colorBlendOp = VK_BLEND_OP_ADD;
    a.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    a.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    a.alphaBlendOp = VK_BLEND_OP_ADD;
    a.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                       VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
  }
  return attachments;
}

}  // namespace

GraphicsPipeline::GraphicsPipeline(Context& ctx, std::string_view vertex_shader,
                                   std::string_view fragment_shader, const GraphicsState& state)
    : Pipeline(ctx, std::string(vertex_shader) + "+" + std::string(fragment_shader),
               merge(reflect(shader_code(vertex_shader), VK_SHADER_STAGE_VERTEX_BIT, vertex_shader),
                     reflect(shader_code(fragment_shader), VK_SHADER_STAGE_FRAGMENT_BIT,
                             fragment_shader),
                     std::string(vertex_shader)),
               VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
               VK_PIPELINE_BIND_POINT_GRAPHICS) {
  VkShaderModule vertex = create_module(shader_code(vertex_shader));
  VkShaderModule fragment = create_module(shader_code(fragment_shader));
  const VkPipelineShaderStageCreateInfo stages[2] = {
      shader_stage(VK_SHADER_STAGE_VERTEX_BIT, vertex),
      shader_stage(VK_SHADER_STAGE_FRAGMENT_BIT, fragment)};

  VkPipelineVertexInputStateCreateInfo vertex_input{
      VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  VkPipelineInputAssemblyStateCreateInfo assembly{
      VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  viewport.viewportCount = 1;
  viewport.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo raster{
      VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = state.cull;
  raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  raster.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo multisample{
      VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo depth{
      VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  const std::vector<VkPipelineColorBlendAttachmentState> attachments = blend_attachments(state);
  VkPipelineColorBlendStateCreateInfo blend{
      VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  blend.attachmentCount = static_cast<uint32_t>(attachments.size());
  blend.pAttachments = attachments.data();
  const VkDynamicState dynamic_states[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
  dynamic.dynamicStateCount = 2;
  dynamic.pDynamicStates = dynamic_states;
  VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
  rendering.colorAttachmentCount = static_cast<uint32_t>(state.color_formats.size());
  rendering.pColorAttachmentFormats = state.color_formats.data();

  VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO, &rendering};
  info.stageCount = 2;
  info.pStages = stages;
  info.pVertexInputState = &vertex_input;
  info.pInputAssemblyState = &assembly;
  info.pViewportState = &viewport;
  info.pRasterizationState = &raster;
  info.pMultisampleState = &multisample;
  info.pDepthStencilState = &depth;
  info.pColorBlendState = &blend;
  info.pDynamicState = &dynamic;
  info.layout = layout_;
  const VkResult result =
      vkCreateGraphicsPipelines(device_, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_);
  vkDestroyShaderModule(device_, vertex, nullptr);
  vkDestroyShaderModule(device_, fragment, nullptr);
  check_vk(result, ("vkCreateGraphicsPipelines(" + name_ + ")").c_str());
}

void Pipeline::bind(VkCommandBuffer cmd, std::span<const DescriptorResource> resources) const {
  vkCmdBindPipeline(cmd, bind_point_, pipeline_);
  if (reflection_.bindings.empty()) return;
  size_t descriptors = 0;
  for (const auto& b : reflection_.bindings) descriptors += b.descriptorCount;
  std::vector<VkDescriptorBufferInfo> buffers;
  std::vector<VkDescriptorImageInfo> images;
  buffers.reserve(descriptors);
  images.reserve(descriptors);
  std::vector<VkWriteDescriptorSet> writes;
  for (const VkDescriptorSetLayoutBinding& b : reflection_.bindings) {
    const auto first =
        std::find_if(resources.begin(), resources.end(), [&](const DescriptorResource& r) {
          return r.binding == b.binding && r.array_element == 0;
        });
    if (first == resources.end()) {
      throw Error("shader '" + name_ + "': nothing bound to binding " + std::to_string(b.binding));
    }
    VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    write.dstBinding = b.binding;
    write.descriptorCount = b.descriptorCount;
    write.descriptorType = b.descriptorType;
    const bool is_buffer = b.descriptorType == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER ||
                           b.descriptorType == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    if (is_buffer)
      write.pBufferInfo = buffers.data() + buffers.size();
    else
      write.pImageInfo = images.data() + images.size();
    for (uint32_t element = 0; element < b.descriptorCount; ++element) {
      auto it = std::find_if(resources.begin(), resources.end(), [&](const DescriptorResource& r) {
        return r.binding == b.binding && r.array_element == element;
      });
      const DescriptorResource& r = it == resources.end() ? *first : *it;
      if (is_buffer)
        buffers.push_back({r.buffer, 0, VK_WHOLE_SIZE});
      else
        images.push_back({r.sampler, r.view, r.layout});
    }
    writes.push_back(write);
  }
  push_descriptor_set_(cmd, bind_point_, layout_, 0, static_cast<uint32_t>(writes.size()),
                       writes.data());
}

void Pipeline::push_constants(VkCommandBuffer cmd, const void* data, uint32_t size) const {
  if (size != reflection_.push_constant_size) {
    throw Error("shader '" + name_ + "': push constants are " +
                std::to_string(reflection_.push_constant_size) + " bytes, given " +
                std::to_string(size));
  }
  vkCmdPushConstants(cmd, layout_, stages_, 0, size, data);
}

}  // namespace strata
