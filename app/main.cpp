#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <vector>

#include "app/commands.h"
#include "engine/core/error.h"
#include "engine/core/files_read.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/io/volume_loader.h"
#include "engine/scene/transfer_function_presets.h"
#include "frame/labelled_render.h"
#include "labeling/camera_path.h"
#include "labeling/text_layout.h"
#include "passes/volume_renderer.h"

namespace strata::app {

ContextOptions DeviceOptions::context() const {
  ContextOptions options;
  options.device_selector = device;
  const char* env = std::getenv("STRATA_VALIDATE");
#ifdef NDEBUG
  options.validation = validate || (env && std::string(env) == "1");
#else
  options.validation = !(env && std::string(env) == "0");
#endif
  return options;
}

namespace {

Scene load_scene_reporting(const SceneInput& in, const VolumeLimits& limits) {
  SceneOpenOptions options;
  options.limits = limits;
  options.preset = in.preset;
  options.labels = in.labels;
  if (in.frame >= 0) options.frame = in.frame;
  options.series = in.series;
  // A scene file names its volumes' series and frames itself.
  if (!in.series.empty() && !is_volume_path(in.file))
    throw UsageError("--series: " + in.file +
                     " is a scene file; --series chooses the series of a DICOM folder opened "
                     "directly (a scene file names it in its volume's \"series\")");
  if (in.frame >= 0 && !is_volume_path(in.file))
    throw UsageError("--frame: " + in.file +
                     " is a scene file; --frame chooses the frame of a 4-D volume opened directly "
                     "(a scene file names it in its volume's \"frame\")");
  if (!in.crop.empty()) {
    const std::vector<float> v =
        parse_numbers(in.crop, 6, "--crop", "X0,Y0,Z0,X1,Y1,Z1 (world mm, LPS)");
    const glm::vec3 lo(v[0], v[1], v[2]), hi(v[3], v[4], v[5]);
    if (!glm::all(glm::lessThan(lo, hi)))
      throw UsageError("--crop: '" + in.crop + "': each low corner value must be below the high");
    options.cut = crop_planes(lo, hi);
  }
  if (in.clip.size() > 6) throw UsageError("--clip: at most six planes");
  for (const std::string& text : in.clip) {
    const std::vector<float> v =
        parse_numbers(text, 6, "--clip", "PX,PY,PZ,NX,NY,NZ (world mm, LPS)");
    const glm::vec3 normal(v[3], v[4], v[5]);
    if (!clip_normal_usable(normal))
      throw UsageError("--clip: '" + text +
                       "': the normal (NX,NY,NZ) must not be zero (a length above 1e-6)");
    options.cut.push_back(clip_plane(glm::vec3(v[0], v[1], v[2]), normal));
  }
  if (!in.window.empty()) {
    if (!in.preset.empty()) throw UsageError("give --preset or --window, not both");
    options.window = parse_window(in.window);
  }
  Scene scene;
  try {
    scene = load_scene(in.file, options);
  } catch (const Error& e) {
    // A --series the folder does not hold is a usage error (as an unknown --camera is); the
    // folder is listed again on this path only.
    std::error_code error;
    if (!in.series.empty() && std::filesystem::is_directory(in.file, error)) {
      const std::vector<DicomSeries> held = list_dicom_series_isolated(in.file);
      if (std::none_of(held.begin(), held.end(), [&](const DicomSeries& s) {
            return s.uid == in.series || s.number == in.series;
          }))
        throw UsageError(std::string("--series: ") + e.what());
    }
    throw;
  }
  // DICOM series and meshes are read in a child process (isolated_read.h), which records
  // nothing here: their files and folders count as read all the same.
  for (const Volume& v : scene.volumes) record_file_read(v.source);
  for (const Mesh& m : scene.meshes) record_file_read(m.source);
  if (!scene.labels.empty()) {  // (characters no font draws: the size does not matter)
    for (std::string& w : missing_glyph_warnings(Font(16.0f), scene.labels))
      scene.warnings.push_back(std::move(w));
  }
  for (const std::string& warning : scene.warnings)
    std::fprintf(stderr, "strata: warning: %s\n", warning.c_str());
  return scene;
}

}  // namespace

Scene load_scene_reporting(const SceneInput& in) {
  return load_scene_reporting(in, VolumeLimits{});
}

Scene load_scene_reporting(const SceneInput& in, const Context& ctx) {
  return load_scene_reporting(in, device_volume_limits(ctx));
}

Scene load_scene_reporting(const std::string& path) {
  return load_scene_reporting(SceneInput{.file = path});
}

std::vector<float> parse_numbers(const std::string& text, size_t count, const char* option,
                                 const char* form) {
  std::vector<float> out;
  size_t start = 0;
  for (;;) {
    const size_t comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? comma : comma - start);
    char* end = nullptr;
    const float v = std::strtof(part.c_str(), &end);
    if (part.empty() || end != part.c_str() + part.size() || !(std::abs(v) <= 1e9f)) break;
    out.push_back(v);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (out.size() != count || std::count(text.begin(), text.end(), ',') != std::ptrdiff_t(count - 1))
    throw UsageError(std::string(option) + ": '" + text + "' is not " + form);
  return out;
}

glm::vec2 parse_window(const std::string& text) {
  const char* form =
      "CENTER,WIDTH (the volume's values, e.g. 40,80 for brain or 400,1800 for bone in HU; "
      "width > 0)";
  const std::vector<float> v = parse_numbers(text, 2, "--window", form);
  if (!(v[1] > 0.0f)) throw UsageError("--window: '" + text + "' is not " + form);
  return {v[0], v[1]};
}

Camera option_camera(const Scene& scene, const std::string& name, const char* option) {
  try {
    return camera_position(scene, name);
  } catch (const Error& e) {
    throw UsageError(std::string(option) + ": " + e.what());
  }
}

void refuse_empty_values(CLI::App& app) {
  const CLI::Validator not_empty(
      [](std::string& input) { return input.empty() ? std::string("an empty value") : ""; }, "");
  for (CLI::Option* option : app.get_options()) {
    if (option->get_type_size() != 0) option->check(not_empty);
  }
  for (CLI::App* sub : app.get_subcommands({})) refuse_empty_values(*sub);
}

void check_options_apply(const CLI::App* cmd, bool has_scene,
                         std::initializer_list<const char*> pattern_options,
                         std::initializer_list<const char*> pattern_only) {
  const auto named = [](std::initializer_list<const char*> names, const CLI::Option* option) {
    return std::any_of(names.begin(), names.end(),
                       [&](const char* name) { return option->check_name(name); });
  };
  for (const CLI::Option* option : cmd->get_options()) {
    if (option->count() == 0 || !option->nonpositional()) continue;
    if (has_scene && named(pattern_only, option))
      throw UsageError(option->get_name() + ": applies to the test pattern only (no scene)");
    if (!has_scene && !named(pattern_options, option) && !named(pattern_only, option))
      throw UsageError(option->get_name() +
                       ": needs a scene (with none given the test pattern is drawn)");
  }
}

uint32_t SceneInput::layer_count(const Scene& scene) const {
  return layers > 0 ? layers : uint32_t(scene.settings.layer_count);  // (the loader checked it)
}

void add_scene_input_options(CLI::App* cmd, SceneInput& in) {
  std::string presets;
  for (const TransferFunctionPreset& p : transfer_function_presets())
    presets += std::string(presets.empty() ? "" : ", ") + p.name;
  cmd->add_option("--preset", in.preset,
                  "transfer-function preset for every volume: " + presets +
                      " (default: the volume's own, else chosen from its values)")
      ->check(CLI::Validator(
          [presets](std::string& input) -> std::string {
            for (const TransferFunctionPreset& p : transfer_function_presets())
              if (input == p.name) return {};
            return "'" + input + "' is not a preset (" + presets + ")";
          },
          "PRESET"));
  cmd->add_option("--labels", in.labels,
                  "labels from a file: 3D Slicer markups (.mrk.json, .fcsv) or CSV "
                  "(docs/scene-format.md)");
  cmd->add_option("--frame", in.frame,
                  "a 4-D volume's frame or a DICOM series' time point, from 0 (default: the first)")
      ->check(whole_range(0, 1e6));
  cmd->add_option("--window", in.window,
                  "CENTER,WIDTH: every volume shown as a grey ramp over these values (Hounsfield "
                  "units for CT: 40,80 brain, 400,1800 bone), in place of its transfer function");
  cmd->add_option("--crop", in.crop,
                  "X0,Y0,Z0,X1,Y1,Z1: show only this box of every volume (world mm, LPS)");
  cmd->add_option("--clip", in.clip,
                  "PX,PY,PZ,NX,NY,NZ: cut every volume at the plane through P, keeping the side "
                  "N points to (world mm, LPS); up to six")
      ->allow_extra_args(false);  // one plane an --clip: the next word is not a second plane
  cmd->add_option("--series", in.series,
                  "a DICOM folder holding several series: the one with this SeriesNumber or "
                  "SeriesInstanceUID (default: the largest 3-D image series; strata info FOLDER "
                  "lists them)");
  cmd->add_option("--layers", in.layers,
                  "depth layers, 1 to " + std::to_string(kMaxLayers) +
                      " (default: the scene's settings.layers, else 4)")
      ->check(whole_range(1, kMaxLayers));
}

std::string find_data_file(const std::string& relative) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (fs::exists(relative, error)) return relative;
  const fs::path program = fs::read_symlink("/proc/self/exe", error);
  std::vector<fs::path> tried;
  if (!error) {
    const fs::path folder = program.parent_path();
    tried = {folder.parent_path().parent_path() / relative,      // build/app/strata
             folder.parent_path() / "share/strata" / relative};  // bin/strata, installed
  }
  tried.push_back(fs::path(STRATA_SOURCE_DIR) / relative);  // the tree it was built from
  for (const fs::path& p : tried) {
    if (fs::exists(p, error)) return p.lexically_normal().string();
  }
  throw Error(relative + ": not found here, beside the program or in " STRATA_SOURCE_DIR
                         " (give the file)");
}

