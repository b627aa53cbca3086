// Shaders by name from the SPIR-V embedded at build time, and compute pipelines whose descriptor
// and push-constant layouts come from SPIR-V reflection: binding types are never typed in C++.
// Descriptors are pushed (VK_KHR_push_descriptor), so a pass needs no pools or sets.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <vulkan/vulkan.h>

namespace strata {

class Context;

// The SPIR-V of shaders/<name> (e.g. "summed_area_table_scan.comp"); throws Error if unknown.
std::span<const uint32_t> shader_code(std::string_view name);
std::vector<std::string_view> shader_names();

struct ShaderReflection {
  std::vector<VkDescriptorSetLayoutBinding> bindings;  // set 0, sorted by binding
  uint32_t push_constant_size = 0;
  std::array<uint32_t, 3> local_size{1, 1, 1};  // compute only
};

// Reads set-0 bindings, push-constant size and workgroup size; throws Error on bad SPIR-V or
// descriptors outside set 0.
ShaderReflection reflect(std::span<const uint32_t> spirv, VkShaderStageFlags stage,
                         std::string_view name);

// One resource for one binding (and array element); buffers bind whole, images with the layout
// they are in.
struct DescriptorResource {
  uint32_t binding = 0;
  uint32_t array_element = 0;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkSampler sampler = VK_NULL_HANDLE;
};

// What compute and graphics pipelines share: a layout reflected from their shaders, push
// descriptors and push constants.
class Pipeline {
 public:
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;
  // (the handles move; the moved-from pipeline holds none)
  Pipeline(Pipeline&& other) noexcept;
  Pipeline& operator=(Pipeline&&) = delete;
  virtual ~Pipeline();

  const std::string& name() const { return name_; }
  const ShaderReflection& reflection() const { return reflection_; }

  // Binds the pipeline and pushes one descriptor per reflected binding; throws Error naming the
  // pipeline and binding when `resources` leaves one out. Elements of an array binding that
  // `resources` does not name repeat its element 0 (so every element is valid).
  void bind(VkCommandBuffer cmd, std::span<const DescriptorResource> resources) const;
  void push_constants(VkCommandBuffer cmd, const void* data, uint32_t size) const;
  template <typename T>
  void push_constants(VkCommandBuffer cmd, const T& value) const {
    push_constants(cmd, &value, sizeof(T));
  }

 protected:
  Pipeline(Context& ctx, std::string name, ShaderReflection reflection, VkShaderStageFlags stages,
           VkPipelineBindPoint bind_point);
  VkShaderModule create_module(std::span<const uint32_t> code) const;

  Context* ctx_ = nullptr;
  VkDevice device_ = VK_NULL_HANDLE;
  std::string name_;
  ShaderReflection reflection_;
  VkShaderStageFlags stages_ = 0;
  VkPipelineBindPoint bind_point_ = VK_PIPELINE_BIND_POINT_COMPUTE;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  PFN_vkCmdPushDescriptorSetKHR push_descriptor_set_ = nullptr;
};

// One statistic the driver reports for a compiled pipeline (e.g. "Register Count": "64").
struct PipelineStatistic {
  std::string name;
  std::string value;
};

// A pipeline's name and its statistics (what passes hand to `strata bench`).
struct PipelineReport {
  std::string name;
  std::vector<PipelineStatistic> statistics;
};

class ComputePipeline : public Pipeline {
 public:
  ComputePipeline(Context& ctx, std::string_view shader);
  std::array<uint32_t, 3> local_size() const { return reflection_.local_size; }
  // What the driver reports about the compiled shader; empty unless
  // Context::pipeline_statistics().
  std::vector<PipelineStatistic> statistics() const;

 private:
  bool captured_ = false;
};

// `from`'s pipeline moved out (a pass made again keeps its pipelines: compiling them is slow on a
// CPU device), or, without one, a new pipeline of `shader`.
ComputePipeline reuse_or_create(Context& ctx, ComputePipeline* from, std::string_view shader);

// The compute pipelines of `shaders`, in that order, created on a thread each: a driver that
// compiles at creation takes them in parallel (lavapipe compiles at creation; docs/performance.md).
// The first error is thrown once every creation has ended.
std::vector<ComputePipeline> create_compute_pipelines(Context& ctx,
                                                      std::span<const std::string_view> shaders);

// Rasterisation state strata's graphics passes choose from; everything else is fixed (triangle
// lists, no vertex input: vertices are pulled from storage buffers; dynamic viewport/scissor).
struct GraphicsState {
  VkCullModeFlags cull = VK_CULL_MODE_NONE;
  std::vector<VkFormat> color_formats;  // dynamic rendering attachments; may be empty
  bool blend = false;                   // premultiplied-alpha "over" blending on every attachment
};

class GraphicsPipeline : public Pipeline {
 public:
  GraphicsPipeline(Context& ctx, std::string_view vertex_shader, std::string_view fragment_shader,
                   const GraphicsState& state);
};

// Workgroups needed to cover `items` with groups of `group` (ceil division).
inline uint32_t group_count(uint32_t items, uint32_t group) {
  return (items + group - 1) / group;
}

}  // namespace strata
