// Rendering without a window: the graph's final rgba8 image is copied into a host-visible buffer
// by a transfer pass at the end of the graph, then read on the host (PNG, tests, benchmarks).
#pragma once

#include <cstdint>
#include <span>

#include "engine/gpu/resources.h"
#include "engine/graph/graph_runner.h"

namespace strata {

class HeadlessTarget {
 public:
  explicit HeadlessTarget(Context& ctx) : ctx_(ctx) {}

  // Adds the readback pass of `frame` (a viewport-sized rgba8 image) to the graph.
  void add_output(graph::Graph& graph, graph::ResourceId frame);
  // Sizes the readback buffer for the runner's viewport and binds it.
  void bind(graph::GraphRunner& runner);
  // The pixels of the last completed run (rgba8, row-major).
  std::span<const uint8_t> pixels() const;

 private:
  Context& ctx_;
  graph::ResourceId readback_id_ = 0;
  Buffer readback_;
};

}  // namespace strata
