#include "engine/shader_library.h"

#include <algorithm>
#include <memory>
#include <utility>

#include <spirv_cross/spirv_cross_c.h>

#include "engine/context.h"
#include "engine/error.h"

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

ComputePipeline::ComputePipeline(Context& ctx, std::string_view shader)
    : device_(ctx.device()), name_(shader) {
  const std::span<const uint32_t> code = shader_code(shader);
  reflection_ = reflect(code, VK_SHADER_STAGE_COMPUTE_BIT, shader);

  VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set_info.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
  set_info.bindingCount = static_cast<uint32_t>(reflection_.bindings.size());
  set_info.pBindings = reflection_.bindings.data();
  STRATA_VK(vkCreateDescriptorSetLayout(device_, &set_info, nullptr, &set_layout_));

  const VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, reflection_.push_constant_size};
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.setLayoutCount = 1;
  layout_info.pSetLayouts = &set_layout_;
  layout_info.pushConstantRangeCount = reflection_.push_constant_size > 0 ? 1 : 0;
  layout_info.pPushConstantRanges = &range;
  STRATA_VK(vkCreatePipelineLayout(device_, &layout_info, nullptr, &layout_));

  VkShaderModuleCreateInfo module_info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  module_info.codeSize = code.size_bytes();
  module_info.pCode = code.data();
  VkShaderModule module = VK_NULL_HANDLE;
  STRATA_VK(vkCreateShaderModule(device_, &module_info, nullptr, &module));
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module;
  info.stage.pName = "main";
  info.layout = layout_;
  const VkResult result =
      vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_);
  vkDestroyShaderModule(device_, module, nullptr);
  check_vk(result, ("vkCreateComputePipelines(" + name_ + ")").c_str());

  push_descriptor_set_ = reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(
      vkGetDeviceProcAddr(device_, "vkCmdPushDescriptorSetKHR"));
}

ComputePipeline::~ComputePipeline() {
  vkDestroyPipeline(device_, pipeline_, nullptr);
  vkDestroyPipelineLayout(device_, layout_, nullptr);
  vkDestroyDescriptorSetLayout(device_, set_layout_, nullptr);
}

void ComputePipeline::bind(VkCommandBuffer cmd,
                           std::span<const DescriptorResource> resources) const {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
  if (reflection_.bindings.empty()) return;
  std::vector<VkDescriptorBufferInfo> buffers(reflection_.bindings.size());
  std::vector<VkDescriptorImageInfo> images(reflection_.bindings.size());
  std::vector<VkWriteDescriptorSet> writes;
  for (size_t i = 0; i < reflection_.bindings.size(); ++i) {
    const VkDescriptorSetLayoutBinding& b = reflection_.bindings[i];
    const auto it =
        std::find_if(resources.begin(), resources.end(),
                     [&](const DescriptorResource& r) { return r.binding == b.binding; });
    if (it == resources.end()) {
      throw Error("shader '" + name_ + "': nothing bound to binding " + std::to_string(b.binding));
    }
    VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    write.dstBinding = b.binding;
    write.descriptorCount = 1;
    write.descriptorType = b.descriptorType;
    if (b.descriptorType == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER ||
        b.descriptorType == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER) {
      buffers[i] = {it->buffer, 0, VK_WHOLE_SIZE};
      write.pBufferInfo = &buffers[i];
    } else {
      images[i] = {it->sampler, it->view, it->layout};
      write.pImageInfo = &images[i];
    }
    writes.push_back(write);
  }
  push_descriptor_set_(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0,
                       static_cast<uint32_t>(writes.size()), writes.data());
}

void ComputePipeline::push_constants(VkCommandBuffer cmd, const void* data, uint32_t size) const {
  if (size != reflection_.push_constant_size) {
    throw Error("shader '" + name_ + "': push constants are " +
                std::to_string(reflection_.push_constant_size) + " bytes, given " +
                std::to_string(size));
  }
  vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, size, data);
}

}  // namespace strata
