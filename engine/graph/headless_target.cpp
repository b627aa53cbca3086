#include "engine/graph/headless_target.h"

namespace strata {

void HeadlessTarget::add_output(graph::Graph& graph, graph::ResourceId frame) {
  // (bound by bind(): its size follows the viewport)
  readback_id_ = graph.import_buffer("readback", {.final_use = graph::Use::host_read});
  const graph::ResourceId readback = readback_id_;
  graph.add_pass({"readback",
                  graph::PassKind::transfer,
                  {{frame, graph::Use::transfer_src}, {readback, graph::Use::transfer_dst}},
                  [frame, readback](graph::PassContext& pc) {
                    VkBufferImageCopy region{};
                    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                    region.imageExtent = {pc.viewport.width, pc.viewport.height, 1};
                    vkCmdCopyImageToBuffer(pc.cmd, pc.image(frame),
                                           VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                           pc.buffer(readback), 1, &region);
                  }});
}

void HeadlessTarget::bind(graph::GraphRunner& runner) {
  const graph::Extent e = runner.viewport();
  const VkDeviceSize size = VkDeviceSize{e.width} * e.height * 4;
  if (readback_.size() != size) {
    readback_ = Buffer(ctx_, size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryKind::host_readback);
  }
  runner.bind_buffer(readback_id_, readback_.handle());
}

std::span<const uint8_t> HeadlessTarget::pixels() const {
  return {reinterpret_cast<const uint8_t*>(readback_.mapped()), readback_.size()};
}

}  // namespace strata
