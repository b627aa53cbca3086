// The summed-area table on the GPU against its CPU reference.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "engine/gpu/resources.h"
#include "engine/graph/graph_runner.h"
#include "gpu_fixture.h"
#include "passes/summed_area_table.h"

namespace strata {
namespace {

std::vector<float> gpu_table(Context& ctx, const std::vector<float>& values, graph::Extent size) {
  const VkDeviceSize bytes = values.size() * sizeof(float);
  Buffer input(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::device_local);
  Buffer output(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::device_local);
  upload(ctx, input, as_bytes(values));
  SummedAreaTable sat(ctx);
  graph::Graph graph;
  const auto in = graph.import_buffer("input", {.buffer = input.handle(), .has_content = true});
  const auto out = graph.import_buffer(
      "output", {.buffer = output.handle(), .final_use = graph::Use::transfer_src});
  sat.add_to(graph, in, out);
  graph::GraphRunner runner(ctx, std::move(graph));
  runner.set_viewport(size);
  runner.run_now();
  return download_as<float>(ctx, output);
}

}  // namespace

TEST_SUITE("gpu") {
  TEST_CASE_FIXTURE(test::GpuTest,
                    "summed_area_table_matches_cpu_reference_on_odd_and_large_sizes") {
    const graph::Extent sizes[] = {{1, 1}, {7, 3}, {64, 64}, {257, 129}, {1024, 768}};
    std::mt19937 rng(1234);
    std::uniform_real_distribution<float> dist(-1.0f, 1.0f);
    for (const graph::Extent size : sizes) {
      CAPTURE(size.width);
      CAPTURE(size.height);
      std::vector<float> values(size_t{size.width} * size.height);
      for (float& v : values) v = dist(rng);
      std::vector<float> magnitude(values.size());
      for (size_t i = 0; i < values.size(); ++i) magnitude[i] = std::abs(values[i]);

      const std::vector<float> gpu = gpu_table(ctx, values, size);
      const std::vector<double> cpu = summed_area_table_reference(values, size.width, size.height);
      // float32 sums of up to W*H terms: the error is bounded by a small multiple of machine
      // epsilon times the sum of magnitudes under the rectangle (the condition of the sum).
      const std::vector<double> scale =
          summed_area_table_reference(magnitude, size.width, size.height);
      size_t bad = 0;
      for (size_t i = 0; i < values.size(); ++i) {
        const double tolerance = 1e-5 * scale[i] + 1e-6;
        if (std::abs(gpu[i] - cpu[i]) > tolerance && bad++ < 5) {
          MESSAGE("pixel " << i % size.width << "," << i / size.width << ": gpu " << gpu[i]
                           << " cpu " << cpu[i]);
        }
      }
      CHECK(bad == 0);
    }
  }

  TEST_CASE_FIXTURE(test::GpuTest, "summed_area_table_of_ones_counts_pixels_exactly") {
    const graph::Extent size{100, 37};
    const std::vector<float> ones(size_t{size.width} * size.height, 1.0f);
    const std::vector<float> gpu = gpu_table(ctx, ones, size);
    for (uint32_t y = 0; y < size.height; ++y) {
      for (uint32_t x = 0; x < size.width; ++x) {
        REQUIRE(gpu[size_t{y} * size.width + x] == float((x + 1) * (y + 1)));
      }
    }
  }
}

}  // namespace strata
