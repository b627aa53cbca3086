// `strata bench NAME`: GPU timings of one piece of work as JSON, median and minimum of N runs
// (`placement` in app/bench_placement.cpp, `soak` in app/soak_command.cpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numeric>
#include <random>
#include <thread>

#include <GLFW/glfw3.h>
#include <nlohmann/json.hpp>

#include "app/bench_placement.h"
#include "app/bench_timings.h"
#include "app/commands.h"
#include "app/soak_command.h"
#include "app/viewer/viewer.h"
#include "engine/core/json_field.h"
#include "engine/gpu/resources.h"
#include "engine/graph/graph_runner.h"
#include "engine/scene/io/scene_loader.h"
#include "frame/labelled_render.h"
#include "labeling/camera_path.h"
#include "passes/summed_area_table.h"
#include "passes/volume_renderer.h"
#include "shared/placement.h"

namespace strata::app {
namespace bench {
namespace {

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
  // (as the viewer's render.step: far below the voxels, a frame's samples grow without bound)
  const float finest = renderer.inputs().finest_spacing;
  if (o.step != 0.0f && o.step < finest / 16.0f) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "--step: %g is below %g, a sixteenth of the finest voxel spacing (0: half of it)",
                  double(o.step), double(finest / 16.0f));
    throw UsageError(text);
  }
  renderer.set_camera(option_camera(scene, o.camera));
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

struct ViewBenchOptions {
  std::string scene = "assets/scenes/head.json";
  std::string size = "1024";
  uint32_t frames = 120;
  uint32_t labels = 0;  // 0: the scene's labels
  double degrees = 90.0;
  uint32_t tidy_rounds = kViewerTidyRounds;
  bool keep_apart = true;
  std::string placement = "auto";
  double pace = 0.0;  // frames a second the frames are started at (a display's); 0: at once
  double frame_budget_ms = 0.0;  // the viewer's interactive rendering (`view --frame-budget`)
  float ghost = 1.0f;            // ghosting's strength (0: off), the default lens
  uint32_t place = 0;  // labels placed at the picture's centre after the runs (their wall time)
};

// The part of a group's name before its first dot ("placement.sat" is part of "placement"), or
// "ungrouped" for passes outside every group (readbacks, the view's copy).
std::string top_group(const std::string& group) {
  return group.empty() ? "ungrouped" : group.substr(0, group.find('.'));
}

// One turntable run of bench view: the viewer's totals before and after it.
struct ViewRun {
  ViewerSummary before, after;
  double seconds = 0.0;

