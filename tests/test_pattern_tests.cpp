// The demo's whole graph (pattern, summed-area table, box filter, readback) against its CPU
// reference, which runs the same shared function for the pattern.
#include <doctest/doctest.h>

#include <cstdlib>

#include "engine/core/png.h"
#include "engine/graph/graph_runner.h"
#include "engine/graph/headless_target.h"
#include "gpu_fixture.h"
#include "passes/test_pattern.h"

namespace strata {
namespace {

// The largest per-channel difference; over `tolerance`, the actual, expected and difference
// images are written to the test output folder and the first bad pixel is reported.
int compare_images(std::span<const uint8_t> actual, const std::vector<uint8_t>& expected,
                   graph::Extent size, int tolerance, const std::string& name) {
  REQUIRE(actual.size() == expected.size());
  int worst = 0;
  std::vector<uint8_t> difference(expected.size(), 255);
  for (size_t i = 0; i < expected.size(); ++i) {
    const int d = std::abs(actual[i] - expected[i]);
    if (d > tolerance && worst <= tolerance) {
      MESSAGE(name << ": pixel " << (i / 4) % size.width << "," << (i / 4) / size.width
                   << " channel " << i % 4 << ": " << int(actual[i]) << " vs " << int(expected[i]));
    }
    worst = std::max(worst, d);
    if (i % 4 != 3) difference[i] = static_cast<uint8_t>(std::min(255, d * 16));
  }
  if (worst > tolerance) {
    const std::string base = test::output_dir() + "/" + name;
    write_png(base + ".actual.png", size.width, size.height, actual);
    write_png(base + ".expected.png", size.width, size.height, expected);
    write_png(base + ".difference.png", size.width, size.height, difference);
  }
  return worst;
}

// The demo's graph with its pattern pass and readback target, ready to run.
struct PatternGraph {
  PatternGraph(Context& ctx, uint32_t radius)
      : pattern(ctx), target(ctx), runner(ctx, build(radius)) {}
  graph::Graph build(uint32_t radius) {
    graph::Graph g;
    target.add_output(g, pattern.add_to(g, radius));
    return g;
  }
  TestPattern pattern;
  HeadlessTarget target;
  graph::GraphRunner runner;
};

}  // namespace

TEST_SUITE("gpu") {
  // Tolerance: 2 of 255 per channel (float pow/sqrt differ slightly between CPU and GPU, and
  // the GPU box-filters the float luminance while the colour passes through rgba8).
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
    CHECK(compare_images(target.pixels(), expected, size, 2, "demo") <= 2);
  }

  TEST_CASE_FIXTURE(test::GpuTest, "graph_follows_a_viewport_resize") {
    PatternGraph demo(ctx, 3);
    graph::GraphRunner& runner = demo.runner;
    HeadlessTarget& target = demo.target;
    for (const graph::Extent size : {graph::Extent{40, 30}, graph::Extent{17, 50}}) {
      CAPTURE(size.width);
      runner.set_viewport(size);
      target.bind(runner);
      runner.run_now();
      const std::vector<uint8_t> expected = test_pattern_reference(size.width, size.height, 3);
      CHECK(compare_images(target.pixels(), expected, size, 2,
                           "resize-" + std::to_string(size.width)) <= 2);
      const auto timings = runner.timings();
      CHECK(timings.size() == runner.graph().passes().size());
      for (const auto& t : timings) CHECK(t.ms >= 0.0);
    }
  }

  TEST_CASE_FIXTURE(test::GpuTest, "group_timestamps_give_one_span_per_run_of_a_group") {
    PatternGraph demo(ctx, 3);
    graph::GraphRunner& runner = demo.runner;
    HeadlessTarget& target = demo.target;
    runner.set_viewport({40, 30});
    target.bind(runner);
    runner.set_timestamps_per_pass(false);
    runner.run_now();
    // The expected spans: one per run of passes that share a group name.
    std::vector<std::string> runs;
    for (const auto& pass : runner.graph().passes()) {
      if (runs.empty() || runs.back() != pass.group) runs.push_back(pass.group);
    }
    REQUIRE(runs.size() >= 3);  // (the table's passes form a group between ungrouped ones)
    REQUIRE(runs.size() < runner.graph().passes().size());
    const auto timings = runner.timings();
    REQUIRE(timings.size() == runs.size());
    double previous_end = 0.0;
    for (size_t i = 0; i < runs.size(); ++i) {
      CHECK(timings[i].name == runs[i]);
      CHECK(timings[i].begin_ms >= previous_end);
      CHECK(timings[i].end_ms >= timings[i].begin_ms);
      previous_end = timings[i].end_ms;
    }
    // Back to a stamp per pass.
    runner.set_timestamps_per_pass(true);
    runner.run_now();
    CHECK(runner.timings().size() == runner.graph().passes().size());
    // A change of the stamping applies to the frames recorded after it: the last frame is read
    // as it was stamped (its slot's stamps, not stamps never written).
    runner.set_timestamps_per_frame();
    CHECK(runner.timings().size() == runner.graph().passes().size());
    runner.run_now();
    REQUIRE(runner.timings().size() == 1);
    CHECK(runner.timings()[0].name == "frame");
    runner.set_timestamps_per_pass(true);
    CHECK(runner.timings().size() == 1);
    runner.run_now();
    const std::vector<uint8_t> expected = test_pattern_reference(40, 30, 3);
    CHECK(compare_images(target.pixels(), expected, {40, 30}, 2, "group-stamps") <= 2);
  }
}

}  // namespace strata
