// The validation hook works: a barrier left out on purpose is caught by synchronization
// validation, and the same graph with its derived barriers is clean.
#include <doctest/doctest.h>

#include "engine/graph/graph_runner.h"
#include "engine/graph/headless_target.h"
#include "gpu_fixture.h"
#include "passes/test_pattern.h"

namespace strata {
namespace {

size_t pass_index(const graph::Graph& g, const std::string& name) {
  for (size_t i = 0; i < g.passes().size(); ++i) {
    if (g.passes()[i].name == name) return i;
  }
  FAIL("no pass " << name);
  return 0;
}

}  // namespace

TEST_SUITE("gpu") {
  TEST_CASE_FIXTURE(test::GpuTest, "synchronization_validation_catches_a_missing_barrier") {
    TestPattern pattern(ctx);
    HeadlessTarget target(ctx);
    graph::Graph g;
    target.add_output(g, pattern.add_to(g, 2));
    graph::GraphRunner runner(ctx, std::move(g));
    runner.set_viewport({48, 32});
    target.bind(runner);

    runner.run_now();
    CHECK(ctx.validation_log().count() == 0);

    // The scan pass reads the carries the previous pass wrote: drop the barrier between them.
    const size_t scan = pass_index(runner.graph(), "summed_area_table.scan");
    REQUIRE(!runner.compiled().pass_barriers[scan].empty());
    runner.compiled().pass_barriers[scan].clear();
    runner.run_now();
    const std::vector<std::string> messages = ctx.validation_log().take();
    REQUIRE(!messages.empty());
    bool read_after_write = false;
    for (const std::string& m : messages) {
      read_after_write = read_after_write ||
                         m.find("SYNC-HAZARD-READ-AFTER-WRITE") != std::string::npos ||
                         m.find("SYNC-HAZARD-READ_AFTER_WRITE") != std::string::npos;
    }
    CHECK_MESSAGE(read_after_write, "first message: " << messages.front());
  }
}

}  // namespace strata
