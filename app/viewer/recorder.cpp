#include "app/viewer/recorder.h"

#include <algorithm>
#include <cstring>
#include <utility>

#include "engine/core/error.h"

namespace strata::app {
namespace {

constexpr VkBufferUsageFlags kUsage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
// Frames compressed at once: the MP4's encoder runs on one worker beside the frames.
constexpr unsigned kWriterThreads = 2;

}  // namespace

Recorder::Recorder(Context& ctx, uint32_t slots)
    : ctx_(ctx),
      idle_(ctx, 4, kUsage, MemoryKind::host_readback),
      buffers_(slots),
      frames_(slots) {}

void Recorder::add_to(graph::Graph& graph, graph::ResourceId picture) {
  id_ = graph.import_buffer("view.recording", {.final_use = graph::Use::host_read});
  const graph::ResourceId buffer = id_;
  graph.add_pass({"view.record",
                  graph::PassKind::transfer,
                  {{picture, graph::Use::transfer_src}, {buffer, graph::Use::transfer_dst}},
                  [this, picture, buffer](graph::PassContext& pc) {
                    if (!copy_) return;
                    VkBufferImageCopy region{};
                    region.bufferRowLength = size_.width;
                    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                    // (a window made smaller while recording: the part it still has)
                    region.imageExtent = {std::min(size_.width, pc.viewport.width),
                                          std::min(size_.height, pc.viewport.height), 1};
                    vkCmdCopyImageToBuffer(pc.cmd, pc.image(picture),
                                           VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pc.buffer(buffer),
                                           1, &region);
                  },
                  "ui"});
}

void Recorder::start(const std::filesystem::path& path, graph::Extent size, double fps) {
  size_ = {size.width & ~1u, size.height & ~1u};
  if (size_.width == 0 || size_.height == 0) throw Error("no picture to record");
  writer_ =
      std::make_unique<FrameWriter>(path, FrameWriter::Settings{.format = FrameWriter::Format::mp4,
                                                                .width = size_.width,
                                                                .height = size_.height,
                                                                .fps = fps,
                                                                .threads = kWriterThreads});
  path_ = path;
  next_frame_ = 0;
  const VkDeviceSize bytes = VkDeviceSize(size_.width) * size_.height * 4;
  for (Buffer& b : buffers_) {
    if (b.size() != bytes) b = Buffer(ctx_, bytes, kUsage, MemoryKind::host_readback);
  }
  std::fill(frames_.begin(), frames_.end(), std::nullopt);
}

void Recorder::slot_free(uint32_t slot) {
  if (!frames_[slot]) return;
  frames_[slot].reset();
  if (!writer_) return;
  const std::byte* p = buffers_[slot].mapped();
  const auto* bytes = reinterpret_cast<const uint8_t*>(p);
  writer_->write({bytes, bytes + buffers_[slot].size()});
}

void Recorder::frame_in(graph::GraphRunner& runner, uint32_t slot) {
  copy_ = writer_ != nullptr;
  runner.bind_buffer(id_, copy_ ? buffers_[slot].handle() : idle_.handle());
  if (copy_) frames_[slot] = next_frame_++;
}

uint64_t Recorder::finish() {
  if (!writer_) return 0;
  // (the frames still in their slots, oldest first)
  std::vector<std::pair<uint64_t, uint32_t>> left;
  for (uint32_t s = 0; s < frames_.size(); ++s) {
    if (frames_[s]) left.emplace_back(*frames_[s], s);
  }
  std::sort(left.begin(), left.end());
  for (const auto& [frame, slot] : left) slot_free(slot);
  writer_->finish();
  const uint64_t written = writer_->frames();
  writer_.reset();
  copy_ = false;
  return written;
}

}  // namespace strata::app
