#include "engine/gpu/resources.h"

#include <algorithm>
#include <utility>

#include "engine/gpu/context.h"
#include "engine/gpu/vulkan_check.h"

namespace strata {
namespace {

VkMemoryPropertyFlags properties_for(MemoryKind kind) {
  switch (kind) {
    case MemoryKind::device_local:
      return VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    case MemoryKind::host_upload:
      return VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    case MemoryKind::host_readback:
      return VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  }
  return 0;
}

// Readbacks are read by the CPU: from cached memory where the device has it (a GPU's uncached
// host memory reads a 1080p picture many times slower).
VkMemoryPropertyFlags preferred_for(MemoryKind kind) {
  return kind == MemoryKind::host_readback ? VK_MEMORY_PROPERTY_HOST_CACHED_BIT : 0;
}

// Memory for a buffer or an image (`what`), checked against the device's limits first and
// counted; `type` is set to the memory type taken.
VkDeviceMemory allocate(Context& ctx, const VkMemoryRequirements& req, VkMemoryPropertyFlags props,
                        const char* what, uint32_t& type, VkMemoryPropertyFlags preferred = 0) {
  VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  info.allocationSize = req.size;
  info.memoryTypeIndex = type = ctx.memory_type(req.memoryTypeBits, props, preferred);
  ctx.check_allocation(req.size, type, what);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  const VkResult result = vkAllocateMemory(ctx.device(), &info, nullptr, &memory);
  if (result == VK_ERROR_OUT_OF_DEVICE_MEMORY || result == VK_ERROR_OUT_OF_HOST_MEMORY) {
    const DeviceMemoryUse held = ctx.memory_use();
    throw Error(std::string(what) + " of " + std::to_string(req.size) +
                " bytes: " + to_string(result) + " from device '" + ctx.report().name +
                "' (strata holds " + std::to_string(held.bytes) + " bytes in " +
                std::to_string(held.allocations) + " allocations)");
  }
  check_vk(result, "vkAllocateMemory");
  ctx.count_allocation(type, req.size);
  return memory;
}

VkImageAspectFlags aspect_of(VkFormat format) {
  return format == VK_FORMAT_D32_SFLOAT ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
}

VkDeviceSize image_bytes(const ImageDesc& d) {
  return VkDeviceSize{d.extent.width} * d.extent.height * d.extent.depth * d.layers *
         texel_size(d.format);
}

// Makes the copies' writes so far visible to `dst`.
void copied_barrier(VkCommandBuffer cmd, SyncScope dst) {
  record_memory_barrier(cmd, {VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT}, dst);
}

// Makes a copy's writes visible to the host that reads the staging buffer after the fence.
void copy_to_host_barrier(VkCommandBuffer cmd) {
  copied_barrier(cmd, {VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT});
}

}  // namespace

Buffer::Buffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryKind kind,
               bool both_queues)
    : size_(size) {
  // (past maxBufferSize, vkCreateBuffer itself would be invalid usage)
  if (ctx.max_buffer() != 0 && size > ctx.max_buffer()) {
    throw Error("a buffer of " + std::to_string(size) + " bytes is more than device '" +
                ctx.report().name + "' allows (maxBufferSize: " + std::to_string(ctx.max_buffer()) +
                " bytes)");
  }
  const VkDevice device = ctx.device();
  if (kind == MemoryKind::device_local) {
    usage |= VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  }
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = usage;
  const uint32_t families[] = {ctx.queue_family(), ctx.placement_family()};
  if (both_queues && families[0] != families[1]) {
    info.sharingMode = VK_SHARING_MODE_CONCURRENT;
    info.queueFamilyIndexCount = 2;
    info.pQueueFamilyIndices = families;
  }
  STRATA_VK(vkCreateBuffer(device, &info, nullptr, &buffer_));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device, buffer_, &req);
  try {
    memory_ =
        allocate(ctx, req, properties_for(kind), "a buffer", memory_type_, preferred_for(kind));
  } catch (...) {
    vkDestroyBuffer(device, buffer_, nullptr);
    throw;
  }
  ctx_ = &ctx;  // (owns both from here: release() frees them)
  allocated_ = req.size;
  STRATA_VK(vkBindBufferMemory(device, buffer_, memory_, 0));
  if (kind != MemoryKind::device_local) {
    void* ptr = nullptr;
    STRATA_VK(vkMapMemory(device, memory_, 0, VK_WHOLE_SIZE, 0, &ptr));
    mapped_ = static_cast<std::byte*>(ptr);
  }
}

