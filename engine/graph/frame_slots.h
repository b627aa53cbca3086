// Frames recorded while earlier ones still run on the GPU: a command buffer and a fence per frame
// slot, taken in turn. The interactive viewer keeps two in flight, so the CPU prepares and records
// one frame while the GPU renders the one before; a slot is reused once its last frame finished,
// and that frame's results (readbacks, timestamps of the same slot) are read then.
#pragma once

#include <span>
#include <vector>

#include <vulkan/vulkan.h>

namespace strata {

class Context;

class FrameSlots {
 public:
  // Submits to `queue` of queue family `family` (none: the frames' queue).
  FrameSlots(Context& ctx, uint32_t count, VkQueue queue = VK_NULL_HANDLE, uint32_t family = 0);
  ~FrameSlots();
  FrameSlots(const FrameSlots&) = delete;
  FrameSlots& operator=(const FrameSlots&) = delete;

  uint32_t count() const { return static_cast<uint32_t>(slots_.size()); }
  // The next slot in turn, once the frame it last held has finished (waits for it, at most the
  // Context's gpu_timeout(): GpuTimeout or DeviceLost naming that frame otherwise).
  uint32_t next();
  // The slot's command buffer, reset and begun.
  VkCommandBuffer begin(uint32_t slot);
  // Ends and submits the slot's command buffer; its fence signals when the frame has finished.
  void submit(uint32_t slot, std::span<const VkSemaphoreSubmitInfo> wait = {},
              std::span<const VkSemaphoreSubmitInfo> signal = {});
  // Waits until every submitted frame has finished (like next()).
  void wait_all();
  // Frames submitted so far; frame N (from 1) is the Nth.
  uint64_t submitted() const { return submitted_; }

 private:
  struct Slot {
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    VkFence done = VK_NULL_HANDLE;
    uint64_t frame = 0;    // the frame it last held (0: none)
    bool pending = false;  // submitted, not yet waited for (a failed submission never signals)
  };
  void wait(Slot& slot);
  Context& ctx_;
  VkQueue queue_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  std::vector<Slot> slots_;
  uint32_t turn_ = 0;
  uint64_t submitted_ = 0;
};

}  // namespace strata
