// `strata bench soak`: the viewer's frame loop (labelled scene, forces, label drawing, the panel)
// headless for many frames, the camera touring the scene's positions, orbiting and zooming, and
// the panel's settings changed on a schedule through the Viewer calls the panel makes. Host
// memory, device memory and the HA-Buffer are measured every few frames after a warm-up; growth
// past 1% from the warm-up's end to the last frame, or an HA-Buffer still growing in the run's
// second half, is an error. Validation messages are errors too (with --validate).
#include "app/soak_command.h"

#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <functional>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/output_files.h"
#include "app/progress.h"
#include "app/viewer/viewer.h"
#include "engine/core/text_file.h"
#include "engine/gpu/context.h"
#include "engine/scene/transfer_function_presets.h"
#include "labeling/camera_path.h"

namespace strata::app {
namespace {

using ordered_json = nlohmann::ordered_json;

constexpr double kFps = 30.0;           // animation time per frame, as `bench view`
constexpr double kAllowedGrowth = 1.0;  // percent, from the warm-up's end to the last frame

struct SoakOptions {
  std::string scene = "assets/scenes/head.json";
  uint32_t frames = 1000;
  std::string size = "256";
  uint32_t every = 10;     // frames between measurements
  uint32_t interval = 25;  // frames a scheduled change lasts (then as many without it)
  uint32_t habuffer_slots = 0;
  std::string json;
};

// One measurement, after a frame.
struct Sample {
  uint64_t frame = 0;
  uint64_t rss = 0;        // VmRSS: all resident pages, shared libraries' code included
  uint64_t rss_anon = 0;   // RssAnon: resident pages no file backs (what a leak grows)
  uint64_t heap = 0;       // malloc's bytes in use (mallinfo2: arenas and mmapped blocks)
  uint64_t heap_held = 0;  // what malloc holds from the system, free chunks included
  uint64_t mappings = 0;   // lines of /proc/self/maps (JIT code, driver mappings)
  uint64_t device = 0;
  uint64_t allocations = 0;
  std::optional<uint64_t> driver;  // VK_EXT_memory_budget's heapUsage, all heaps
  uint32_t slots = 0;              // the HA-Buffer's capacity
  uint32_t fragments = 0;
  uint32_t overflow = 0;
};

// A "Name:   1234 kB" line of /proc/self/status, in bytes.
uint64_t status_bytes(const std::string& name) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(name + ":", 0) == 0) return std::stoull(line.substr(name.size() + 1)) * 1024;
  }
  return 0;
}

uint64_t mapping_count() {
  std::ifstream maps("/proc/self/maps");
  std::string line;
  uint64_t n = 0;
  while (std::getline(maps, line)) ++n;
  return n;
}

Sample measure(uint64_t frame, Context& ctx, const Viewer& viewer) {
  Sample s;
  s.frame = frame;
  s.rss = status_bytes("VmRSS");
  s.rss_anon = status_bytes("RssAnon");
  const struct mallinfo2 m = mallinfo2();
  s.heap = m.uordblks + m.hblkhd;
  s.heap_held = m.arena + m.hblkhd;
  s.mappings = mapping_count();
  const DeviceMemoryUse use = ctx.memory_use();
  s.device = use.bytes;
  s.allocations = use.allocations;
  s.driver = ctx.heap_usage();
  const RenderStats& r = viewer.render_stats();
  s.slots = r.table_size;
  s.fragments = r.fragments;
  s.overflow = r.overflow;
  return s;
}

// A scheduled change: applied, then undone `interval` frames later.
struct Change {
  std::string what;
  std::function<void()> apply, undo;
};

std::string number_text(float v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", double(v));
  return text;
}

