// Summed-area table of a viewport-sized float32 buffer (row-major), for integral costs over label
// boxes: out(x, y) = sum of in(x', y') over x' <= x, y' <= y. Three compute dispatches, reduce
// then scan (shaders/shared/summed_area_table.h), so no workgroup waits on another: safe on
// devices without forward-progress guarantees, such as lavapipe.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "engine/gpu/shader_library.h"
#include "engine/graph/render_graph.h"

namespace strata {

class SummedAreaTable {
 public:
  explicit SummedAreaTable(Context& ctx);

  // Adds the three passes that write the tables of `input` to `output`: stacks of `layers`
  // viewport-sized float images one after the other, each summed on its own.
  void add_to(graph::Graph& graph, graph::ResourceId input, graph::ResourceId output,
              const std::string& group = "summed_area_table", uint32_t layers = 1) const;

 private:
  ComputePipeline sums_;
  ComputePipeline carries_;
  ComputePipeline scan_;
};

// The CPU reference, in double precision.
std::vector<double> summed_area_table_reference(std::span<const float> values, uint32_t width,
                                                uint32_t height);

}  // namespace strata