Buffer::~Buffer() {
  release();
}

Buffer::Buffer(Buffer&& other) noexcept {
  *this = std::move(other);
}

Buffer& Buffer::operator=(Buffer&& other) noexcept {
  if (this != &other) {
    release();
    ctx_ = std::exchange(other.ctx_, nullptr);
    buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    size_ = std::exchange(other.size_, 0);
    allocated_ = std::exchange(other.allocated_, 0);
    memory_type_ = other.memory_type_;
    mapped_ = std::exchange(other.mapped_, nullptr);
  }
  return *this;
}

void Buffer::release() {
  if (!ctx_) return;
  // (after a wait that timed out the GPU may still use it: left to the process's end)
  if (ctx_->may_destroy()) {
    vkDestroyBuffer(ctx_->device(), buffer_, nullptr);
    vkFreeMemory(ctx_->device(), memory_, nullptr);
    ctx_->count_free(memory_type_, allocated_);
  }
  ctx_ = nullptr;
}

Image::Image(Context& ctx, const ImageDesc& desc) : desc_(desc) {
  const VkDevice device = ctx.device();
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = desc.type;
  info.format = desc.format;
  info.extent = desc.extent;
  info.mipLevels = 1;
  info.arrayLayers = desc.layers;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = desc.usage | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  const uint32_t families[] = {ctx.queue_family(), ctx.placement_family()};
  if (desc.both_queues && families[0] != families[1]) {
    info.sharingMode = VK_SHARING_MODE_CONCURRENT;
    info.queueFamilyIndexCount = 2;
    info.pQueueFamilyIndices = families;
  }
  STRATA_VK(vkCreateImage(device, &info, nullptr, &image_));
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device, image_, &req);
  try {
    memory_ = allocate(ctx, req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, "an image", memory_type_);
  } catch (...) {
    vkDestroyImage(device, image_, nullptr);
    throw;
  }
  ctx_ = &ctx;
  allocated_ = req.size;
  STRATA_VK(vkBindImageMemory(device, image_, memory_, 0));

  VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  view.image = image_;
  view.viewType = desc.type == VK_IMAGE_TYPE_3D   ? VK_IMAGE_VIEW_TYPE_3D
                  : desc.layers > 1 || desc.array ? VK_IMAGE_VIEW_TYPE_2D_ARRAY
                                                  : VK_IMAGE_VIEW_TYPE_2D;
  view.format = desc.format;
  view.subresourceRange = {aspect_of(desc.format), 0, 1, 0, desc.layers};
  STRATA_VK(vkCreateImageView(device, &view, nullptr, &view_));
}

Image::~Image() {
  release();
}

Image::Image(Image&& other) noexcept {
  *this = std::move(other);
}