// What the panel can change while the viewer runs, each through the call the panel makes, and
// back to where the run started (so the last frames run as the first did, and their memory
// compares with it). Transfer-function presets follow each other (a preset has no "back").
std::vector<Change> schedule(Viewer& viewer, HeadlessOutput& output, const Scene& scene,
                             const LabellingSettings& s, graph::Extent size) {
  std::vector<Change> out;
  const auto number = [&](const std::string& name, float value, float back) {
    out.push_back({name + " " + number_text(value),
                   [&viewer, name, value] { viewer.set_number(name, value); },
                   [&viewer, name, back] { viewer.set_number(name, back); }});
  };
  const auto flag = [&](const std::string& name, bool value) {
    out.push_back({name + (value ? " on" : " off"),
                   [&viewer, name, value] { viewer.set_flag(name, value); },
                   [&viewer, name, value] { viewer.set_flag(name, !value); }});
  };
  const CostWeights& w = s.placement.weights;
  number("weights.label_shadow", w.label_shadow * 10.0f, w.label_shadow);
  number("layers", 2.0f, float(s.layer_count));
  flag("render.skip_empty", !s.render.skip_empty);
  number("tidy_rounds", 16.0f, float(s.placement.tidy_rounds));
  number("label_scale", 1.5f, s.label_scale);
  flag("hard", !s.placement.hard);
  number("weights.distance_to_anchor", w.distance_to_anchor * 4.0f, w.distance_to_anchor);
  out.push_back(
      {"resize to 3/4",
       [&output, size] {
         output.resize({std::max(1u, size.width * 3 / 4), std::max(1u, size.height * 3 / 4)});
       },
       [&output, size] { output.resize(size); }});
  number("layers", 8.0f, float(s.layer_count));
  flag("internal", !s.internal);
  number("font", s.font_pixels + 6.0f, s.font_pixels);
  flag("layer_colors", !s.layer_colors);
  number("render.step", 2.0f, s.render.step);
  flag("forces.anchor_relative", !s.forces.anchor_relative);
  number("weights.integral_costs", w.integral_costs * 0.1f, w.integral_costs);
  number("margin_em", s.placement.margin_em + 0.5f, s.placement.margin_em);
  if (!scene.labels.empty()) {
    const int id = scene.labels.front().id;
    out.push_back({"label " + std::to_string(id) + " hidden",
                   [&viewer, id] { viewer.set_label_hidden(id, true); },
                   [&viewer, id] { viewer.set_label_hidden(id, false); }});
  }
  out.push_back({"resize to 5/4 x 3/4",
                 [&output, size] {
                   output.resize({size.width * 5 / 4, std::max(1u, size.height * 3 / 4)});
                 },
                 [&output, size] { output.resize(size); }});
  if (!scene.volumes.empty()) {
    for (const TransferFunctionPreset& p : transfer_function_presets()) {
      const std::string name = p.name;
      out.push_back({"preset " + name, [&viewer, name] { viewer.set_preset(0, name); }, [] {}});
    }
  }
  return out;
}

// The camera of frame `i`: the scene's positions one after another, then a turn around the
// scene, twice over the run (so the second half sees what the first saw), zoomed in and out
// (the wheel, as a user would) twice per round.
struct CameraLoop {
  std::optional<CameraPath> tour;
  CameraPath orbit;
  double round = 1.0;  // seconds

  CameraLoop(const Scene& scene, uint32_t frames) {
    round = std::max(2.0, double(frames) / 2.0 / kFps);
    const double tour_share = scene.camera_positions.empty() ? 0.0 : 0.45;
    if (tour_share > 0.0) {
      const double step = round * tour_share / double(scene.camera_positions.size() + 1);
      // (the keys from the poses, not from path text: a position's name may hold an underscore)
      CameraPath path;
      path.centre = parse_camera_path(scene, scene_camera_name).centre;
      path.keys.push_back({scene.camera, 0.0});
      double t = 0.0;
      for (const CameraPose& p : scene.camera_positions) {
        t += step;
        path.keys.push_back({camera_position(scene, p.name), t});
      }
      t += step;
      path.keys.push_back({scene.camera, t});
      tour = path;
    }
    orbit = orbit_path(scene, scene.camera, 360.0, round * (1.0 - tour_share));
  }

  // The camera and the wheel ticks at frame `i`.
  std::pair<Camera, double> at(uint32_t i) const {
    const double t = std::fmod(double(i) / kFps, round);
    const double zoom = 3.0 * std::sin(2.0 * std::numbers::pi * t / (round / 2.0));
    if (tour && t < tour->duration()) return {tour->at(t), zoom};
    return {orbit.at(t - (tour ? tour->duration() : 0.0)), zoom};
  }
};

