// What the host reads back after a frame (counters, placements): host-visible buffers the frame's
// last passes copy into, one per frame in flight, so that the host reads one frame's results
// while the next frame, already submitted, writes its own into another.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "engine/gpu/resources.h"
#include "engine/graph/render_graph.h"

namespace strata::graph {

class GraphRunner;

class Readback {
 public:
  Readback(Context& ctx, VkDeviceSize size);

  // Imports the readback into `graph` (a transfer_dst for the copy, read by the host after the
  // run); the buffer of the slot last chosen is bound.
  ResourceId import(Graph& graph, std::string name);
  // One buffer per frame in flight (zeroed); the slot goes back to 0.
  void set_slots(uint32_t slots);
  // The slot the next frame copies into and data() reads (after that slot's last frame has
  // finished): binds its buffer to `runner`.
  void use_slot(GraphRunner& runner, uint32_t slot);

  // The bytes of the current slot's last completed frame.
  std::span<const std::byte> data() const;
  VkDeviceSize size() const { return size_; }

 private:
  Context& ctx_;
  VkDeviceSize size_;
  std::vector<Buffer> buffers_;
  uint32_t slot_ = 0;
  ResourceId id_ = 0;
  bool imported_ = false;
};

}  // namespace strata::graph