Image& Image::operator=(Image&& other) noexcept {
  if (this != &other) {
    release();
    ctx_ = std::exchange(other.ctx_, nullptr);
    image_ = std::exchange(other.image_, VK_NULL_HANDLE);
    view_ = std::exchange(other.view_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    allocated_ = std::exchange(other.allocated_, 0);
    memory_type_ = other.memory_type_;
    desc_ = other.desc_;
  }
  return *this;
}

void Image::release() {
  if (!ctx_) return;
  if (ctx_->may_destroy()) {
    vkDestroyImageView(ctx_->device(), view_, nullptr);
    vkDestroyImage(ctx_->device(), image_, nullptr);
    vkFreeMemory(ctx_->device(), memory_, nullptr);
    ctx_->count_free(memory_type_, allocated_);
  }
  ctx_ = nullptr;
}

void record_update(VkCommandBuffer cmd, VkBuffer buffer, VkDeviceSize offset,
                   std::span<const std::byte> data) {
  constexpr size_t kMost = 65536;
  for (size_t at = 0; at < data.size(); at += kMost) {
    vkCmdUpdateBuffer(cmd, buffer, offset + at, std::min(kMost, data.size() - at),
                      data.data() + at);
  }
}

namespace {

// Vulkan's barrier structs share the fields of the two scopes.
template <class Barrier>
Barrier scoped(Barrier barrier, SyncScope src, SyncScope dst) {
  barrier.srcStageMask = src.stage;
  barrier.srcAccessMask = src.access;
  barrier.dstStageMask = dst.stage;
  barrier.dstAccessMask = dst.access;
  return barrier;
}

}  // namespace

VkImageSubresourceRange whole_image(VkFormat format, uint32_t layers) {
  return {aspect_of(format), 0, 1, 0, layers};
}

VkImageMemoryBarrier2 image_barrier(VkImage image, const VkImageSubresourceRange& range,
                                    VkImageLayout from, VkImageLayout to, SyncScope src,
                                    SyncScope dst) {
  VkImageMemoryBarrier2 barrier =
      scoped(VkImageMemoryBarrier2{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2}, src, dst);
  barrier.oldLayout = from;
  barrier.newLayout = to;
  barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = image;
  barrier.subresourceRange = range;
  return barrier;
}

VkBufferMemoryBarrier2 buffer_barrier(VkBuffer buffer, SyncScope src, SyncScope dst) {
  VkBufferMemoryBarrier2 barrier =
      scoped(VkBufferMemoryBarrier2{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2}, src, dst);
  barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.buffer = buffer;
  barrier.size = VK_WHOLE_SIZE;
  return barrier;
}

void record_barriers(VkCommandBuffer cmd, std::span<const VkImageMemoryBarrier2> images,
                     std::span<const VkBufferMemoryBarrier2> buffers) {
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.bufferMemoryBarrierCount = static_cast<uint32_t>(buffers.size());
  dep.pBufferMemoryBarriers = buffers.data();
  dep.imageMemoryBarrierCount = static_cast<uint32_t>(images.size());
  dep.pImageMemoryBarriers = images.data();
  vkCmdPipelineBarrier2(cmd, &dep);
}

void record_memory_barrier(VkCommandBuffer cmd, SyncScope src, SyncScope dst) {
  const VkMemoryBarrier2 memory = scoped(VkMemoryBarrier2{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2}, src, dst);
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.memoryBarrierCount = 1;
  dep.pMemoryBarriers = &memory;
  vkCmdPipelineBarrier2(cmd, &dep);
}

uint32_t texel_size(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_R8G8B8A8_SRGB:
    case VK_FORMAT_B8G8R8A8_UNORM:
    case VK_FORMAT_B8G8R8A8_SRGB:
    case VK_FORMAT_R32_SFLOAT:
    case VK_FORMAT_R32_UINT:
    case VK_FORMAT_D32_SFLOAT:
      return 4;
    case VK_FORMAT_R16G16B16A16_SFLOAT:
    case VK_FORMAT_R16G16B16A16_SNORM:
      return 8;
    case VK_FORMAT_R32G32B32A32_SFLOAT:
      return 16;
    case VK_FORMAT_R8_UNORM:
      return 1;
    case VK_FORMAT_R16_UNORM:
    case VK_FORMAT_R16_SFLOAT:
      return 2;
    default:
      throw Error("texel_size: format " + std::to_string(format) + " is not one strata uses");
  }
}

namespace {

void transition(VkCommandBuffer cmd, VkImage image, const ImageDesc& desc, VkImageLayout from,
                VkImageLayout to, SyncScope src, SyncScope dst) {
  const VkImageMemoryBarrier2 barrier =
      image_barrier(image, whole_image(desc.format, desc.layers), from, to, src, dst);
  record_barriers(cmd, {&barrier, 1});
}

Buffer staged(Context& ctx, std::span<const std::byte> data) {
  Buffer staging(ctx, data.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryKind::host_upload);
  std::memcpy(staging.mapped(), data.data(), data.size());
  return staging;
}

}  // namespace