double growth_percent(uint64_t start, uint64_t end) {
  return start ? (double(end) - double(start)) / double(start) * 100.0 : 0.0;
}

std::string mib(uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f MiB", double(bytes) / (1024.0 * 1024.0));
  return text;
}

struct Series {
  const char* name;  // in messages
  const char* key;   // in the JSON
  uint64_t Sample::*field;
  bool judged;  // growth past kAllowedGrowth fails the soak
};

// VmRSS is reported but not judged: it counts the pages of shared libraries' code a process has
// touched (the shader compiler's first use of a code path, pages the kernel dropped and faulted
// back in), which no leak makes; RssAnon is what allocations keep resident.
const Series kSeries[] = {
    {"host memory (RssAnon)", "host_rss_anon_bytes", &Sample::rss_anon, true},
    {"host memory (VmRSS)", "host_rss_bytes", &Sample::rss, false},
    {"host heap (malloc in use)", "host_heap_bytes", &Sample::heap, true},
    {"device memory (strata's allocations)", "device_bytes", &Sample::device, true},
};

// One HA-Buffer capacity change: at which frame, to how many slots, at which picture size.
struct Capacity {
  uint64_t frame = 0;
  uint32_t slots = 0;
  graph::Extent size;
};

// When the run does what (see soak()): the warm-up, the measurements and the scheduled changes.
struct SoakPlan {
  static constexpr uint32_t plain = 10;  // plain frames before the warm-up's changes
  uint32_t warmup_changes = 0;
  uint32_t warmup = 0;
  uint32_t every = 1;
  uint32_t interval = 1;
  uint32_t changes_end = 0;  // the schedule stops here: the last frames run as the warm-up's did
};

// The warm-up: plain frames (the HA-Buffer grows to what the view needs), then every scheduled
// change once, applied for a frame and undone for a frame, so that what a setting costs the
// first time (pipelines, JIT-compiled shader variants, the allocator's working set) is paid
// before the first measurement; and the camera's whole first round (the run's first half:
// the HA-Buffer meets the closest zoom there). The second half repeats the round and the
// changes, so whatever it adds to memory stays for good: a leak.
SoakPlan plan_soak(const SoakOptions& o, size_t changes) {
  SoakPlan plan;
  plan.warmup_changes = uint32_t(changes);
  plan.warmup = std::max(o.frames / 2, SoakPlan::plain + 2 * plan.warmup_changes);
  if (o.frames < 2 * plan.warmup) {
    throw Error("soak: --frames " + std::to_string(o.frames) + " is too few: the warm-up takes " +
                std::to_string(plan.warmup) + " frames (every scheduled change once), and as " +
                "many must follow it; at least " + std::to_string(2 * plan.warmup));
  }
  plan.every = std::max(1u, o.every);
  plan.interval = std::max(1u, o.interval);
  const uint32_t tail = std::max(plan.interval, o.frames / 20);
  plan.changes_end = o.frames > plan.warmup + tail ? o.frames - tail : plan.warmup;
  return plan;
}

// What the frames gave: the measurements, the HA-Buffer's capacity changes and the changes
// applied.
struct SoakRecord {
  std::vector<Sample> samples;
  std::vector<Capacity> capacity;
  std::vector<std::pair<uint64_t, std::string>> applied;
  double seconds = 0.0;
};

void check_validation(Context& ctx, uint64_t frame) {
  const size_t count = ctx.validation_log().count();
  if (count == 0) return;
  const std::vector<std::string> messages = ctx.validation_log().take();
  throw Error("soak: " + std::to_string(count) + " validation message(s) by frame " +
              std::to_string(frame) + ", the first: " + messages.front());
}

// Frame i's scheduled change: in the warm-up each once, applied then undone; after it one at a
// time, for `interval` frames each, with as many frames between them.
struct ChangeSchedule {
  const std::vector<Change>& changes;
  const SoakPlan& plan;
  const Change* pending = nullptr;
  size_t next = 0;