void check_image_size(const Context& ctx, graph::Extent size, const char* option) {
  const uint32_t limit = ctx.properties().limits.maxImageDimension2D;
  if (size.width > limit || size.height > limit) {
    throw UsageError(std::string(option) + ": " + std::to_string(size.width) + "x" +
                     std::to_string(size.height) + " is larger than the device's " +
                     std::to_string(limit) + " pixels a side (maxImageDimension2D)");
  }
}

void add_placement_option(CLI::App* cmd, std::string& mode) {
  cmd->add_option("--placement", mode,
                  "beside: the placement runs beside the frames, which never wait for it; frame: "
                  "in every frame; auto: beside where the device has a second queue")
      ->check(CLI::IsMember({"auto", "beside", "frame"}))
      ->capture_default_str();
}

bool placement_beside(const std::string& mode, const Context& ctx) {
  return mode == "beside" || (mode == "auto" && ctx.separate_placement_queue());
}

graph::Extent parse_size(const std::string& text, const char* option) {
  unsigned w = 0, h = 0;
  char x = 0, extra = 0;
  const int n = std::sscanf(text.c_str(), "%u%c%u%c", &w, &x, &h, &extra);
  if (n == 1) h = w;
  if ((n != 1 && !(n == 3 && x == 'x')) || w == 0 || h == 0 || w > 16384 || h > 16384) {
    throw UsageError(std::string(option) + ": '" + text + "' is not a size (N or WxH, 1 to 16384)");
  }
  return {w, h};
}

