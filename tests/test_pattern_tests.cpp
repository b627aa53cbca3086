// The demo's whole graph (pattern, summed-area table, box filter, readback) against its CPU
// reference, which runs the same shared function for the pattern.
#include <doctest/doctest.h>

#include <cstdlib>

#include "engine/graph_runner.h"
#include "engine/headless_target.h"
#include "engine/png.h"
#include "gpu_fixture.h"
#include "passes/test_pattern.h"

namespace strata {

TEST_SUITE("gpu") {
  TEST_CASE_FIXTURE(test::GpuTest, "demo_image_matches_cpu_reference_within_two_levels") {
    const graph::Extent size{96, 64};
    const uint32_t radius = 5;
    TestPattern pattern(ctx);
    HeadlessTarget target(ctx);
    graph::Graph g;
    target.add_output(g, pattern.add_to(g, radius));
    graph::GraphRunner runner(ctx, std::move(g));
    runner.set_viewport(size);
    target.bind(runner);
    runner.run_now();

    const std::vector<uint8_t> expected = test_pattern_reference(size.width, size.height, radius);
    const std::span<const uint8_t> actual = target.pixels();
    REQUIRE(actual.size() == expected.size());
    // Tolerance: 2 of 255 per channel (float pow/sqrt differ slightly between CPU and GPU, and
    // the GPU box-filters the float luminance while the colour passes through rgba8).
    int worst = 0;
    for (size_t i = 0; i < expected.size(); ++i)
      worst = std::max(worst, std::abs(actual[i] - expected[i]));
    if (worst > 2) {
      write_png(test::output_dir() + "/demo.actual.png", size.width, size.height, actual);
      write_png(test::output_dir() + "/demo.expected.png", size.width, size.height, expected);
    }
    CHECK(worst <= 2);
  }

  TEST_CASE_FIXTURE(test::GpuTest, "graph_follows_a_viewport_resize") {
    TestPattern pattern(ctx);
    HeadlessTarget target(ctx);
    graph::Graph g;
    target.add_output(g, pattern.add_to(g, 3));
    graph::GraphRunner runner(ctx, std::move(g));
    for (const graph::Extent size : {graph::Extent{40, 30}, graph::Extent{17, 50}}) {
      runner.set_viewport(size);
      target.bind(runner);
      runner.run_now();
      const std::vector<uint8_t> expected = test_pattern_reference(size.width, size.height, 3);
      REQUIRE(target.pixels().size() == expected.size());
      int worst = 0;
      for (size_t i = 0; i < expected.size(); ++i) {
        worst = std::max(worst, std::abs(target.pixels()[i] - expected[i]));
      }
      CHECK(worst <= 2);
      const auto timings = runner.timings();
      CHECK(timings.size() == runner.graph().passes().size());
      for (const auto& t : timings) CHECK(t.ms >= 0.0);
    }
  }
}

}  // namespace strata