  void before_frame(uint32_t i, SoakRecord& record) {
    if (i >= SoakPlan::plain && i < SoakPlan::plain + 2 * plan.warmup_changes) {
      const Change& c = changes[(i - SoakPlan::plain) / 2];
      if ((i - SoakPlan::plain) % 2 == 0) {
        c.apply();
      } else {
        c.undo();
      }
    }
    if (i >= plan.warmup && i <= plan.changes_end && (i - plan.warmup) % plan.interval == 0) {
      if (pending) {
        pending->undo();
        pending = nullptr;
      } else if (i < plan.changes_end && !changes.empty()) {
        pending = &changes[next++ % changes.size()];
        pending->apply();
        record.applied.emplace_back(i, pending->what);
      }
    }
  }
};

SoakRecord run_frames(Context& ctx, Viewer& viewer, HeadlessOutput& output, const CameraLoop& loop,
                      const std::vector<Change>& changes, const SoakPlan& plan, uint32_t frames) {
  SoakRecord record;
  ChangeSchedule schedule{changes, plan};
  Progress progress("frame", frames);
  const auto start = std::chrono::steady_clock::now();
  for (uint32_t i = 0; i < frames; ++i) {
    schedule.before_frame(i, record);
    const auto [camera, zoom] = loop.at(i);
    viewer.set_camera(camera);
    viewer.scroll(zoom);
    viewer.frame(1.0 / kFps);
    const RenderStats& r = viewer.render_stats();
    std::vector<Capacity>& capacity = record.capacity;
    if (capacity.empty() || capacity.back().slots != r.table_size ||
        !(capacity.back().size == viewer.extent())) {
      capacity.push_back({i + 1, r.table_size, viewer.extent()});
    }
    progress.step_done(i + 1);
    const bool last = i + 1 == frames;
    if (last) output.wait_idle();  // (the end: every frame finished)
    if ((i + 1 >= plan.warmup && (i + 1 - plan.warmup) % plan.every == 0) || last) {
      record.samples.push_back(measure(i + 1, ctx, viewer));
      check_validation(ctx, i + 1);
    }
  }
  record.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (record.samples.empty()) throw Error("soak: no measurements (--frames below the warm-up)");
  return record;
}

// One memory series, start to end: reported, and past kAllowedGrowth a failure if judged.
void judge_series(ordered_json& report, std::vector<std::string>& failures, const std::string& name,
                  const std::string& key, uint64_t a, uint64_t b, uint64_t peak, bool judged) {
  const double growth = growth_percent(a, b);
  report[key] = {{"start", a}, {"end", b}, {"peak", peak}, {"growth_percent", growth}};
  std::printf("soak: %-38s %14s %14s %14s %+8.2f%%\n", name.c_str(), mib(a).c_str(), mib(b).c_str(),
              mib(peak).c_str(), growth);
  if (judged && growth > kAllowedGrowth) {
    char text[256];
    std::snprintf(text, sizeof text, "soak: %s grew %.2f%% (start %s, end %s)", name.c_str(),
                  growth, mib(a).c_str(), mib(b).c_str());
    failures.emplace_back(text);
  }
}

// Memory from the first measurement after the warm-up to the last.
void judge_memory(ordered_json& report, std::vector<std::string>& failures,
                  const std::vector<Sample>& samples, const Context& ctx) {
  const Sample& first = samples.front();
  const Sample& end = samples.back();
  const std::string span =
      "frame " + std::to_string(first.frame) + " to " + std::to_string(end.frame);
  std::printf("soak: %-38s %14s %14s %14s %9s\n", span.c_str(), "start", "end", "peak", "growth");
  for (const Series& s : kSeries) {
    uint64_t peak = 0;
    for (const Sample& x : samples) peak = std::max(peak, x.*s.field);
    judge_series(report, failures, s.name, s.key, first.*s.field, end.*s.field, peak, s.judged);
  }
  if (first.driver && end.driver) {
    uint64_t peak = 0;
    for (const Sample& x : samples) peak = std::max(peak, x.driver.value_or(0));
    judge_series(report, failures, "device memory (driver's heapUsage)", "driver_heap_usage_bytes",
                 *first.driver, *end.driver, peak, true);
  } else {
    report["driver_heap_usage_bytes"] = nullptr;
    std::printf(
        "soak: device memory (driver's heapUsage): not reported (no "
        "VK_EXT_memory_budget)\n");
  }
  report["device_allocations"] = {{"start", first.allocations}, {"end", end.allocations}};
  std::printf("soak: device allocations %llu -> %llu, peak of strata's device memory %s\n",
              static_cast<unsigned long long>(first.allocations),
              static_cast<unsigned long long>(end.allocations), mib(ctx.memory_use().peak).c_str());
}

