// What `strata render` and `strata view` show without a scene: shaders/shared/test_pattern.h drawn
// into a colour image, its luminance summed into a table, and the right half box-filtered from it.
#pragma once

#include <vector>

#include "engine/gpu/shader_library.h"
#include "engine/graph/render_graph.h"
#include "passes/summed_area_table.h"

namespace strata {

class TestPattern {
 public:
  explicit TestPattern(Context& ctx);

  // Adds the passes; returns the viewport-sized rgba8 image they write.
  graph::ResourceId add_to(graph::Graph& graph, uint32_t blur_radius) const;

 private:
  ComputePipeline draw_;
  ComputePipeline blur_;
  SummedAreaTable table_;
};

// CPU reference of the whole demo image: rgba8, row-major.
std::vector<uint8_t> test_pattern_reference(uint32_t width, uint32_t height, uint32_t blur_radius);

}  // namespace strata
