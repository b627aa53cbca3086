// The viewer's recording: every frame drawn goes into an MP4 through FrameWriter (compressed on
// a worker thread). The frame itself copies its picture into a host buffer of its frame slot;
// the pixels are read when the slot comes round again, a frame or two later, so a recording
// waits for no frame in flight.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "engine/core/frame_writer.h"
#include "engine/gpu/resources.h"
#include "engine/graph/graph_runner.h"

namespace strata::app {

class Recorder {
 public:
  Recorder(Context& ctx, uint32_t slots);

  // The frame's copy of `picture` into the slot's buffer (nothing while not recording).
  void add_to(graph::Graph& graph, graph::ResourceId picture);
  // Frames from now on, `size` (made even: the encoder's) at `fps`, into `path`.
  void start(const std::filesystem::path& path, graph::Extent size, double fps);
  // The slot's last frame finished: its picture, if it was recorded, goes to the writer.
  void slot_free(uint32_t slot);
  // The next frame, recorded into `slot` by `runner`: recorded too while recording.
  void frame_in(graph::GraphRunner& runner, uint32_t slot);
  // Once every frame in flight has finished: their pictures written and the file put in place.
  // Returns the frames written.
  uint64_t finish();
  bool on() const { return writer_ != nullptr; }
  const std::filesystem::path& path() const { return path_; }

 private:
  Context& ctx_;
  Buffer idle_;                  // bound while not recording (the copy pass then records nothing)
  std::vector<Buffer> buffers_;  // per slot
  std::vector<std::optional<uint64_t>> frames_;  // per slot: the frame recorded there, if any
  std::unique_ptr<FrameWriter> writer_;
  std::filesystem::path path_;
  graph::Extent size_{};
  graph::ResourceId id_ = 0;
  uint64_t next_frame_ = 0;
  bool copy_ = false;  // the frame being recorded copies its picture
};

}  // namespace strata::app
