// `strata bench NAME`: GPU timings of one piece of work as JSON, median and minimum of N runs.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>

#include "app/commands.h"
#include "engine/graph_runner.h"
#include "engine/resources.h"
#include "passes/summed_area_table.h"

namespace strata::app {
namespace {

struct Stat {
  double median = 0.0;
  double min = 0.0;
};

Stat stat_of(std::vector<double> samples) {
  std::sort(samples.begin(), samples.end());
  const size_t n = samples.size();
  const double median = n % 2 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
  return {median, samples.front()};
}

std::string json_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) >= 0x20) out += c;
  }
  return out;
}

// Runs the graph `warmup + runs` times and prints per-pass and per-group GPU times.
void print_timings(Context& ctx, graph::GraphRunner& runner, uint32_t warmup, uint32_t runs,
                   const std::string& header) {
  std::map<std::string, std::vector<double>> passes, groups;
  std::vector<std::string> pass_order, group_order;
  for (uint32_t i = 0; i < warmup + runs; ++i) {
    runner.run_now();
    if (i < warmup) continue;
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
  const auto print_list = [](const char* key, const std::vector<std::string>& order,
                             std::map<std::string, std::vector<double>>& samples) {
    std::printf("  \"%s\": [", key);
    for (size_t i = 0; i < order.size(); ++i) {
      const Stat s = stat_of(samples[order[i]]);
      std::printf("%s\n    {\"name\": \"%s\", \"median_ms\": %.6f, \"min_ms\": %.6f}", i ? "," : "",
                  json_escape(order[i]).c_str(), s.median, s.min);
    }
    std::printf("\n  ]");
  };
  std::printf("{\n  \"device\": \"%s\",\n  \"driver\": \"%s\",\n%s  \"runs\": %u,\n",
              json_escape(ctx.report().name).c_str(), json_escape(ctx.report().driver).c_str(),
              header.c_str(), runs);
  print_list("passes", pass_order, passes);
  std::printf(",\n");
  print_list("groups", group_order, groups);
  std::printf("\n}\n");
}

void bench_sat(DeviceOptions& device, graph::Extent size, uint32_t runs) {
  Context ctx(device.context());
  const size_t count = size_t{size.width} * size.height;
  std::vector<float> values(count);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> dist(0.0f, 1.0f);
  for (float& v : values) v = dist(rng);
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  Buffer input(ctx, count * sizeof(float), usage, MemoryKind::device_local);
  Buffer output(ctx, count * sizeof(float), usage, MemoryKind::device_local);
  upload(ctx, input, as_bytes(values));

  SummedAreaTable sat(ctx);
  graph::Graph graph;
  const graph::ResourceId in = graph.import_resource("input", {false, true});
  const graph::ResourceId out = graph.import_resource("output", {false, false});
  sat.add_to(graph, in, out);
  graph::GraphRunner runner(ctx, std::move(graph));
  runner.set_viewport(size);
  runner.bind_buffer(in, input.handle());
  runner.bind_buffer(out, output.handle());

  // The timed result must also be right: compare it once with the CPU reference.
  runner.run_now();
  const std::vector<float> gpu = download_as<float>(ctx, output);
  const std::vector<double> cpu = summed_area_table_reference(values, size.width, size.height);
  double max_relative = 0.0;
  for (size_t i = 0; i < count; ++i) {
    max_relative =
        std::max(max_relative, std::abs(gpu[i] - cpu[i]) / std::max(1.0, std::abs(cpu[i])));
  }
  char header[256];
  std::snprintf(header, sizeof header,
                "  \"benchmark\": \"sat\",\n  \"width\": %u,\n  \"height\": %u,\n"
                "  \"max_relative_error\": %.3g,\n",
                size.width, size.height, max_relative);
  print_timings(ctx, runner, 3, runs, header);
}

}  // namespace

void add_bench_command(CLI::App& app, DeviceOptions& device) {
  CLI::App* cmd = app.add_subcommand("bench", "GPU timings as JSON (median and min of N runs)");
  cmd->require_subcommand(1);
  struct Options {
    std::string size = "1024";
    uint32_t runs = 50;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sat = cmd->add_subcommand("sat", "summed-area table of a float32 image");
  sat->add_option("--size", options->size, "N or WxH")->capture_default_str();
  sat->add_option("--runs", options->runs, "timed runs after 3 warm-up runs")
      ->capture_default_str()
      ->check(CLI::Range(1u, 100000u));
  sat->callback([&device, options] {
    bench_sat(device, parse_size(options->size, "--size"), options->runs);
  });
}

}  // namespace strata::app