// The HA-Buffer's capacity must not grow in the run's second half (at a size it has had before:
// a resize to a larger picture is not growth).
void judge_habuffer(ordered_json& report, std::vector<std::string>& failures,
                    const SoakRecord& record, uint32_t frames) {
  ordered_json history = ordered_json::array();
  std::string history_text;
  uint64_t last_growth = 0;
  const std::vector<Capacity>& capacity = record.capacity;
  for (size_t k = 0; k < capacity.size(); ++k) {
    const Capacity& c = capacity[k];
    history.push_back(
        {{"frame", c.frame}, {"slots", c.slots}, {"size", {c.size.width, c.size.height}}});
    history_text += (k ? ", " : "") + std::to_string(c.slots) + " (frame " +
                    std::to_string(c.frame) + ", " + std::to_string(c.size.width) + "x" +
                    std::to_string(c.size.height) + ")";
    // A resize changes the slots a viewport-sized table has, and a table grown at one size keeps
    // its slots at the next: only an increase at an unchanged size is growth.
    const uint32_t before = k > 0 && capacity[k - 1].size == c.size ? capacity[k - 1].slots : 0;
    if (before == 0 || c.slots <= before) continue;
    last_growth = c.frame;
    if (c.frame > frames / 2) {
      failures.push_back("soak: the HA-Buffer still grows in the run's second half (" +
                         std::to_string(before) + " -> " + std::to_string(c.slots) +
                         " slots at frame " + std::to_string(c.frame) + ")");
    }
  }
  const Sample& first = record.samples.front();
  const Sample& end = record.samples.back();
  uint32_t peak_slots = 0, peak_overflow = 0;
  for (const Sample& x : record.samples) {
    peak_slots = std::max(peak_slots, x.slots);
    peak_overflow = std::max(peak_overflow, x.overflow);
  }
  report["habuffer"] = {
      {"slots", {{"start", first.slots}, {"end", end.slots}, {"peak", peak_slots}}},
      {"fragments_end", end.fragments},
      {"load_end", end.slots ? double(end.fragments) / end.slots : 0.0},
      {"overflow_after_warmup_max", peak_overflow},
      {"last_growth_frame", last_growth},
      {"history", history}};
  std::printf(
      "soak: HA-Buffer slots %u -> %u (peak %u, load %.2f at the end, last growth at "
      "frame %llu); history: %s\n",
      first.slots, end.slots, peak_slots, end.slots ? double(end.fragments) / end.slots : 0.0,
      static_cast<unsigned long long>(last_growth), history_text.c_str());
}

// The changes applied and every measurement, for --json.
void add_record_json(ordered_json& report, const SoakRecord& record) {
  ordered_json changes_json = ordered_json::array();
  for (const auto& [frame, what] : record.applied)
    changes_json.push_back({{"frame", frame}, {"change", what}});
  report["changes"] = changes_json;
  ordered_json samples_json = ordered_json::array();
  for (const Sample& x : record.samples) {
    ordered_json entry = {{"frame", x.frame},          {"rss", x.rss},
                          {"rss_anon", x.rss_anon},    {"heap", x.heap},
                          {"heap_held", x.heap_held},  {"mappings", x.mappings},
                          {"device", x.device},        {"allocations", x.allocations},
                          {"habuffer_slots", x.slots}, {"habuffer_fragments", x.fragments}};
    entry["driver_heap_usage"] = x.driver ? ordered_json(*x.driver) : ordered_json(nullptr);
    samples_json.push_back(entry);
  }
  report["samples"] = samples_json;
}