  // The frames' GPU times (the frames read back during the run; its last ones were still in
  // their slots when it ended): median, 95th percentile and maximum.
  ordered_json frame_quantiles() const {
    std::vector<double> v(after.gpu_span_ms.begin() + long(before.gpu_span_ms.size()),
                          after.gpu_span_ms.end());
    std::sort(v.begin(), v.end());
    const auto at = [&](double q) {
      return v.empty() ? 0.0 : v[std::min(v.size() - 1, size_t(q * double(v.size())))];
    };
    return {{"median", ms_json(at(0.5))}, {"p95", ms_json(at(0.95))}, {"max", ms_json(at(1.0))}};
  }
  // Mean ms per frame of each timing entry (a pass, or a group with group stamps).
  std::map<std::string, double> means() const {
    std::map<std::string, double> out;
    const uint64_t timed = after.timed_frames - before.timed_frames;
    for (const auto& [name, ms] : after.gpu_ms) {
      const auto was = before.gpu_ms.find(name);
      const double sum = ms - (was == before.gpu_ms.end() ? 0.0 : was->second);
      if (sum > 0.0) out[name] = timed ? sum / double(timed) : 0.0;
    }
    return out;
  }
};

// Labels of one's own placed as a user does (place mode, a click every fourth frame around the
// picture's centre, the camera at rest): every frame's wall time from one to the next while
// placing, against as many frames at rest just before; and the labels placed.
ordered_json placing_json(Viewer& viewer, ViewerOutput& output, const Scene& scene,
                          const Camera& camera, uint32_t count, double fps) {
  const auto intervals = [&](uint32_t frames, bool click) {
    const graph::Extent e = viewer.extent();
    const glm::vec2 centre(0.5f * float(e.width), 0.5f * float(e.height));
    std::vector<double> ms;
    auto last = std::chrono::steady_clock::now();
    for (uint32_t f = 0; f < frames; ++f) {
      if (click && f % 4 == 0) {
        // (on a spiral around the centre, apart: each click a label of its own)
        const float k = float(f / 4);
        const float r =
            0.3f * float(std::min(e.width, e.height)) * std::sqrt((k + 0.5f) / float(count));
        viewer.cursor(centre + r * glm::vec2(std::cos(2.4f * k), std::sin(2.4f * k)));
        viewer.mouse_button(GLFW_MOUSE_BUTTON_LEFT, GLFW_PRESS, 0);
        viewer.mouse_button(GLFW_MOUSE_BUTTON_LEFT, GLFW_RELEASE, 0);
      }
      viewer.frame(1.0 / fps);
      const auto now = std::chrono::steady_clock::now();
      ms.push_back(std::chrono::duration<double, std::milli>(now - last).count());
      last = now;
    }
    // (the mean too: with frames in flight a long interval is often followed by a short one)
    const double mean = std::accumulate(ms.begin(), ms.end(), 0.0) / double(ms.size());
    std::sort(ms.begin(), ms.end());
    return ordered_json{{"median", ms[ms.size() / 2]}, {"mean", mean}, {"max", ms.back()}};
  };
  viewer.set_camera(camera);
  viewer.set_place_mode(true);
  viewer.runner().set_timestamps_per_pass(true);
  for (int f = 0; f < 8; ++f) viewer.frame(1.0 / fps);  // (settled into the pace)
  const size_t before = scene.labels.size();
  ordered_json out;
  out["labels_asked"] = count;
  out["frame_ms_at_rest"] = intervals(4 * count, false);
  const auto picking_ms = [&] {
    double ms = 0.0;
    for (const auto& [pass, sum] : viewer.summary().gpu_ms)
      if (pass.rfind("picking.", 0) == 0) ms += sum;
    return ms;
  };
  const double picking_before = picking_ms();
  out["frame_ms_placing"] = intervals(4 * count, true);
  for (int f = 0; f < 8; ++f) viewer.frame(1.0 / fps);  // (the last picks come back)
  output.wait_idle();
  // (every frame's picking passes over the placing frames, per label: the picks' own GPU time,
  // through the ghosting lenses, and the frames' idle passes)
  out["picking_gpu_ms_per_label"] = (picking_ms() - picking_before) / double(count);
  out["labels_placed"] = scene.labels.size() - before;
  viewer.set_place_mode(false);
  return out;
}

// The placement's own figures over a run: placements finished and taken up, their rate, GPU time
// and latency (frames from the frame that started one to the frame that took it up). In the
// frame: one a frame, no latency, the placement group's time.
ordered_json placement_json(const ViewRun& r, size_t frames, bool beside, double group_ms) {
  const double frame_ms = 1e3 * r.seconds / double(frames);
  if (!beside) {
    return {{"mode", "frame"},
            {"placements", frames},
            {"per_second", double(frames) / r.seconds},
            {"gpu_ms_mean", ms_json(group_ms)},
            {"latency_frames_mean", 0},
            {"latency_frames_max", 0},
            {"latency_ms_mean", 0}};
  }
  const uint64_t count = r.after.placements - r.before.placements;
  const std::vector<uint32_t> latency(
      r.after.placement_latency_frames.begin() + long(r.before.placement_latency_frames.size()),
      r.after.placement_latency_frames.end());
  double sum = 0.0;
  uint32_t most = 0;
  for (const uint32_t l : latency) {
    sum += l;
    most = std::max(most, l);
  }
  const double mean = latency.empty() ? 0.0 : sum / double(latency.size());
  const double gpu = r.after.placement_gpu_ms - r.before.placement_gpu_ms;
  return {{"mode", "beside"},
          {"placements", count},
          {"per_second", double(count) / r.seconds},
          {"gpu_ms_mean", ms_json(count ? gpu / double(count) : 0.0)},
          {"latency_frames_mean", mean},
          {"latency_frames_max", most},
          {"latency_ms_mean", ms_json(mean * frame_ms)}};
}

ordered_json means_json(const std::map<std::string, double>& means) {
  ordered_json out = ordered_json::object();
  for (const auto& [name, ms] : means) out[name.empty() ? "ungrouped" : name] = ms_json(ms);
  return out;
}

// Each top-level group's mean: a group's spans (a group split by another, as the placement by
// its summed-area tables, is stamped once per piece) summed with those of its subgroups; with
// `group_of`, entries are passes and fall to their pass's group.
std::map<std::string, double> group_totals(
    const std::map<std::string, double>& means,
    const std::function<std::string(const std::string&)>& group_of) {
  std::map<std::string, double> out;
  for (const auto& [name, ms] : means) out[top_group(group_of ? group_of(name) : name)] += ms;
  return out;
}

// The path is run three times: with a timestamp around every pass (the time of each), with
// stamps only where groups begin and end, and only where the frame does (the whole frame,
// undisturbed).
enum class Stamps { pass, group, frame };

// One run along the cameras, a frame started `pace` times a second (0: each as soon as the last is
// submitted), after a frame that puts the stamps in place.
ViewRun run_path(Viewer& viewer, HeadlessOutput& output, const std::vector<Camera>& cameras,
                 double fps, double pace, Stamps stamps) {
  if (stamps == Stamps::frame) {
    viewer.runner().set_timestamps_per_frame();
  } else {
    viewer.runner().set_timestamps_per_pass(stamps == Stamps::pass);
  }
  viewer.frame(1.0 / fps);
  output.wait_idle();
  ViewRun r{viewer.summary(), {}, 0.0};
  const auto start = std::chrono::steady_clock::now();
  for (size_t f = 0; f < cameras.size(); ++f) {
    if (pace > 0.0) {
      std::this_thread::sleep_until(start + std::chrono::duration<double>(double(f) / pace));
    }
    viewer.set_camera(cameras[f]);
    viewer.frame(1.0 / fps);
  }
  output.wait_idle();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.after = viewer.summary();
  return r;
}

// Each pass's group, from the graph the frames ran (the per-pass run's group totals).
std::function<std::string(const std::string&)> group_of_passes(Viewer& viewer) {
  std::map<std::string, std::string> pass_group;
  for (const auto& pass : viewer.runner().graph().passes()) pass_group[pass.name] = pass.group;
  return [pass_group](const std::string& pass) {
    const auto it = pass_group.find(pass);
    return it == pass_group.end() ? std::string() : it->second;
  };
}

// For people: the whole frame and where it goes.
void print_view_summary(const ordered_json& out, const std::map<std::string, double>& totals,
                        size_t labels, graph::Extent size, size_t frames) {
  std::fprintf(stderr,
               "bench view: %zu labels, %ux%u, %zu frames: GPU frame median %.3f ms (p95 %.3f)",
               labels, size.width, size.height, frames, out["gpu_frame_ms"]["median"].get<double>(),
               out["gpu_frame_ms"]["p95"].get<double>());
  std::fprintf(stderr, "; group means (stamps at group edges):");
  for (const char* group : {"render", "placement", "labels", "ui"}) {
    const auto it = totals.find(group);
    std::fprintf(stderr, " %s %.3f,", group, it == totals.end() ? 0.0 : it->second);
  }
  const auto other = totals.find("ungrouped");
  std::fprintf(stderr, " ungrouped %.3f ms\n", other == totals.end() ? 0.0 : other->second);
  const ordered_json& placed = out["placement"];
  std::fprintf(stderr,
               "bench view: placement %s: %.1f a second, GPU %.3f ms each, latency %.2f frames "
               "(max %u, %.3f ms); %.1f frames a second\n",
               placed["mode"].get<std::string>().c_str(), placed["per_second"].get<double>(),
               placed["gpu_ms_mean"].get<double>(), placed["latency_frames_mean"].get<double>(),
               placed["latency_frames_max"].get<uint32_t>(),
               placed["latency_ms_mean"].get<double>(), out["frames_per_second"].get<double>());
}

// The viewer as the bench runs it: no idle optimization, every frame's spans kept, nothing
// printed but the report.
ViewerOptions bench_viewer_options(const ViewBenchOptions& o, const Context& ctx) {
  ViewerOptions options;
  options.scene_path = o.scene;
  options.optimize_on_idle = false;
  options.keep_frame_spans = true;
  options.print_actions = false;  // (stdout is the report)
  options.frame_budget_ms = o.frame_budget_ms;
  // (the viewer keeps the placement beside the frames with interactive rendering)
  options.placement_beside = placement_beside(o.placement, ctx) || o.frame_budget_ms > 0.0;
  return options;
}

LabellingSettings bench_view_settings(const ViewBenchOptions& o, const Scene& scene) {
  LabellingSettings settings;
  settings.placement.weights = scene.settings.weights;
  settings.placement.tidy_rounds = o.tidy_rounds;
  settings.forces.keep_apart = o.keep_apart;
  settings.ghost.strength = o.ghost;
  settings.ghost.radius = scene.settings.ghost_radius;
  return settings;
}

// The viewer's whole frame (labelled scene, forces, label drawing, the panel), headless, with two
// frames in flight, along a turntable at 30 frames a second of animation time.
void bench_view(DeviceOptions& device, const ViewBenchOptions& o) {
  const std::string scene_file = find_data_file(o.scene);
  const graph::Extent size = parse_size(o.size, "--size");
  Scene scene = load_scene_reporting(scene_file);
  scene.labels = resized_labels(scene.labels, o.labels, scene_file);
  Context ctx(device.context());
  const double fps = 30.0;
  const std::vector<Camera> cameras =
      sample(orbit_path(scene, scene.camera, o.degrees, double(o.frames) / fps), fps);
  HeadlessOutput output(ctx, size, 2);
  const ViewerOptions options = bench_viewer_options(o, ctx);
  const LabellingSettings settings = bench_view_settings(o, scene);
  Viewer viewer(ctx, scene, cameras.front(), settings, options, output, nullptr);
  for (int i = 0; i < 10; ++i) viewer.frame(1.0 / fps);  // warm up: the HA-Buffer grows
  const ViewRun passes = run_path(viewer, output, cameras, fps, o.pace, Stamps::pass);
  const ViewRun groups = run_path(viewer, output, cameras, fps, o.pace, Stamps::group);
  const ViewRun frames = run_path(viewer, output, cameras, fps, o.pace, Stamps::frame);
  const std::map<std::string, double> group_means = groups.means();
  const std::map<std::string, double> totals = group_totals(group_means, {});
  ordered_json out;
  out["device"] = ctx.report().name;
  out["driver"] = ctx.report().driver;
  out["scene"] = scene_file;
  out["size"] = {size.width, size.height};
  out["labels"] = scene.labels.size();
  out["keep_apart"] = o.keep_apart;
  out["frames"] = cameras.size();
  out["frames_in_flight"] = output.frames_in_flight();
  out["pace"] = o.pace;
  out["frame_budget_ms"] = o.frame_budget_ms;
  out["ghost"] = o.ghost;
  out["largest_divisor"] = frames.after.largest_divisor;
  if (o.place > 0)
    out["placing"] = placing_json(viewer, output, scene, cameras.front(), o.place, fps);
  out["frames_per_second"] = double(cameras.size()) / frames.seconds;
  out["gpu_frame_ms"] = frames.frame_quantiles();
  out["gpu_frame_ms_stamped_per_group"] = groups.frame_quantiles();
  out["mean_group_ms"] = means_json(group_means);
  out["mean_group_total_ms"] = means_json(totals);
  const auto placement_group = totals.find("placement");
  out["placement"] =
      placement_json(frames, cameras.size(), options.placement_beside,
                     placement_group == totals.end() ? 0.0 : placement_group->second);
  out["gpu_frame_ms_stamped_per_pass"] = passes.frame_quantiles();
  out["mean_pass_ms"] = means_json(passes.means());
  out["mean_group_total_ms_stamped_per_pass"] =
      means_json(group_totals(passes.means(), group_of_passes(viewer)));
  print_report(out);
  print_view_summary(out, totals, scene.labels.size(), size, cameras.size());
}

}  // namespace
}  // namespace bench

