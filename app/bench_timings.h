// What every `strata bench` shares: GPU times of a graph's runs per pass and per group, and the
// JSON report they go into (app/bench_timings.cpp).
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/gpu/context.h"
#include "engine/gpu/shader_library.h"
#include "engine/graph/graph_runner.h"

namespace strata::app::bench {

using ordered_json = nlohmann::ordered_json;

struct Stat {
  double median = 0.0;
  double min = 0.0;
};
Stat stat_of(std::vector<double> samples);

struct Timings {
  std::vector<std::pair<std::string, Stat>> passes, groups;
};

// Runs the graph `warmup` times, and more until kWarmupSeconds have passed, then `runs` times
// (calling after_run after each), and takes per-pass and per-group (first pass begin to last pass
// end) GPU times.
Timings measure(graph::GraphRunner& runner, uint32_t warmup, uint32_t runs,
                const std::function<void()>& after_run = {});
// A GPU that idled while the host set a benchmark up runs its first frames slowly: with three
// warm-up frames the first count measured in a process read its loop several times too slow
// (docs/performance.md); warming up for this long made that rare. (The labels' state carries over
// from frame to frame, so how many frames ran changes how many tidy-up rounds the measured frames
// run.)
inline constexpr double kWarmupSeconds = 0.5;

// Milliseconds rounded to whole nanoseconds, the finest a GPU timestamp resolves: further digits
// are noise of the arithmetic.
double ms_json(double ms);
// [{name, median_ms, min_ms}] in the order the passes or groups first ran.
ordered_json stats_json(const std::vector<std::pair<std::string, Stat>>& list);
// What the driver reports per pipeline (registers, ...), if anything: {pipeline: {name: value}}.
ordered_json pipelines_json(const std::vector<PipelineReport>& reports);

// A report on stdout. Device names and scene paths are bytes, not always UTF-8: what is not is
// replaced, never thrown about.
void print_report(const ordered_json& report);
// One benchmark's report: the device, what was measured (`setup`: the benchmark's name and
// parameters), the timings, then what the benchmark derived from them (`results`). Scripts read
// the keys by name; the fixed order is for people.
void print_json(Context& ctx, const ordered_json& setup, uint32_t runs, const Timings& t,
                const ordered_json& results = ordered_json::object());

}  // namespace strata::app::bench