void Uploads::add(Context& ctx, const Buffer& dst, std::span<const std::byte> data) {
  if (data.size() > dst.size()) throw Error("upload: data larger than the buffer");
  if (data.empty()) return;
  items_.push_back({staged(ctx, data), dst.handle()});
}

void Uploads::add(Context& ctx, const Image& dst, std::span<const std::byte> data,
                  VkImageLayout final_layout) {
  const VkDeviceSize size = image_bytes(dst.desc());
  if (data.size() != size) {
    throw Error("upload: " + std::to_string(data.size()) + " bytes for an image of " +
                std::to_string(size));
  }
  items_.push_back({staged(ctx, data), VK_NULL_HANDLE, dst.handle(), dst.desc(), final_layout});
}

void Uploads::append(Uploads&& later) {
  for (Item& item : later.items_) items_.push_back(std::move(item));
  later.items_.clear();
}

void Uploads::record(VkCommandBuffer cmd) const {
  if (items_.empty()) return;
  for (const Item& item : items_) {
    if (item.buffer != VK_NULL_HANDLE) {
      const VkBufferCopy region{0, 0, item.staging.size()};
      vkCmdCopyBuffer(cmd, item.staging.handle(), item.buffer, 1, &region);
      continue;
    }
    // (a new image: it starts undefined, and is handed to every later stage in final_layout)
    transition(cmd, item.image, item.desc, VK_IMAGE_LAYOUT_UNDEFINED,
               VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, {},
               {VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT});
    VkBufferImageCopy region{};
    region.imageSubresource = {aspect_of(item.desc.format), 0, 0, item.desc.layers};
    region.imageExtent = item.desc.extent;
    vkCmdCopyBufferToImage(cmd, item.staging.handle(), item.image,
                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    transition(cmd, item.image, item.desc, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, item.final_layout,
               {VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT},
               {VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_READ_BIT});
  }
  copied_barrier(cmd, {VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_READ_BIT});
}

void upload(Context& ctx, const Buffer& dst, std::span<const std::byte> data) {
  Uploads uploads;
  uploads.add(ctx, dst, data);
  if (!uploads.empty()) ctx.run_now([&](VkCommandBuffer cmd) { uploads.record(cmd); });
}

void upload(Context& ctx, const Image& dst, std::span<const std::byte> data,
            VkImageLayout final_layout) {
  // (setup code outside any graph: the graph imports the image with content in final_layout)
  Uploads uploads;
  uploads.add(ctx, dst, data, final_layout);
  ctx.run_now([&](VkCommandBuffer cmd) { uploads.record(cmd); });
}

std::vector<std::byte> download(Context& ctx, const Buffer& src) {
  Buffer staging(ctx, src.size(), VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryKind::host_readback);
  ctx.run_now([&](VkCommandBuffer cmd) {
    const VkBufferCopy region{0, 0, src.size()};
    vkCmdCopyBuffer(cmd, src.handle(), staging.handle(), 1, &region);
    copy_to_host_barrier(cmd);
  });
  return {staging.mapped(), staging.mapped() + src.size()};
}

std::vector<std::byte> download(Context& ctx, const Image& src, VkImageLayout layout) {
  const ImageDesc& d = src.desc();
  const VkDeviceSize size = image_bytes(d);
  Buffer staging(ctx, size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryKind::host_readback);
  ctx.run_now([&](VkCommandBuffer cmd) {
    VkBufferImageCopy region{};
    region.imageSubresource = {aspect_of(d.format), 0, 0, d.layers};
    region.imageExtent = d.extent;
    vkCmdCopyImageToBuffer(cmd, src.handle(), layout, staging.handle(), 1, &region);
    copy_to_host_barrier(cmd);
  });
  return {staging.mapped(), staging.mapped() + size};
}

}  // namespace strata