void soak(DeviceOptions& device, const SoakOptions& o) {
  const std::string scene_file = find_data_file(o.scene);
  const graph::Extent size = parse_size(o.size, "--size");
  Scene scene = load_scene_reporting(scene_file);
  if (!o.json.empty()) check_output_file("--json", o.json);
  Context ctx(device.context());
  check_image_size(ctx, {size.width * 5 / 4, size.height}, "--size");
  LabellingSettings settings;
  settings.placement.weights = scene.settings.weights;
  settings.placement.tidy_rounds = kViewerTidyRounds;
  settings.layer_count = uint32_t(std::max(1, scene.settings.layer_count));
  HeadlessOutput output(ctx, size, 2);
  ViewerOptions options;
  options.scene_path = scene_file;
  options.optimize_on_idle = false;  // (the camera never rests)
  const CameraLoop loop(scene, o.frames);
  Viewer viewer(ctx, scene, loop.at(0).first, settings, options, output, nullptr);
  if (o.habuffer_slots) viewer.set_habuffer_slots(o.habuffer_slots);
  const std::vector<Change> changes = schedule(viewer, output, scene, settings, size);
  const SoakPlan plan = plan_soak(o, changes.size());
  const SoakRecord record = run_frames(ctx, viewer, output, loop, changes, plan, o.frames);

  const double seconds = record.seconds;
  ordered_json report = {{"benchmark", "soak"},
                         {"device", ctx.report().name},
                         {"scene", scene_file},
                         {"size", {size.width, size.height}},
                         {"frames", o.frames},
                         {"warmup_frames", plan.warmup},
                         {"measured_every", plan.every},
                         {"change_interval", plan.interval},
                         {"seconds", seconds},
                         {"frames_per_second", double(o.frames) / seconds},
                         {"changes_applied", record.applied.size()}};
  std::printf("soak: %s, %u frames at %ux%u on %s, %.1f s (%.2f frames/s), %zu changes\n",
              scene_file.c_str(), o.frames, size.width, size.height, ctx.report().name.c_str(),
              seconds, double(o.frames) / seconds, record.applied.size());
  std::vector<std::string> failures;
  judge_memory(report, failures, record.samples, ctx);
  judge_habuffer(report, failures, record, o.frames);
  add_record_json(report, record);
  report["validation_messages"] = ctx.validation_log().count();
  report["failures"] = failures;
  report["ok"] = failures.empty();
  if (!o.json.empty()) {
    write_text_file(o.json,
                    report.dump(2, ' ', false, ordered_json::error_handler_t::replace) + "\n");
  }
  check_validation(ctx, o.frames);
  if (!failures.empty()) {
    std::string all;
    for (const std::string& f : failures) all += (all.empty() ? "" : "; ") + f;
    throw Error(all);
  }
  std::printf("soak: ok (memory within %.0f%% of the warm-up's end, HA-Buffer settled)\n",
              kAllowedGrowth);
}

}  // namespace

void add_soak_command(CLI::App* bench, DeviceOptions& device) {
  auto o = std::make_shared<SoakOptions>();
  CLI::App* cmd = bench->add_subcommand(
      "soak",
      "the viewer's frame loop for many frames (camera moving, settings changing); memory and "
      "HA-Buffer growth are errors");
  cmd->add_option("scene", o->scene, "scene file")->capture_default_str();
  cmd->add_option("--frames", o->frames, "frames to run")
      ->capture_default_str()
      ->check(whole_range(1, 10000000));
  cmd->add_option("--size", o->size, "N or WxH")->capture_default_str();
  cmd->add_option("--every", o->every, "frames between measurements after the warm-up")
      ->capture_default_str()
      ->check(whole_range(1, 1000000));
  cmd->add_option("--interval", o->interval, "frames a scheduled change lasts")
      ->capture_default_str()
      ->check(whole_range(1, 1000000));
  cmd->add_option("--habuffer-slots", o->habuffer_slots,
                  "the HA-Buffer's slots at the start (it grows from there; 0: from the size)")
      ->check(whole_range(0, double(UINT32_MAX)))  // (the device's limit is checked with the sizes)
      ->capture_default_str();
  cmd->add_option("--json", o->json, "also write the summary and every measurement as JSON");
  cmd->callback([&device, o] { soak(device, *o); });
}

}  // namespace strata::app
