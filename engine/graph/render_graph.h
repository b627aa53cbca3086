// The render graph: passes declare what they touch and how; compile() derives every barrier and
// image layout from those declarations alone (plain C++, no device, unit-tested), and GraphRunner
// (graph_runner.h) creates the resources, records the passes and times each one on the GPU.
//
// Passes run in the order they are added. A resource is transient (created by the graph, sized
// from the viewport) or imported (owned outside and handed over with its handle when imported: an
// uploaded volume, a buffer the host reads afterwards; only what changes from run to run, such as
// the swapchain image, is bound again before a run).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

namespace strata {
class ComputePipeline;
}

namespace strata::graph {

using ResourceId = uint32_t;
using PassId = uint32_t;

struct Extent {
  uint32_t width = 0;
  uint32_t height = 0;
  bool operator==(const Extent&) const = default;
};

enum class PassKind { compute, graphics, transfer };

// How a pass touches a resource. Writes that are not also reads (storage_write, transfer_dst,
// color_attachment) need no earlier content; every read (color_blend too) needs a writer or
// imported content.
enum class Use {
  sampled,             // image read through a sampler
  storage_read,        // storage buffer or image, read
  storage_write,       // storage buffer or image, overwritten
  storage_read_write,  // storage buffer or image, read and written (atomics, accumulation)
  uniform,             // uniform buffer
  indirect,            // indirect dispatch or draw arguments
  conditional,         // conditional-rendering predicates (PassContext::begin_conditional)
  color_attachment,    // rendered to (cleared or overwritten)
  color_blend,         // rendered onto: loaded, blended over, stored (a UI over the picture)
  depth_attachment,    // depth test and write
  transfer_src,
  transfer_dst,
  host_read,  // only as an import's final use: the host reads it after the run
  present,    // only as an import's final use: handed to the presentation engine
};

const char* to_string(Use use);

struct ResourceUse {
  ResourceId resource = 0;
  Use use = Use::storage_read;
  // Descriptor binding in the pass's shader (shaders/shared/*.h); PassContext::bind pushes it.
  std::optional<uint32_t> binding;
  uint32_t array_element = 0;  // for array bindings (e.g. one element per volume)
};

struct ImageInfo {
  VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
  // Size: the viewport when `fixed` is zero, else `fixed`.
  Extent fixed{};
  uint32_t layers = 1;  // more than one: a 2D array image (e.g. one layer per depth layer)
  bool array = false;   // a 2D-array view even with one layer
  // Its content is kept from one run to the next (a pass may skip writing it): each run starts
  // with the layout its last use left (every use must have the same one), and the runner puts a
  // new image in that layout (GraphRunner::allocation() counts new images).
  bool keep = false;
};

struct BufferInfo {
  std::function<VkDeviceSize(Extent viewport)> size;
};

// A buffer owned outside the graph: its handle, whether it holds content the passes may read,
// and how it must be left (host_read for a readback).
struct BufferImport {
  VkBuffer buffer = VK_NULL_HANDLE;  // null: bound before each run (GraphRunner::bind_buffer)
  bool has_content = false;
  std::optional<Use> final_use;
};

// An image owned outside the graph, with where it starts and how it must be left.
struct ImageImport {
  VkImage image = VK_NULL_HANDLE;  // null: bound before each run (a swapchain image)
  VkImageView view = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  bool has_content = false;
  VkImageLayout initial_layout = VK_IMAGE_LAYOUT_UNDEFINED;
  std::optional<Use> final_use;  // present, transfer_src, sampled, ...
  // The stage at which the outside producer's dependency ends (for a swapchain image, the wait
  // stage of the acquire semaphore), so the first barrier chains onto it.
  VkPipelineStageFlags2 initial_stage = VK_PIPELINE_STAGE_2_NONE;
};

// What compile() needs of either kind of import.
struct ImportInfo {
  bool has_content = false;
  VkImageLayout initial_layout = VK_IMAGE_LAYOUT_UNDEFINED;
  std::optional<Use> final_use;
  VkPipelineStageFlags2 initial_stage = VK_PIPELINE_STAGE_2_NONE;
};

class PassContext;

struct PassInfo {
  std::string name;
  PassKind kind = PassKind::compute;
  std::vector<ResourceUse> uses;
  std::function<void(PassContext&)> record;
  std::string group;  // timings of passes that share a group are also reported together
};

struct ResourceInfo {
  std::string name;
  bool is_image = false;
  bool imported = false;
  ImageInfo image;
  BufferInfo buffer;
  ImportInfo import;
  BufferImport imported_buffer;  // the handles an import came with
  ImageImport imported_image;
};

class Graph {
 public:
  ResourceId add_image(std::string name, ImageInfo info);
  ResourceId add_buffer(std::string name, BufferInfo info);
  ResourceId import_buffer(std::string name, BufferImport info);
  ResourceId import_image(std::string name, ImageImport info);
  PassId add_pass(PassInfo pass);

  const std::vector<ResourceInfo>& resources() const { return resources_; }
  const std::vector<PassInfo>& passes() const { return passes_; }

 private:
  std::vector<ResourceInfo> resources_;
  std::vector<PassInfo> passes_;
};

struct Barrier {
  ResourceId resource = 0;
  bool is_image = false;
  VkPipelineStageFlags2 src_stage = VK_PIPELINE_STAGE_2_NONE;
  VkAccessFlags2 src_access = VK_ACCESS_2_NONE;
  VkPipelineStageFlags2 dst_stage = VK_PIPELINE_STAGE_2_NONE;
  VkAccessFlags2 dst_access = VK_ACCESS_2_NONE;
  VkImageLayout old_layout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImageLayout new_layout = VK_IMAGE_LAYOUT_UNDEFINED;
};

// What one use of a resource means to Vulkan, in a pass of a given kind.
struct Access {
  VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_NONE;
  VkAccessFlags2 access = VK_ACCESS_2_NONE;
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;  // images only
  bool reads = false;
  bool writes = false;
};

Access access_of(Use use, PassKind kind, bool is_image);

struct CompiledGraph {
  std::vector<std::vector<Barrier>> pass_barriers;  // before each pass, in pass order
  std::vector<Barrier> final_barriers;              // after the last pass (imports' final uses)
  std::vector<VkFlags> usage;                       // per resource: VkImageUsageFlags or
                                                    // VkBufferUsageFlags derived from its uses
  // The layout of `resource` while `pass` runs (images; UNDEFINED when the pass does not use it).
  std::vector<std::vector<VkImageLayout>> layout;  // [pass][resource]
  std::vector<VkImageLayout> kept_layout;          // per resource: a kept image's one layout
};

// A graph that cannot run: the message names the pass and the resource.
class GraphError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

CompiledGraph compile(const Graph& graph);

// The compiled graph as text, one pass a paragraph: its uses (resource, how, binding) and the
// barriers before it, then the final barriers (`strata render --dump-graph`, tests).
std::string describe(const Graph& graph, const CompiledGraph& compiled);
// Barriers the graph emits in one run: before each pass and after the last.
size_t barrier_count(const CompiledGraph& compiled);

}  // namespace strata::graph