Ghosting look_ghosting(const LabelLookOptions& o, const Scene& scene) {
  const float radius = o.ghost_radius.value_or(scene.settings.ghost_radius);
  // (a connector's lens a third of the anchor's wide)
  return {o.ghost.value_or(scene.settings.ghost), radius, o.ghost_leaders ? radius / 3.0f : 0.0f};
}

void add_tidy_rounds_option(CLI::App* cmd, uint32_t& rounds, const char* when) {
  cmd->add_option("--tidy-rounds", rounds, std::string("rounds of the tidy-up ") + when)
      ->check(whole_range(0, TIDY_ROUNDS_MAX))
      ->capture_default_str();
}

void add_hard_option(CLI::App* cmd, bool& hard) {
  cmd->add_flag("--hard", hard, "hard constraints: a label with no allowed position is hidden");
}

void add_label_look_options(CLI::App* cmd, LabelLookOptions& o) {
  cmd->add_option("--label-scale", o.label_scale, "label text and boxes times this (0.25 to 4)")
      ->check(finite_range(0.25, 4.0))
      ->capture_default_str();
  cmd->add_flag("--layer-colors", o.layer_colors,
                "label borders in their depth layer's colour (front to back: orange, blue, green, "
                "pink, ...)");
  cmd->add_option("--ghost", o.ghost,
                  "ghosting: the layers in front of a rear label's anchor made this much more "
                  "transparent around it (0: off, 1: fully open at the anchor; default: the "
                  "scene's settings.ghost, else 1)")
      ->check(finite_range(0.0, 1.0));
  cmd->add_option("--ghost-radius", o.ghost_radius,
                  "the ghosting lens's radius, a share of the picture's shorter side (default: the "
                  "scene's settings.ghost_radius, else 0.1)")
      ->check(finite_range(kGhostRadiusMin, kGhostRadiusMax));
  cmd->add_flag("--ghost-leaders", o.ghost_leaders,
                "ghosting opens the layers along each rear label's connector too");
}

}  // namespace strata::app

int main(int argc, char** argv) {
  using namespace strata::app;
  CLI::App app{"strata: label placement in volume-rendered medical scenes (Vulkan)"};
  app.require_subcommand(1);
  DeviceOptions device;
  app.add_option(
      "--device", device.device,
      "Vulkan device by index or part of its name (default: STRATA_DEVICE, else the best)");
  app.add_flag("--validate", device.validate,
               "Khronos validation with synchronization validation (always on in debug builds)");
  add_devices_command(app, device);
  add_render_command(app, device);
  add_view_command(app, device);
  add_bench_command(app, device);
  add_info_command(app);
  add_eval_command(app);
  add_video_command(app, device);
  add_pick_command(app, device);
  refuse_empty_values(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version end here too (exit code 0); anything else is a usage error: 2.
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
    std::fprintf(stderr, "strata: error: %s (see strata --help or strata COMMAND --help)\n",
                 e.what());
    return 2;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "strata: error: %s (see strata --help or strata COMMAND --help)\n",
                 e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "strata: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
