// Timings per pass and per group, and the reports of `strata bench` (app/bench_timings.h).
#include "app/bench_timings.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>

namespace strata::app::bench {

Stat stat_of(std::vector<double> samples) {
  std::sort(samples.begin(), samples.end());
  const size_t n = samples.size();
  const double median = n % 2 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
  return {median, samples.front()};
}

Timings measure(graph::GraphRunner& runner, uint32_t warmup, uint32_t runs,
                const std::function<void()>& after_run) {
  std::map<std::string, std::vector<double>> passes, groups;
  std::vector<std::string> pass_order, group_order;
  const auto start = std::chrono::steady_clock::now();
  const auto warming = [&](uint32_t i) {
    return i < warmup ||
           std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() <
               kWarmupSeconds;
  };
  for (uint32_t i = 0; warming(i); ++i) {
    runner.run_now();
    if (after_run) after_run();
  }
  for (uint32_t i = 0; i < runs; ++i) {
    runner.run_now();
    if (after_run) after_run();
    std::map<std::string, std::pair<double, double>> spans;
    for (const graph::PassTiming& t : runner.timings()) {
      if (!passes.count(t.name)) pass_order.push_back(t.name);
      passes[t.name].push_back(t.ms);
      if (t.group.empty()) continue;
      auto [it, fresh] = spans.try_emplace(t.group, t.begin_ms, t.end_ms);
      if (fresh && !groups.count(t.group)) group_order.push_back(t.group);
      it->second.first = std::min(it->second.first, t.begin_ms);
      it->second.second = std::max(it->second.second, t.end_ms);
    }
    for (const auto& [group, span] : spans) groups[group].push_back(span.second - span.first);
  }
  Timings out;
  for (const auto& name : pass_order) out.passes.emplace_back(name, stat_of(passes[name]));
  for (const auto& name : group_order) out.groups.emplace_back(name, stat_of(groups[name]));
  return out;
}

double ms_json(double ms) {
  return std::round(ms * 1e6) / 1e6;
}

ordered_json stats_json(const std::vector<std::pair<std::string, Stat>>& list) {
  ordered_json out = ordered_json::array();
  for (const auto& [name, stat] : list) {
    out.push_back(
        {{"name", name}, {"median_ms", ms_json(stat.median)}, {"min_ms", ms_json(stat.min)}});
  }
  return out;
}

void print_report(const ordered_json& report) {
  const std::string text = report.dump(2, ' ', false, ordered_json::error_handler_t::replace);
  std::printf("%s\n", text.c_str());
  std::fflush(stdout);
}

void print_json(Context& ctx, const ordered_json& setup, uint32_t runs, const Timings& t,
                const ordered_json& results) {
  ordered_json report = {{"device", ctx.report().name}, {"driver", ctx.report().driver}};
  report.update(setup);
  report["runs"] = runs;
  report["passes"] = stats_json(t.passes);
  report["groups"] = stats_json(t.groups);
  report.update(results);
  print_report(report);
}

ordered_json pipelines_json(const std::vector<PipelineReport>& reports) {
  ordered_json out = ordered_json::object();
  for (const auto& [name, statistics] : reports) {
    if (statistics.empty()) continue;
    ordered_json& entry = out[name];
    for (const auto& s : statistics) entry[s.name] = s.value;
  }
  return out;
}

}  // namespace strata::app::bench
