#include "passes/test_pattern.h"

#include <algorithm>
#include <cmath>

#include "engine/graph/graph_runner.h"
#include "shared/test_pattern.h"

namespace strata {

using graph::Use;

TestPattern::TestPattern(Context& ctx)
    : draw_(ctx, "test_pattern.comp"), blur_(ctx, "test_pattern_blur.comp"), table_(ctx) {}

graph::ResourceId TestPattern::add_to(graph::Graph& graph, uint32_t blur_radius) const {
  const auto floats = [](graph::Extent e) {
    return VkDeviceSize{e.width} * e.height * sizeof(float);
  };
  const graph::ResourceId color = graph.add_image("pattern.color", {VK_FORMAT_R8G8B8A8_UNORM});
  const graph::ResourceId luminance = graph.add_buffer("pattern.luminance", {floats});
  const graph::ResourceId table = graph.add_buffer("pattern.table", {floats});
  const graph::ResourceId result = graph.add_image("pattern.result", {VK_FORMAT_R8G8B8A8_UNORM});

  auto dispatch = [blur_radius](const ComputePipeline& pipeline, graph::PassContext& pc) {
    const gpu::TestPatternParams p{pc.viewport.width, pc.viewport.height, blur_radius, 0};
    pc.dispatch(pipeline, p, {p.width, p.height, 1});
  };
  graph.add_pass({"pattern.draw",
                  graph::PassKind::compute,
                  {{color, Use::storage_write, TEST_PATTERN_BINDING_COLOR},
                   {luminance, Use::storage_write, TEST_PATTERN_BINDING_LUMINANCE}},
                  [this, dispatch](graph::PassContext& pc) { dispatch(draw_, pc); }});
  table_.add_to(graph, luminance, table);
  graph.add_pass({"pattern.blur",
                  graph::PassKind::compute,
                  {{color, Use::storage_read, TEST_PATTERN_BINDING_COLOR},
                   {table, Use::storage_read, TEST_PATTERN_BINDING_TABLE},
                   {result, Use::storage_write, TEST_PATTERN_BINDING_OUTPUT}},
                  [this, dispatch](graph::PassContext& pc) { dispatch(blur_, pc); }});
  return result;
}

std::vector<uint8_t> test_pattern_reference(uint32_t width, uint32_t height, uint32_t blur_radius) {
  const auto to_byte = [](float v) {
    return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
  };
  std::vector<glm::vec3> color(size_t{width} * height);
  std::vector<float> lum(color.size());
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      const glm::vec2 uv((static_cast<float>(x) + 0.5f) / static_cast<float>(width),
                         (static_cast<float>(y) + 0.5f) / static_cast<float>(height));
      const size_t i = size_t{y} * width + x;
      color[i] = gpu::test_pattern(uv);
      // The GPU stores rgba8 and reads it back before blurring; the table sums full floats.
      lum[i] = gpu::luminance(color[i]);
    }
  }
  const std::vector<double> table = summed_area_table_reference(lum, width, height);
  const auto at = [&](int x, int y) { return x < 0 || y < 0 ? 0.0 : table[size_t(y) * width + x]; };
  std::vector<uint8_t> out(color.size() * 4);
  const int r = static_cast<int>(blur_radius);
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      const size_t i = size_t{y} * width + x;
      glm::vec3 c = color[i];
      if (x >= width / 2) {
        const int x0 = std::max(int(x) - r, 0) - 1, y0 = std::max(int(y) - r, 0) - 1;
        const int x1 = std::min(int(x) + r, int(width) - 1),
                  y1 = std::min(int(y) + r, int(height) - 1);
        const double sum = at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0);
        const float mean = static_cast<float>(sum / ((x1 - x0) * (y1 - y0)));
        c = mean * glm::vec3(1.0f, 0.9f, 0.7f);
      }
      out[4 * i + 0] = to_byte(c.r);
      out[4 * i + 1] = to_byte(c.g);
      out[4 * i + 2] = to_byte(c.b);
      out[4 * i + 3] = 255;
    }
  }
  return out;
}

}  // namespace strata
