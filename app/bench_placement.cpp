// `strata bench placement` (app/bench_placement.h): one Context, a LabelledRenderer per label
// count, each measured with a stamp around every pass, again with stamps only where groups begin
// and end, and (unless --no-baseline) against a frame of its own submitted a label at a time.
#include "app/bench_placement.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <tuple>

#include "app/bench_timings.h"
#include "frame/labelled_render.h"
#include "shared/placement.h"

namespace strata::app {
namespace bench {

std::vector<Label> resized_labels(const std::vector<Label>& labels, uint32_t count,
                                  const std::string& scene_file) {
  if (count == 0) return labels;
  if (labels.empty()) {
    throw Error(scene_file + ": labels: none to cut or repeat to --labels " +
                std::to_string(count));
  }
  std::vector<Label> out;
  for (uint32_t i = 0; i < count; ++i) {
    Label l = labels[i % labels.size()];
    const auto round = static_cast<float>(i / labels.size());
    l.anchor += glm::vec3(2.0f * round, -2.0f * round, 0.0f);
    l.id = int(i) + 1;
    out.push_back(l);
  }
  return out;
}

namespace {

struct PlacementBenchOptions {
  std::string scene = "assets/scenes/head-100.json";
  std::string size = "1024";
  std::string camera;
  std::string labels;        // one count or a list ("10,50,100"); empty or 0: the scene's labels
  bool no_baseline = false;  // skip the readback-per-label baseline (slow with many labels)
  uint32_t runs = 50;
  std::optional<float> ghost;  // ghosting's strength; none: the scene's settings.ghost
  PlacementMethod greedy = PlacementMethod::sequential;
  uint32_t rounds = PlacementSettings{}.rounds;            // the rounds at most
  uint32_t round_tiles = PlacementSettings{}.round_tiles;  // tiles a label searches at most
  uint32_t tidy_rounds = PlacementSettings{}.tidy_rounds;
  bool wide = false;  // PlacementSettings::wide_search
};

// --labels: "100" or "10,50,100", each 0 (the scene's own labels) to kMaxLabels.
std::vector<uint32_t> parse_label_counts(const std::string& text) {
  std::vector<uint32_t> counts;
  for (size_t begin = 0;;) {
    const size_t end = std::min(text.find(',', begin), text.size());
    const std::string item = text.substr(begin, end - begin);
    const bool digits =
        !item.empty() && item.size() <= 5 &&
        std::all_of(item.begin(), item.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (!digits || std::stoul(item) > size_t(kMaxLabels)) {
      throw UsageError("--labels: '" + item + "' is not a label count from 0 to " +
                       std::to_string(kMaxLabels) + " (one, or a list: 10,50,100)");
    }
    counts.push_back(uint32_t(std::stoul(item)));
    if (end == text.size()) return counts;
    begin = end + 1;
  }
}

// One label count's placement, measured.
struct PlacementRun {
  Timings timings;  // a stamp around every pass
  uint32_t labels = 0, labels_shown = 0, layers = 0;
  double whole_ms = 0.0;    // the placement group with stamps only at its two ends
  double stamped_ms = 0.0;  // the same group with a stamp around every pass
  double loop_ms = 0.0, tidy_ms = 0.0, forces_ms = 0.0;
  std::optional<double> baseline_loop_ms;  // the label loop with a readback after every label
  double first_tiles = 0.0, rest_tiles = 0.0;
  uint32_t tidy_rounds = 0, tidy_rounds_run = 0;  // asked (after the cap), and that ran
  uint32_t greedy_rounds = 0;  // rounds of the greedy placement that decided labels (rounds only)
  ordered_json pipelines;

  // The stages before the loop (per-pass stamps) plus the loop with a readback per label.
  std::optional<double> baseline_ms() const {
    if (!baseline_loop_ms) return std::nullopt;
    return stamped_ms - loop_ms + *baseline_loop_ms;
  }
  double ms_per_pass(const std::string& name) const {
    for (const auto& [pass, stat] : timings.passes) {
      if (pass == name) return stat.median;
    }
    return 0.0;
  }
};

ordered_json optional_ms(std::optional<double> ms) {
  return ms ? ordered_json(ms_json(*ms)) : ordered_json(nullptr);
}

// The thesis program's structure: back to the CPU after every label, reading its result. A
// frame of its own with the label loop as a pass per step (step s finishes position s - 1): the
// passes before the loop first, then a submission per label (the first with step 0, the
// speculative start) and a readback of the results after each. Returns the median time of the
// loop so split, on the host's clock.
double label_loop_with_readback_per_label(Context& ctx, const Scene& scene, const Camera& camera,
                                          graph::Extent size, LabellingSettings settings,
                                          uint32_t runs) {
  settings.placement_layout.pass_per_label = true;
  LabelledRenderer frame(ctx, scene, camera, size, settings);
  frame.run();  // warm up, grow the HA-Buffer if it must, and set the frame's order
  graph::GraphRunner& runner = frame.runner();
  const graph::PassId loop = frame.placement().label_loop;
  const auto labels = static_cast<graph::PassId>(frame.placement_order_count());
  std::vector<double> readback_ms;
  for (uint32_t run = 0; run < std::max(1u, runs / 4) && labels > 0; ++run) {
    runner.run_passes(0, loop);
    const auto start = std::chrono::steady_clock::now();
    for (graph::PassId label = 1; label <= labels; ++label) {
      runner.run_passes(label == 1 ? loop : loop + label, loop + label + 1);
      runner.download_buffer(frame.placement().results);
    }
    readback_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
  }
  return stat_of(readback_ms.empty() ? std::vector<double>{0.0} : readback_ms).median;
}

// How many 32x32 tiles each label's passes took (of all the image's tiles), on average: the
// speculative one (bucket 0) and the main one beyond bucket 0.
std::pair<double, double> tiles_per_label(LabelledRenderer& frame) {
  graph::GraphRunner& runner = frame.runner();
  runner.run_now();
  const std::vector<std::byte> bytes = runner.download_buffer(frame.placement().buckets);
  std::vector<gpu::PlacementBucketsGpu> buckets(bytes.size() / sizeof(gpu::PlacementBucketsGpu));
  std::memcpy(buckets.data(), bytes.data(), buckets.size() * sizeof(gpu::PlacementBucketsGpu));
  // (dispatches 0 .. labels ran: entry s of each label s, and one more)
  size_t placed = 0;
  while (placed + 1 < buckets.size() && buckets[placed + 1].done != 0) ++placed;
  double first = 0.0, rest = 0.0;
  for (size_t i = 0; i < placed; ++i) {
    first += buckets[i].counts[0];
    rest += buckets[i].rest;
  }
  if (placed == 0) return {0.0, 0.0};
  return {first / double(placed), rest / double(placed)};
}

// How many of the tidy-up's rounds ran in the last frame (a round runs when the one before it
// applied a change; the rest leave at once).
uint32_t tidy_rounds_run(LabelledRenderer& frame, uint32_t rounds) {
  graph::GraphRunner& runner = frame.runner();
  const std::vector<std::byte> bytes = runner.download_buffer(frame.placement().tidy_rounds);
  std::vector<uint32_t> applied(bytes.size() / sizeof(uint32_t));
  std::memcpy(applied.data(), bytes.data(), applied.size() * sizeof(uint32_t));
  uint32_t run = 0;
  for (uint32_t r = 0; r < rounds && r < applied.size(); ++r) run += applied[r] != 0;
  return run;
}

// How many of the greedy placement's rounds decided labels in the last frame (0: sequential).
uint32_t greedy_rounds_run(LabelledRenderer& frame) {
  if (frame.settings().placement.method != PlacementMethod::rounds) return 0;
  graph::GraphRunner& runner = frame.runner();
  const std::vector<std::byte> bytes = runner.download_buffer(frame.placement().round_counts);
  std::vector<uint32_t> undecided(bytes.size() / sizeof(uint32_t));
  std::memcpy(undecided.data(), bytes.data(), undecided.size() * sizeof(uint32_t));
  uint32_t run = 0;
  for (const uint32_t count : undecided) run += count != 0;
  return run;
}

LabellingSettings labelling_settings(const Scene& scene, const PlacementBenchOptions& o) {
  LabellingSettings settings;
  settings.placement.method = o.greedy;
  settings.placement.rounds = o.rounds;
  settings.placement.round_tiles = o.round_tiles;
  settings.placement.tidy_rounds = o.tidy_rounds;
  settings.placement.wide_search = o.wide;
  settings.placement.weights = scene.settings.weights;
  settings.ghost.strength = scene.settings.ghost;
  settings.ghost.radius = scene.settings.ghost_radius;
  return settings;
}

PlacementRun measure_placement(Context& ctx, const Scene& scene, const Camera& camera,
                               graph::Extent size, const PlacementBenchOptions& o) {
  const LabellingSettings settings = labelling_settings(scene, o);
  LabelledRenderer frame(ctx, scene, camera, size, settings);
  frame.run();  // warm up, and grow the HA-Buffer if it must
  graph::GraphRunner& runner = frame.runner();
  PlacementRun r;
  // (three warm-up runs: with one, a sweep read a count's loop much slower than a run of that
  // count alone; the GPU idles while the CPU builds each count's frame)
  r.timings = measure(runner, 3, o.runs);
  // The whole placement again with timestamps only where groups begin and end (a stamp waits for
  // the GPU to drain and costs time the real frame does not spend).
  runner.set_timestamps_per_pass(false);
  for (const auto& [name, stat] : measure(runner, 3, o.runs).groups) {
    if (name == "placement") r.whole_ms = stat.median;
  }
  runner.set_timestamps_per_pass(true);
  for (const auto& [name, stat] : r.timings.groups) {
    if (name == "placement") r.stamped_ms = stat.median;
  }
  // (the greedy placement: one of the two passes records dispatches)
  r.loop_ms = r.ms_per_pass(runner.graph().passes()[frame.placement().label_loop].name) +
              r.ms_per_pass(runner.graph().passes()[frame.placement().rounds].name);
  r.tidy_ms = r.ms_per_pass("placement.tidy");   // the tidy-up
  r.forces_ms = r.ms_per_pass("labels.forces");  // thesis 3.4: one invocation per label
  std::tie(r.first_tiles, r.rest_tiles) = tiles_per_label(frame);  // (runs a frame)
  r.tidy_rounds =
      placement_params(settings.placement, size, 1, uint32_t(scene.labels.size()), 0).tidy_rounds;
  r.tidy_rounds_run = tidy_rounds_run(frame, r.tidy_rounds);
  r.greedy_rounds = greedy_rounds_run(frame);
  const LabelledFrame last = frame.result(false);
  r.labels = uint32_t(scene.labels.size());
  for (const LabelLayout& l : last.labels) r.labels_shown += l.placed;
  r.layers = last.layering.layer_count;
  r.pipelines = pipelines_json(frame.placement_pipelines());
  return r;
}

// The derived figures of one count, under the keys the single-count report has always had.
ordered_json placement_results(const PlacementRun& r) {
  const std::optional<double> baseline = r.baseline_ms();
  ordered_json speedup = nullptr;
  if (baseline) {
    speedup = r.whole_ms > 0.0 ? std::round(*baseline / r.whole_ms * 100.0) / 100.0 : 0.0;
  }
  return {{"placement_ms", ms_json(r.whole_ms)},
          {"placement_ms_stamped_per_pass", ms_json(r.stamped_ms)},
          {"label_loop_ms", ms_json(r.loop_ms)},
          {"forces_ms", ms_json(r.forces_ms)},
          {"label_loop_with_readback_per_label_ms", optional_ms(r.baseline_loop_ms)},
          {"placement_with_readback_per_label_ms", optional_ms(baseline)},
          {"speedup", speedup},
          {"tiles_per_label_speculative", r.first_tiles},
          {"tiles_per_label_main_beyond_speculative", r.rest_tiles},
          {"tidy_rounds", r.tidy_rounds},
          {"tidy_rounds_run", r.tidy_rounds_run},
          {"greedy_rounds", r.greedy_rounds},
          {"greedy_ms_per_round",
           r.greedy_rounds ? ordered_json(ms_json(r.loop_ms / r.greedy_rounds)) : ordered_json(nullptr)}};
}

// The label loop's time per label asked for, in µs: how the loop's chain of dispatches grows.
double loop_us_per_label(const PlacementRun& r) {
  return r.labels ? r.loop_ms * 1e3 / r.labels : 0.0;
}

// A sweep's entry: the count, its figures, and every pass's and group's median.
ordered_json sweep_entry(const PlacementRun& r) {
  ordered_json entry = {
      {"labels", r.labels}, {"labels_shown", r.labels_shown}, {"layers", r.layers}};
  entry.update(placement_results(r));
  entry["label_loop_us_per_label"] = std::round(loop_us_per_label(r) * 1e3) / 1e3;
  entry["tidy_ms"] = ms_json(r.tidy_ms);
  entry["placement_rest_ms"] = ms_json(r.stamped_ms - r.loop_ms - r.tidy_ms);
  for (const auto& [key, list] :
       {std::pair{"groups", &r.timings.groups}, std::pair{"passes", &r.timings.passes}}) {
    ordered_json& medians = entry[key] = ordered_json::object();
    for (const auto& [name, stat] : *list) medians[name] = ms_json(stat.median);
  }
  return entry;
}

// The table for people, on stderr, a row as each count is done (a sweep on a slow device takes
// a while): the whole placement, then its parts from the run with a stamp around every pass.
void print_placement_row(const PlacementRun* r) {
  if (!r) {
    std::fprintf(stderr, "%6s %6s %12s %10s %7s %9s %12s %9s %9s %9s %12s\n", "labels", "shown",
                 "placement", "greedy", "rounds", "us/label", "tidy-up", "rounds", "rest",
                 "forces", "baseline");
    return;
  }
  const std::optional<double> baseline = r->baseline_ms();
  char base[32] = "-";
  if (baseline) std::snprintf(base, sizeof base, "%.3f", *baseline);
  char rounds[32];  // (tidy-up rounds that ran of those asked)
  std::snprintf(rounds, sizeof rounds, "%u/%u", r->tidy_rounds_run, r->tidy_rounds);
  std::fprintf(stderr, "%6u %6u %12.3f %10.3f %7u %9.2f %12.3f %9s %9.3f %9.4f %12s   (ms)\n",
               r->labels, r->labels_shown, r->whole_ms, r->loop_ms, r->greedy_rounds,
               loop_us_per_label(*r),
               r->tidy_ms, rounds, r->stamped_ms - r->loop_ms - r->tidy_ms, r->forces_ms, base);
}

void bench_placement(DeviceOptions& device, const PlacementBenchOptions& o) {
  const std::vector<uint32_t> counts = parse_label_counts(o.labels.empty() ? "0" : o.labels);
  const std::string scene_file = find_data_file(o.scene);
  const graph::Extent size = parse_size(o.size, "--size");
  Scene scene = load_scene_reporting(scene_file);
  const Camera camera = option_camera(scene, o.camera);
  std::vector<std::vector<Label>> labels;
  for (const uint32_t count : counts) {
    labels.push_back(resized_labels(scene.labels, count, scene_file));
  }
  if (o.ghost) scene.settings.ghost = *o.ghost;
  Context ctx(device.context());
  const glm::uvec2 tiles = gpu::placement_tiles(size.width, size.height);
  // One renderer at a time (it keeps a reference to the scene, whose labels change between).
  std::vector<PlacementRun> measured;
  print_placement_row(nullptr);
  for (std::vector<Label>& these : labels) {
    scene.labels = std::move(these);
    measured.push_back(measure_placement(ctx, scene, camera, size, o));
    if (!o.no_baseline) {
      // (the sequential loop's, the thesis program's structure)
      PlacementBenchOptions sequential = o;
      sequential.greedy = PlacementMethod::sequential;
      measured.back().baseline_loop_ms = label_loop_with_readback_per_label(
          ctx, scene, camera, size, labelling_settings(scene, sequential), o.runs);
    }
    print_placement_row(&measured.back());
  }
  if (counts.size() == 1) {
    const PlacementRun& r = measured.front();
    const ordered_json setup = {{"benchmark", "placement"}, {"scene", scene_file},
                                {"greedy", o.greedy == PlacementMethod::rounds ? "rounds" : "sequential"},
                                {"width", size.width},      {"height", size.height},
                                {"labels", r.labels},       {"labels_shown", r.labels_shown},
                                {"layers", r.layers},       {"ghost", scene.settings.ghost}};
    ordered_json results = placement_results(r);
    results["tiles"] = tiles.x * tiles.y;
    if (!r.pipelines.empty()) results["pipelines"] = r.pipelines;
    print_json(ctx, setup, o.runs, r.timings, results);
    return;
  }
  // Several counts: the setup they share, then one entry per count.
  ordered_json report = {{"device", ctx.report().name},
                         {"driver", ctx.report().driver},
                         {"benchmark", "placement"},
                         {"scene", scene_file},
                         {"greedy", o.greedy == PlacementMethod::rounds ? "rounds" : "sequential"},
                         {"ghost", scene.settings.ghost},
                         {"width", size.width},
                         {"height", size.height},
                         {"tiles", tiles.x * tiles.y},
                         {"runs", o.runs},
                         {"readback_baseline", !o.no_baseline},
                         {"sweep", ordered_json::array()}};
  for (const PlacementRun& r : measured) report["sweep"].push_back(sweep_entry(r));
  if (!measured.front().pipelines.empty()) report["pipelines"] = measured.front().pipelines;
  print_report(report);
}

}  // namespace
}  // namespace bench

void add_placement_bench(CLI::App* bench_cmd, DeviceOptions& device) {
  auto place = std::make_shared<bench::PlacementBenchOptions>();
  CLI::App* place_cmd = bench_cmd->add_subcommand(
      "placement", "label placement per stage, against a CPU readback after every label");
  place_cmd->add_option("--scene", place->scene, "scene file")->capture_default_str();
  place_cmd->add_option("--size", place->size, "N or WxH")->capture_default_str();
  place_cmd->add_option("--camera", place->camera, "named camera position");
  place_cmd->add_option("--labels", place->labels,
                        "label count, or a list of them (10,50,100): the scene's labels cut or "
                        "repeated");
  place_cmd
      ->add_option("--ghost", place->ghost,
                   "ghosting's strength, 0 (off) to 1 (default: the scene's settings.ghost)")
      ->check(finite_range(0.0, 1.0));
  add_greedy_option(place_cmd, place->greedy);
  place_cmd->add_option("--rounds", place->rounds, "the greedy placement's rounds at most")
      ->check(whole_range(1, ROUNDS_MAX))
      ->capture_default_str();
  place_cmd
      ->add_option("--round-tiles", place->round_tiles,
                   "32x32 tiles of candidates a label searches at most in the rounds")
      ->check(whole_range(1, 65536))
      ->capture_default_str();
  add_tidy_rounds_option(place_cmd, place->tidy_rounds, "after the placement (0: none)");
  place_cmd->add_flag("--wide", place->wide,
                      "in the rounds, a label with no wanted position in its tiles searches all");
  place_cmd->add_flag("--no-baseline", place->no_baseline,
                      "skip the baseline with a readback after every label (slow with many)");
  place_cmd->add_option("--runs", place->runs, "timed runs after 3 warm-up runs")
      ->capture_default_str()
      ->check(whole_range(1, 100000));
  place_cmd->callback([&device, place] { bench::bench_placement(device, *place); });
}

}  // namespace strata::app