namespace {

// `bench sat`: the summed-area table alone.
void add_sat_bench(CLI::App* cmd, DeviceOptions& device) {
  struct Options {
    std::string size = "1024";
    uint32_t runs = 50;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sat = cmd->add_subcommand("sat", "summed-area table of a float32 image");
  sat->add_option("--size", options->size, "N or WxH")->capture_default_str();
  sat->add_option("--runs", options->runs, "timed runs after 3 warm-up runs")
      ->capture_default_str()
      ->check(whole_range(1, 100000));
  sat->callback([&device, options] {
    bench::bench_sat(device, parse_size(options->size, "--size"), options->runs);
  });
}

// `bench render`: the volume renderer alone.
void add_render_bench(CLI::App* cmd, DeviceOptions& device) {
  auto runs = std::make_shared<uint32_t>(50);
  auto render = std::make_shared<bench::RenderBenchOptions>();
  CLI::App* render_cmd = cmd->add_subcommand("render", "HA-Buffer build and resolve of a scene");
  render_cmd->add_option("--scene", render->scene, "scene file")->capture_default_str();
  render_cmd->add_option("--size", render->size, "N or WxH")->capture_default_str();
  render_cmd->add_option("--camera", render->camera, "named camera position");
  render_cmd->add_option("--layers", render->layers, "depth layers, 1 to 8")
      ->check(whole_range(1, 8))
      ->capture_default_str();
  render_cmd->add_flag("--no-skipping", render->no_skipping, "turn empty-space skipping off");
  render_cmd
      ->add_option("--step", render->step, "sampling distance in world units (0: half a voxel)")
      ->check(finite_range(0.0, 1000.0));
  render_cmd->add_option("--runs", *runs, "timed runs after 3 warm-up runs")
      ->capture_default_str()
      ->check(whole_range(1, 100000));
  render_cmd->callback([&device, render, runs] { bench::bench_render(device, *render, *runs); });
}

// `bench view`: the viewer's whole frame.
void add_view_bench(CLI::App* cmd, DeviceOptions& device) {
  auto view = std::make_shared<bench::ViewBenchOptions>();
  CLI::App* view_cmd = cmd->add_subcommand(
      "view", "the viewer's whole frame (labels, forces, drawing, UI) along a turntable");
  view_cmd->add_option("scene", view->scene, "scene file")->capture_default_str();
  view_cmd->add_option("--size", view->size, "N or WxH")->capture_default_str();
  view_cmd->add_option("--frames", view->frames, "frames timed along the path")
      ->capture_default_str()
      ->check(whole_range(1, 100000));
  view_cmd->add_option("--labels", view->labels, "label count (the scene's cut, or repeated)")
      ->check(whole_range(0, kMaxLabels));
  view_cmd->add_option("--degrees", view->degrees, "how far the turntable turns")
      ->check(finite_range(-36000.0, 36000.0))
      ->capture_default_str();
  add_tidy_rounds_option(view_cmd, view->tidy_rounds, "per frame");
  view_cmd->add_flag_callback(
      "--let-overlap", [view] { view->keep_apart = false; },
      "labels on their way may overlap (the forces alone, as `video --let-overlap`)");
  add_placement_option(view_cmd, view->placement);
  view_cmd
      ->add_option("--pace", view->pace,
                   "start a frame this many times a second, as a display's refresh would "
                   "(0: each as soon as the last is submitted)")
      ->check(finite_range(0.0, 10000.0))
      ->capture_default_str();
  view_cmd
      ->add_option("--frame-budget", view->frame_budget_ms,
                   "as `view --frame-budget`: while the camera moves (every frame here) cast fewer "
                   "rays to keep a frame within this many ms (0: off)")
      ->check(finite_range(0.0, 10000.0))
      ->capture_default_str();
  view_cmd->add_option("--ghost", view->ghost, "ghosting's strength, 0 (off) to 1")
      ->check(finite_range(0.0, 1.0))
      ->capture_default_str();
  view_cmd
      ->add_option("--place", view->place,
                   "after the runs, place this many labels near the picture's centre (the "
                   "viewer's place mode, a click every fourth frame) and time the frames")
      ->check(whole_range(0, 100))
      ->capture_default_str();
  view_cmd->callback([&device, view] { bench::bench_view(device, *view); });
}

}  // namespace

void add_bench_command(CLI::App& app, DeviceOptions& device) {
  CLI::App* cmd = app.add_subcommand("bench", "GPU timings as JSON (median and min of N runs)");
  cmd->require_subcommand(1);
  add_sat_bench(cmd, device);
  add_render_bench(cmd, device);
  add_placement_bench(cmd, device);
  add_encode_bench(cmd);
  add_segmentation_bench(cmd);
  add_view_bench(cmd, device);
  add_soak_command(cmd, device);
}

}  // namespace strata::app
