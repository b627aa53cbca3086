#include "engine/graph/second_queue.h"

#include "engine/gpu/context.h"
#include "engine/gpu/vulkan_check.h"

namespace strata::graph {

Timeline::Timeline(Context& ctx) : ctx_(ctx) {
  VkSemaphoreTypeCreateInfo type{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
  type.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
  VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &type};
  STRATA_VK(vkCreateSemaphore(ctx.device(), &info, nullptr, &semaphore_));
}

Timeline::~Timeline() {
  // (after a device loss or a wait that timed out, what the GPU may still use is left alone)
  if (ctx_.drain() || ctx_.may_destroy()) vkDestroySemaphore(ctx_.device(), semaphore_, nullptr);
}

uint64_t Timeline::value() const {
  uint64_t value = 0;
  STRATA_VK(vkGetSemaphoreCounterValue(ctx_.device(), semaphore_, &value));
  return value;
}

VkSemaphoreSubmitInfo Timeline::at(uint64_t value) const {
  VkSemaphoreSubmitInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  info.semaphore = semaphore_;
  info.value = value;
  info.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  return info;
}

SecondQueue::SecondQueue(Context& ctx)
    : slots_(ctx, 1, ctx.placement_queue(), ctx.placement_family()), fed_(ctx), finished_(ctx) {}

uint64_t SecondQueue::run_after(GraphRunner& frame, GraphRunner& graph) {
  const uint64_t k = ++started_;
  const uint32_t slot = slots_.next();
  graph.record(slots_.begin(slot), slot);
  FrameSubmission& submission = frame.submission();
  submission.signal.push_back(fed_.at(k));
  submission.submitted = [this, slot, k] {
    const VkSemaphoreSubmitInfo waits[] = {fed_.at(k), finished_.at(k - 1)};
    const VkSemaphoreSubmitInfo signal = finished_.at(k);
    slots_.submit(slot, waits, {&signal, 1});
  };
  return k;
}

void SecondQueue::wait_in(GraphRunner& frame, uint64_t run) const {
  frame.submission().wait.push_back(finished_.at(run));
}

}  // namespace strata::graph
