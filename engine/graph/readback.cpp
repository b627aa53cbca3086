#include "engine/graph/readback.h"

#include <cstring>

#include "engine/core/error.h"
#include "engine/graph/graph_runner.h"

namespace strata::graph {

Readback::Readback(Context& ctx, VkDeviceSize size)
    : ctx_(ctx), size_(std::max<VkDeviceSize>(4, size)) {
  set_slots(1);
}

void Readback::set_slots(uint32_t slots) {
  if (slots == 0) throw Error("readback: no slots");
  while (buffers_.size() < slots) {
    Buffer& b = buffers_.emplace_back(ctx_, size_, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                      MemoryKind::host_readback);
    std::memset(b.mapped(), 0, size_);
  }
  buffers_.resize(slots);
  slot_ = 0;
}

ResourceId Readback::import(Graph& graph, std::string name) {
  id_ = graph.import_buffer(std::move(name),
                            {.buffer = buffers_[slot_].handle(), .final_use = Use::host_read});
  imported_ = true;
  return id_;
}

void Readback::use_slot(GraphRunner& runner, uint32_t slot) {
  if (slot >= buffers_.size()) {
    throw Error("readback: slot " + std::to_string(slot) + " of " +
                std::to_string(buffers_.size()));
  }
  slot_ = slot;
  if (imported_) runner.bind_buffer(id_, buffers_[slot_].handle());
}

std::span<const std::byte> Readback::data() const {
  return {buffers_[slot_].mapped(), size_};
}

}  // namespace strata::graph
