#include "engine/graph/frame_slots.h"

#include "engine/core/error.h"
#include "engine/gpu/context.h"
#include "engine/gpu/vulkan_check.h"

namespace strata {

FrameSlots::FrameSlots(Context& ctx, uint32_t count, VkQueue queue, uint32_t family)
    : ctx_(ctx), queue_(queue ? queue : ctx.queue()) {
  if (count == 0) throw Error("frame slots: none asked for");
  VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool.queueFamilyIndex = queue ? family : ctx.queue_family();
  STRATA_VK(vkCreateCommandPool(ctx.device(), &pool, nullptr, &pool_));
  slots_.resize(count);
  for (Slot& s : slots_) {
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = pool_;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    STRATA_VK(vkAllocateCommandBuffers(ctx.device(), &alloc, &s.cmd));
    VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    fence.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    STRATA_VK(vkCreateFence(ctx.device(), &fence, nullptr, &s.done));
  }
}

FrameSlots::~FrameSlots() {
  // (never throws; after a device loss or a wait that timed out nothing is waited for, and
  // what the GPU may still use is left alone)
  if (!ctx_.drain() && !ctx_.may_destroy()) return;
  for (Slot& s : slots_) vkDestroyFence(ctx_.device(), s.done, nullptr);
  vkDestroyCommandPool(ctx_.device(), pool_, nullptr);
}

void FrameSlots::wait(Slot& slot) {
  if (!slot.pending) return;
  ctx_.wait_for(slot.done, "frame " + std::to_string(slot.frame));
  slot.pending = false;
}

uint32_t FrameSlots::next() {
  const uint32_t slot = turn_;
  wait(slots_[slot]);
  turn_ = (turn_ + 1) % count();
  return slot;
}

VkCommandBuffer FrameSlots::begin(uint32_t slot) {
  const VkCommandBuffer cmd = slots_.at(slot).cmd;
  STRATA_VK(vkResetCommandBuffer(cmd, 0));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  STRATA_VK(vkBeginCommandBuffer(cmd, &begin));
  return cmd;
}

void FrameSlots::submit(uint32_t slot, std::span<const VkSemaphoreSubmitInfo> wait,
                        std::span<const VkSemaphoreSubmitInfo> signal) {
  Slot& s = slots_.at(slot);
  STRATA_VK(vkEndCommandBuffer(s.cmd));
  STRATA_VK(vkResetFences(ctx_.device(), 1, &s.done));
  VkCommandBufferSubmitInfo cmd_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  cmd_info.commandBuffer = s.cmd;
  VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  submit.waitSemaphoreInfoCount = static_cast<uint32_t>(wait.size());
  submit.pWaitSemaphoreInfos = wait.data();
  submit.commandBufferInfoCount = 1;
  submit.pCommandBufferInfos = &cmd_info;
  submit.signalSemaphoreInfoCount = static_cast<uint32_t>(signal.size());
  submit.pSignalSemaphoreInfos = signal.data();
  s.frame = ++submitted_;
  const VkResult result = vkQueueSubmit2(queue_, 1, &submit, s.done);
  if (result == VK_ERROR_DEVICE_LOST)
    throw DeviceLost("submitting frame " + std::to_string(s.frame));
  check_vk(result, "vkQueueSubmit2");
  s.pending = true;
}

void FrameSlots::wait_all() {
  for (Slot& s : slots_) wait(s);
}

}  // namespace strata
