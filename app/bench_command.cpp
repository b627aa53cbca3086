// `strata bench NAME`: GPU timings of one piece of work as JSON, median and minimum of N runs.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <random>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/soak_command.h"
#include "app/viewer.h"
#include "engine/gpu/resources.h"
#include "engine/graph/graph_runner.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/io/transfer_function_loader.h"
#include "labeling/camera_path.h"
#include "labeling/labelled_render.h"
#include "passes/summed_area_table.h"
#include "passes/volume_renderer.h"
#include "shared/placement.h"

namespace strata::app {
namespace {

using ordered_json = nlohmann::ordered_json;

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

struct Timings {
  std::vector<std::pair<std::string, Stat>> passes, groups;
};

// Runs the graph `warmup + runs` times (calling after_run after each) and takes per-pass and
// per-group (first pass begin to last pass end) GPU times.
Timings measure(graph::GraphRunner& runner, uint32_t warmup, uint32_t runs,
                const std::function<void()>& after_run = {}) {
  std::map<std::string, std::vector<double>> passes, groups;
  std::vector<std::string> pass_order, group_order;
  for (uint32_t i = 0; i < warmup + runs; ++i) {
    runner.run_now();
    if (after_run) after_run();
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
  Timings out;
  for (const auto& name : pass_order) out.passes.emplace_back(name, stat_of(passes[name]));
  for (const auto& name : group_order) out.groups.emplace_back(name, stat_of(groups[name]));
  return out;
}

// Milliseconds rounded to whole nanoseconds, the finest a GPU timestamp resolves: further digits
// are noise of the arithmetic.
double ms_json(double ms) {
  return std::round(ms * 1e6) / 1e6;
}

// [{name, median_ms, min_ms}] in the order the passes or groups first ran.
ordered_json stats_json(const std::vector<std::pair<std::string, Stat>>& list) {
  ordered_json out = ordered_json::array();
  for (const auto& [name, stat] : list) {
    out.push_back(
        {{"name", name}, {"median_ms", ms_json(stat.median)}, {"min_ms", ms_json(stat.min)}});
  }
  return out;
}

// One benchmark's report: the device, what was measured (`setup`: the benchmark's name and
// parameters), the timings, then what the benchmark derived from them (`results`). Scripts read
// the keys by name; the fixed order is for people.
void print_json(Context& ctx, const ordered_json& setup, uint32_t runs, const Timings& t,
                const ordered_json& results = ordered_json::object()) {
  ordered_json report = {{"device", ctx.report().name}, {"driver", ctx.report().driver}};
  report.update(setup);
  report["runs"] = runs;
  report["passes"] = stats_json(t.passes);
  report["groups"] = stats_json(t.groups);
  report.update(results);
  // Device names and scene paths are bytes, not always UTF-8: replace what is not, never throw.
  const std::string text = report.dump(2, ' ', false, ordered_json::error_handler_t::replace);
  std::printf("%s\n", text.c_str());
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
  const graph::ResourceId in =
      graph.import_buffer("input", {.buffer = input.handle(), .has_content = true});
  const graph::ResourceId out = graph.import_buffer("output", {.buffer = output.handle()});
  sat.add_to(graph, in, out);
  graph::GraphRunner runner(ctx, std::move(graph));
  runner.set_viewport(size);

  // The timed result must also be right: compare it once with the CPU reference.
  runner.run_now();
  const std::vector<float> gpu = download_as<float>(ctx, output);
  const std::vector<double> cpu = summed_area_table_reference(values, size.width, size.height);
  double max_relative = 0.0;
  for (size_t i = 0; i < count; ++i) {
    max_relative =
        std::max(max_relative, std::abs(gpu[i] - cpu[i]) / std::max(1.0, std::abs(cpu[i])));
  }
  const ordered_json setup = {{"benchmark", "sat"},
                              {"width", size.width},
                              {"height", size.height},
                              {"max_relative_error", max_relative}};
  print_json(ctx, setup, runs, measure(runner, 3, runs));
}

struct RenderBenchOptions {
  std::string scene = "assets/scenes/head.json";
  std::string size = "1024";
  std::string camera;
  uint32_t layers = 4;
  bool no_skipping = false;
  float step = 0.0f;
};

// What the driver reports per pipeline (registers, ...), if anything: {pipeline: {name: value}}.
ordered_json pipelines_json(const std::vector<PipelineReport>& reports) {
  ordered_json out = ordered_json::object();
  for (const auto& [name, statistics] : reports) {
    if (statistics.empty()) continue;
    ordered_json& entry = out[name];
    for (const auto& s : statistics) entry[s.name] = s.value;
  }
  return out;
}

void bench_render(DeviceOptions& device, const RenderBenchOptions& o, uint32_t runs) {
  const std::string scene_file = find_data_file(o.scene);
  const graph::Extent size = parse_size(o.size, "--size");
  const Scene scene = load_scene_reporting(scene_file);
  Context ctx(device.context());
  RenderSettings settings;
  settings.layer_count = o.layers;
  settings.skip_empty = !o.no_skipping;
  settings.step = o.step;
  VolumeRenderer renderer(ctx, scene, settings);
  renderer.set_camera(camera_for(scene, o.camera));
  graph::Graph graph;
  renderer.add_to(graph);
  graph::GraphRunner runner(ctx, std::move(graph));
  runner.set_viewport(size);
  RenderStats last;
  const Timings t = measure(runner, 3, runs, [&] { last = renderer.collect(runner); });
  double resolve_ms = 0.0;
  for (const auto& [name, stat] : t.passes) {
    if (name == "render.resolve") resolve_ms = stat.median;
  }
  // Texture fetches: one trilinear atlas fetch per live volume per sample (the transfer tables
  // are storage buffers, not textures).
  const double rays = double(size.width) * size.height;
  const double fetches = double(last.fetches);
  // The sampling distance the frame used (--step 0 asks for half a voxel).
  const float step = frame_data(renderer.inputs(), renderer.camera(), settings, size, 1).step;
  const ordered_json setup = {{"benchmark", "render"},
                              {"scene", scene_file},
                              {"camera", o.camera},
                              {"width", size.width},
                              {"height", size.height},
                              {"layers", o.layers},
                              {"empty_space_skipping", !o.no_skipping},
                              {"step", shortest_double(step)}};
  ordered_json results = {{"samples_per_ray", double(last.samples) / rays},
                          {"shaded_samples_per_ray", double(last.shaded) / rays},
                          {"habuffer_fragments", last.fragments},
                          {"habuffer_slots", last.table_size},
                          {"habuffer_load_factor", last.load_factor()},
                          {"habuffer_overflow", last.overflow},
                          {"resolve_overflow", last.resolve_overflow},
                          {"texture_fetches_per_frame", last.fetches},
                          {"resolve_fetch_rate_gtexel_per_s",
                           resolve_ms > 0.0 ? fetches / (resolve_ms * 1e-3) * 1e-9 : 0.0}};
  const ordered_json pipelines = pipelines_json(renderer.pipeline_statistics());
  if (!pipelines.empty()) results["pipelines"] = pipelines;
  print_json(ctx, setup, runs, t, results);
}

struct PlacementBenchOptions {
  std::string scene = "assets/scenes/head-100.json";
  std::string size = "1024";
  std::string camera;
  uint32_t labels = 0;  // 0: the scene's labels
};

// The scene's labels, cut to `count` or repeated up to it (each repeat's anchor moved by 2 mm so
// that no two coincide).
void resize_labels(Scene& scene, uint32_t count) {
  if (count == 0 || scene.labels.empty()) return;
  const std::vector<Label> original = scene.labels;
  scene.labels.clear();
  for (uint32_t i = 0; i < count; ++i) {
    Label l = original[i % original.size()];
    const auto round = static_cast<float>(i / original.size());
    l.anchor += glm::vec3(2.0f * round, -2.0f * round, 0.0f);
    l.id = int(i) + 1;
    scene.labels.push_back(l);
  }
}

void bench_placement(DeviceOptions& device, const PlacementBenchOptions& o, uint32_t runs) {
  const std::string scene_file = find_data_file(o.scene);
  const graph::Extent size = parse_size(o.size, "--size");
  Scene scene = load_scene_reporting(scene_file);
  resize_labels(scene, o.labels);
  Context ctx(device.context());
  LabellingSettings settings;
  settings.placement.weights = scene.settings.weights;
  LabelledRenderer frame(ctx, scene, camera_for(scene, o.camera), size, settings);
  frame.run();  // warm up, and grow the HA-Buffer if it must
  graph::GraphRunner& runner = frame.runner();
  const graph::PassId loop = frame.placement().label_loop;
  const Timings t = measure(runner, 1, runs);
  // The whole placement again with timestamps only where groups begin and end (a stamp waits for
  // the GPU to drain and costs time the real frame does not spend).
  runner.set_timestamps_per_pass(false);
  double whole_ms = 0.0;
  for (const auto& [name, stat] : measure(runner, 1, runs).groups) {
    if (name == "placement") whole_ms = stat.median;
  }
  runner.set_timestamps_per_pass(true);

  // The thesis program's structure: back to the CPU after every label, reading its result. The
  // loop's barrier b follows dispatch b, and dispatches 1 .. N each finish a label.
  std::vector<double> readback_ms;
  for (uint32_t run = 0; run < std::max(1u, runs / 4); ++run) {
    std::chrono::steady_clock::time_point start;
    const auto before_loop = [&](const graph::SplitPoint& s) {
      return s.pass + 1 == loop && !s.barrier;
    };
    const auto ends_label = [&](const graph::SplitPoint& s) {
      return s.pass == loop && (!s.barrier || *s.barrier >= 1);
    };
    runner.run_split([&](const graph::SplitPoint& s) { return before_loop(s) || ends_label(s); },
                     [&](const graph::SplitPoint& s) {
                       if (before_loop(s)) {
                         start = std::chrono::steady_clock::now();
                         return;
                       }
                       runner.download_buffer(frame.placement().results);
                       if (!s.barrier) {
                         readback_ms.push_back(std::chrono::duration<double, std::milli>(
                                                   std::chrono::steady_clock::now() - start)
                                                   .count());
                       }
                     });
  }
  double placement_ms = 0.0;
  for (const auto& [name, stat] : t.groups) {
    if (name == "placement") placement_ms = stat.median;
  }
  // The forces after the placement (thesis 3.4): one invocation per label.
  double forces_ms = 0.0;
  for (const auto& [name, stat] : t.passes) {
    if (name == "labels.forces") forces_ms = stat.median;
  }
  // The label loop on the GPU: its pass's time.
  runner.run_now();
  const double loop_ms = runner.timings()[loop].ms;
  // How many 32x32 tiles each label's passes took (of all the image's tiles): the speculative
  // one (bucket 0) and the main one beyond bucket 0.
  double first_tiles = 0.0, rest_tiles = 0.0;
  {
    runner.run_now();
    const std::vector<std::byte> bytes = runner.download_buffer(frame.placement().buckets);
    std::vector<gpu::PlacementBucketsGpu> buckets(bytes.size() / sizeof(gpu::PlacementBucketsGpu));
    std::memcpy(buckets.data(), bytes.data(), buckets.size() * sizeof(gpu::PlacementBucketsGpu));
    // (dispatches 0 .. labels ran: entry s of each label s, and one more)
    size_t placed = 0;
    while (placed + 1 < buckets.size() && buckets[placed + 1].done != 0) ++placed;
    for (size_t i = 0; i < placed; ++i) {
      first_tiles += buckets[i].counts[0];
      rest_tiles += buckets[i].rest;
    }
    if (placed > 0) {
      first_tiles /= double(placed);
      rest_tiles /= double(placed);
    }
  }
  const Stat baseline = stat_of(readback_ms.empty() ? std::vector<double>{0.0} : readback_ms);
  // The stages before the loop (per-pass stamps) plus the loop with a readback per label.
  const double baseline_total = placement_ms - loop_ms + baseline.median;
  const LabelledFrame last = frame.result(false);
  uint32_t enabled = 0;
  for (const LabelLayout& l : last.labels) enabled += l.placed;
  const ordered_json setup = {{"benchmark", "placement"},
                              {"scene", scene_file},
                              {"width", size.width},
                              {"height", size.height},
                              {"labels", scene.labels.size()},
                              {"labels_shown", enabled},
                              {"layers", last.layering.layer_count}};
  const glm::uvec2 tiles = gpu::placement_tiles(size.width, size.height);
  ordered_json results = {
      {"placement_ms", ms_json(whole_ms)},
      {"placement_ms_stamped_per_pass", ms_json(placement_ms)},
      {"label_loop_ms", ms_json(loop_ms)},
      {"forces_ms", ms_json(forces_ms)},
      {"label_loop_with_readback_per_label_ms", ms_json(baseline.median)},
      {"placement_with_readback_per_label_ms", ms_json(baseline_total)},
      {"speedup", whole_ms > 0.0 ? std::round(baseline_total / whole_ms * 100.0) / 100.0 : 0.0},
      {"tiles", tiles.x * tiles.y},
      {"tiles_per_label_speculative", first_tiles},
      {"tiles_per_label_main_beyond_speculative", rest_tiles}};
  const ordered_json pipelines = pipelines_json(frame.placement_pipelines());
  if (!pipelines.empty()) results["pipelines"] = pipelines;
  print_json(ctx, setup, runs, t, results);
}

struct ViewBenchOptions {
  std::string scene = "assets/scenes/head.json";
  std::string size = "1024";
  uint32_t frames = 120;
  double degrees = 90.0;
  uint32_t tidy_rounds = kViewerTidyRounds;
};

// The viewer's whole frame (labelled scene, forces, label drawing, the panel), headless, with two
// frames in flight, along a turntable at 30 frames a second of animation time.
void bench_view(DeviceOptions& device, const ViewBenchOptions& o) {
  const std::string scene_file = find_data_file(o.scene);
  const graph::Extent size = parse_size(o.size, "--size");
  Scene scene = load_scene_reporting(scene_file);
  Context ctx(device.context());
  LabellingSettings settings;
  settings.placement.weights = scene.settings.weights;
  settings.placement.tidy_rounds = o.tidy_rounds;
  const double fps = 30.0;
  const std::vector<Camera> cameras =
      sample(orbit_path(scene, scene.camera, o.degrees, double(o.frames) / fps), fps);
  HeadlessOutput output(ctx, size, 2);
  ViewerOptions options;
  options.scene_path = o.scene;
  options.optimize_on_idle = false;
  options.keep_frame_spans = true;
  Viewer viewer(ctx, scene, cameras.front(), settings, options, output, nullptr);
  for (int i = 0; i < 10; ++i) viewer.frame(1.0 / fps);  // warm up: the HA-Buffer grows
  // The path three times: with a timestamp around every pass (the time of each), with stamps only
  // where groups begin and end, and only where the frame does (the whole frame, undisturbed).
  struct Run {
    ViewerSummary before, after;
    double seconds = 0.0;
  };
  enum class Stamps { pass, group, frame };
  const auto run = [&](Stamps stamps) {
    if (stamps == Stamps::frame) {
      viewer.runner().set_timestamps_per_frame();
    } else {
      viewer.runner().set_timestamps_per_pass(stamps == Stamps::pass);
    }
    viewer.frame(1.0 / fps);
    output.wait_idle();
    Run r{viewer.summary(), {}, 0.0};
    const auto start = std::chrono::steady_clock::now();
    for (const Camera& camera : cameras) {
      viewer.set_camera(camera);
      viewer.frame(1.0 / fps);
    }
    output.wait_idle();
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    r.after = viewer.summary();
    return r;
  };
  const Run passes = run(Stamps::pass);
  const Run groups = run(Stamps::group);
  const Run frames = run(Stamps::frame);
  // (the frames read back during a path; its last ones were still in their slots)
  const auto quantiles = [](const std::vector<double>& all, size_t from) {
    std::vector<double> v(all.begin() + long(from), all.end());
    std::sort(v.begin(), v.end());
    const auto at = [&](double q) {
      return v.empty() ? 0.0 : v[std::min(v.size() - 1, size_t(q * double(v.size())))];
    };
    return nlohmann::ordered_json{{"median", at(0.5)}, {"p95", at(0.95)}, {"max", at(1.0)}};
  };
  const auto means = [](const Run& r) {
    nlohmann::ordered_json out;
    const uint64_t timed = r.after.timed_frames - r.before.timed_frames;
    for (const auto& [name, ms] : r.after.gpu_ms) {
      const auto was = r.before.gpu_ms.find(name);
      const double sum = ms - (was == r.before.gpu_ms.end() ? 0.0 : was->second);
      if (sum > 0.0) out[name] = timed ? sum / double(timed) : 0.0;
    }
    return out;
  };
  nlohmann::ordered_json out;
  out["device"] = ctx.report().name;
  out["scene"] = scene_file;
  out["size"] = {size.width, size.height};
  out["labels"] = scene.labels.size();
  out["frames"] = cameras.size();
  out["frames_in_flight"] = output.frames_in_flight();
  out["frames_per_second"] = double(cameras.size()) / frames.seconds;
  out["gpu_frame_ms"] = quantiles(frames.after.gpu_span_ms, frames.before.gpu_span_ms.size());
  out["gpu_frame_ms_stamped_per_group"] =
      quantiles(groups.after.gpu_span_ms, groups.before.gpu_span_ms.size());
  out["mean_group_ms"] = means(groups);
  out["gpu_frame_ms_stamped_per_pass"] =
      quantiles(passes.after.gpu_span_ms, passes.before.gpu_span_ms.size());
  out["mean_pass_ms"] = means(passes);
  std::printf("%s\n", out.dump(2).c_str());
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

  auto render = std::make_shared<RenderBenchOptions>();
  CLI::App* render_cmd = cmd->add_subcommand("render", "HA-Buffer build and resolve of a scene");
  render_cmd->add_option("--scene", render->scene, "scene file")->capture_default_str();
  render_cmd->add_option("--size", render->size, "N or WxH")->capture_default_str();
  render_cmd->add_option("--camera", render->camera, "named camera position");
  render_cmd->add_option("--layers", render->layers, "depth layers, 1 to 8")
      ->check(CLI::Range(1u, 8u))
      ->capture_default_str();
  render_cmd->add_flag("--no-skipping", render->no_skipping, "turn empty-space skipping off");
  render_cmd->add_option("--step", render->step,
                         "sampling distance in world units (0: half a voxel)");
  render_cmd->add_option("--runs", options->runs, "timed runs after 3 warm-up runs")
      ->capture_default_str()
      ->check(CLI::Range(1u, 100000u));
  render_cmd->callback(
      [&device, render, options] { bench_render(device, *render, options->runs); });

  auto place = std::make_shared<PlacementBenchOptions>();
  CLI::App* place_cmd = cmd->add_subcommand(
      "placement", "label placement per stage, against a CPU readback after every label");
  place_cmd->add_option("--scene", place->scene, "scene file")->capture_default_str();
  place_cmd->add_option("--size", place->size, "N or WxH")->capture_default_str();
  place_cmd->add_option("--camera", place->camera, "named camera position");
  place_cmd->add_option("--labels", place->labels, "label count (the scene's cut, or repeated)");
  place_cmd->add_option("--runs", options->runs, "timed runs after 1 warm-up run")
      ->capture_default_str()
      ->check(CLI::Range(1u, 100000u));
  place_cmd->callback(
      [&device, place, options] { bench_placement(device, *place, options->runs); });

  auto view = std::make_shared<ViewBenchOptions>();
  CLI::App* view_cmd = cmd->add_subcommand(
      "view", "the viewer's whole frame (labels, forces, drawing, UI) along a turntable");
  view_cmd->add_option("scene", view->scene, "scene file")->capture_default_str();
  view_cmd->add_option("--size", view->size, "N or WxH")->capture_default_str();
  view_cmd->add_option("--frames", view->frames, "frames timed along the path")
      ->capture_default_str()
      ->check(CLI::Range(1u, 100000u));
  view_cmd->add_option("--degrees", view->degrees, "how far the turntable turns")
      ->capture_default_str();
  view_cmd->add_option("--tidy-rounds", view->tidy_rounds, "rounds of the layout tidy-up per frame")
      ->check(CLI::Range(0u, TIDY_ROUNDS_MAX))
      ->capture_default_str();
  view_cmd->callback([&device, view] { bench_view(device, *view); });

  add_soak_command(cmd, device);
}

}  // namespace strata::app
