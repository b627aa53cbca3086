// Buffers and images with their own memory, moved not copied, freed with their owner.
// Device-local resources are filled through a staging buffer (upload) and read back through one
// (download); both wait on the GPU and are meant for setup and tests, never inside a frame (a
// frame takes its uploads as Uploads, recorded into it).
// Each allocation is checked against the device's limits first (an Error naming the limit and
// the bytes, not a driver failure) and counted in the Context (`Context::memory_use()`).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include <vulkan/vulkan.h>

namespace strata {

class Context;

enum class MemoryKind { device_local, host_upload, host_readback };

class Buffer {
 public:
  Buffer() = default;
  // `both_queues`: used by the frames' queue family and the placement's where they differ
  // (concurrent sharing: no ownership transfers).
  Buffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryKind kind,
         bool both_queues = false);
  ~Buffer();
  Buffer(Buffer&& other) noexcept;
  Buffer& operator=(Buffer&& other) noexcept;

  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  // Host-visible buffers stay mapped for their whole life; nullptr for device-local ones.
  std::byte* mapped() const { return mapped_; }

 private:
  void release();
  Context* ctx_ = nullptr;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  VkDeviceSize allocated_ = 0;  // the memory's size (counted in the Context)
  uint32_t memory_type_ = 0;
  std::byte* mapped_ = nullptr;
};

struct ImageDesc {
  VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
  VkExtent3D extent{1, 1, 1};
  VkImageType type = VK_IMAGE_TYPE_2D;
  VkImageUsageFlags usage = 0;
  uint32_t layers = 1;       // array layers (2D only)
  bool array = false;        // a 2D-array view even with one layer (shaders declare image2DArray)
  bool both_queues = false;  // as Buffer's
};

class Image {
 public:
  Image() = default;
  Image(Context& ctx, const ImageDesc& desc);
  ~Image();
  Image(Image&& other) noexcept;
  Image& operator=(Image&& other) noexcept;

  VkImage handle() const { return image_; }
  VkImageView view() const { return view_; }
  const ImageDesc& desc() const { return desc_; }

 private:
  void release();
  Context* ctx_ = nullptr;
  VkImage image_ = VK_NULL_HANDLE;
  VkImageView view_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize allocated_ = 0;
  uint32_t memory_type_ = 0;
  ImageDesc desc_;
};

// ---- barriers: the one place where a dependency becomes Vulkan's (the render graph's and the
// uploads' alike)

// One side of a dependency: the stages and the accesses of them.
struct SyncScope {
  VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_NONE;
  VkAccessFlags2 access = VK_ACCESS_2_NONE;
};

// The first mip's `layers` layers of an image of this format, depth or colour.
VkImageSubresourceRange whole_image(VkFormat format, uint32_t layers);
VkImageMemoryBarrier2 image_barrier(VkImage image, const VkImageSubresourceRange& range,
                                    VkImageLayout from, VkImageLayout to, SyncScope src,
                                    SyncScope dst);
// The whole buffer.
VkBufferMemoryBarrier2 buffer_barrier(VkBuffer buffer, SyncScope src, SyncScope dst);
// Records the barriers as one vkCmdPipelineBarrier2.
void record_barriers(VkCommandBuffer cmd, std::span<const VkImageMemoryBarrier2> images,
                     std::span<const VkBufferMemoryBarrier2> buffers = {});
// Records a global memory barrier.
void record_memory_barrier(VkCommandBuffer cmd, SyncScope src, SyncScope dst);

// Bytes per texel of the colour formats strata uses; throws for others.
uint32_t texel_size(VkFormat format);

// Records the update of `buffer` at `offset` with `data` (vkCmdUpdateBuffer, in pieces of at most
// the 65536 bytes it takes at once).
void record_update(VkCommandBuffer cmd, VkBuffer buffer, VkDeviceSize offset,
                   std::span<const std::byte> data);

// Copies for a command buffer someone else submits (a frame: GraphRunner::upload_in_next_frame)
// instead of a submission and a wait of their own. The data are staged when added; record()
// copies them and makes them visible to every later command. The staging memory lives as long as
// the Uploads, which must outlive the recorded commands' run; the destinations too.
class Uploads {
 public:
  // Into a buffer at offset 0.
  void add(Context& ctx, const Buffer& dst, std::span<const std::byte> data);
  // A whole image (2D or 3D, tightly packed texels; new: its contents are dropped), left in
  // `final_layout`.
  void add(Context& ctx, const Image& dst, std::span<const std::byte> data,
           VkImageLayout final_layout);
  bool empty() const { return items_.empty(); }
  // Moves what `later` holds to the end of these.
  void append(Uploads&& later);
  void record(VkCommandBuffer cmd) const;

 private:
  struct Item {
    Buffer staging;
    VkBuffer buffer = VK_NULL_HANDLE;  // or an image
    VkImage image = VK_NULL_HANDLE;
    ImageDesc desc{};
    VkImageLayout final_layout = VK_IMAGE_LAYOUT_UNDEFINED;
  };
  std::vector<Item> items_;
};

// Copies `data` into a device-local buffer at offset 0 and waits.
void upload(Context& ctx, const Buffer& dst, std::span<const std::byte> data);
// Fills a whole image (2D or 3D, tightly packed texels) and leaves it in `final_layout`; waits.
void upload(Context& ctx, const Image& dst, std::span<const std::byte> data,
            VkImageLayout final_layout);
// Reads a whole buffer back to the host and waits.
std::vector<std::byte> download(Context& ctx, const Buffer& src);
// Reads a 2D image (in `layout`, left in it) back as tightly packed texels and waits.
std::vector<std::byte> download(Context& ctx, const Image& src, VkImageLayout layout);

template <typename T>
std::span<const std::byte> as_bytes(const std::vector<T>& v) {
  return std::as_bytes(std::span(v));
}

template <typename T>
std::vector<T> download_as(Context& ctx, const Buffer& src) {
  const std::vector<std::byte> bytes = download(ctx, src);
  std::vector<T> out(bytes.size() / sizeof(T));
  std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
  return out;
}

}  // namespace strata
