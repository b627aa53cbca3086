// `strata bench segmentation`: what opening a segmentation costs on the CPU, without a file: a
// made-up label map and the time to
// summarise its regions: one pass for their extents, then each region's parts and distance
// transform for its anchor (summarise_regions, on every hardware thread).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>

#include "app/bench_timings.h"
#include "app/commands.h"
#include "engine/scene/segmentation.h"

namespace strata::app {
namespace {

struct SegmentationBenchOptions {
  std::string size = "512x512x400";
  uint32_t regions = 100;
  uint32_t runs = 3;
};

// The grid cut into cells (the fewest cubes of cells that give `regions`), the first `regions`
// cells each holding one region: a blob with a wavy edge, about a quarter of its cell, as organs
// fill about a quarter of an abdominal CT.
Segmentation made_up(glm::uvec3 dims, uint32_t regions) {
  Volume grid;
  grid.source = "made-up label map";
  grid.dims = dims;
  grid.spacing = {0.8f, 0.8f, 1.0f};
  Segmentation s;
  s.source = grid.source;
  s.format = "made up";
  s.layers.push_back(empty_layer(grid));
  const uint32_t side = uint32_t(std::ceil(std::cbrt(double(regions)) - 1e-9));
  std::vector<std::byte>& voxels = s.layers[0].voxels;
  size_t i = 0;
  for (uint32_t z = 0; z < dims.z; ++z)
    for (uint32_t y = 0; y < dims.y; ++y)
      for (uint32_t x = 0; x < dims.x; ++x, ++i) {
        const glm::vec3 cell_f = (glm::vec3(x, y, z) + 0.5f) / glm::vec3(dims) * float(side);
        const glm::uvec3 cell = glm::min(glm::uvec3(cell_f), glm::uvec3(side - 1));
        const uint32_t region = (cell.z * side + cell.y) * side + cell.x;
        if (region >= regions) continue;
        const glm::vec3 in = glm::fract(cell_f) - 0.5f;
        const float edge = 0.38f + 0.06f * std::sin(float(region) + 9.0f * in.x + 5.0f * in.z);
        if (glm::dot(in, in) > edge * edge) continue;
        const uint16_t value = uint16_t(region + 1);
        std::memcpy(voxels.data() + 2 * i, &value, 2);
      }
  for (uint32_t r = 1; r <= regions; ++r)
    s.regions.push_back({int(r), 0, int(r), "region " + std::to_string(r), {}});
  return s;
}

void bench_segmentation(const SegmentationBenchOptions& options) {
  std::string commas = options.size;
  std::replace(commas.begin(), commas.end(), 'x', ',');
  const std::vector<float> sides = parse_numbers(commas, 3, "--size", "WxHxD");
  for (float side : sides)
    if (!(side >= 1.0f && side <= 2048.0f && side == std::floor(side)))
      throw UsageError("--size: '" + options.size + "': each side a whole number, 1 to 2048");
  const glm::uvec3 dims(sides[0], sides[1], sides[2]);
  const Segmentation s = made_up(dims, options.regions);
  std::vector<double> ms;
  std::vector<RegionSummary> summaries;
  for (uint32_t run = 0; run < options.runs; ++run) {
    const auto start = std::chrono::steady_clock::now();
    summaries = summarise_regions(s);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                     .count());
  }
  size_t voxels = 0, with_voxels = 0;
  for (const RegionSummary& r : summaries) {
    voxels += r.voxels;
    with_voxels += r.voxels > 0;
  }
  const bench::Stat stat = bench::stat_of(ms);
  bench::ordered_json report = {
      {"benchmark", "segmentation"}, {"size", options.size},
      {"regions", options.regions},  {"regions_with_voxels", with_voxels},
      {"labelled_voxels", voxels},   {"threads", std::max(1u, std::thread::hardware_concurrency())},
      {"runs", options.runs},        {"anchors_ms", {{"median", stat.median}, {"min", stat.min}}}};
  bench::print_report(report);
}

}  // namespace

void add_segmentation_bench(CLI::App* bench) {
  auto options = std::make_shared<SegmentationBenchOptions>();
  CLI::App* cmd = bench->add_subcommand(
      "segmentation",
      "CPU: the anchors of a made-up label map's regions (extents, parts, distance transforms)");
  cmd->add_option("--size", options->size, "WxHxD voxels")->capture_default_str();
  cmd->add_option("--regions", options->regions, "regions in the label map")
      ->capture_default_str()
      ->check(whole_range(1, kMaxRegionValue));
  cmd->add_option("--runs", options->runs, "timed runs")
      ->capture_default_str()
      ->check(whole_range(1, 1000));
  cmd->callback([options] { bench_segmentation(*options); });
}

}  // namespace strata::app
