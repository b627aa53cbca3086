// The scene a command works on (commands.h's SceneInput): its options, its loading with the
// command line's cuts and choices, and the demo data found wherever the program runs from.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "app/commands.h"
#include "engine/core/files_read.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/io/volume_loader.h"
#include "engine/scene/transfer_function_presets.h"
#include "labeling/text_layout.h"
#include "passes/volume_renderer.h"

namespace strata::app {

namespace {

std::optional<SegmentationEntry> segmentation_entry(const SceneInput& in) {
  if (in.segmentation.empty()) {
    for (const auto& [given, option] : {std::pair{!in.names.empty(), "--names"},
                                        {!in.regions.empty(), "--regions"},
                                        {!in.make.empty(), "--make"}})
      if (given) throw UsageError(std::string(option) + " needs --segmentation");
    return std::nullopt;
  }
  SegmentationEntry entry;
  entry.file = in.segmentation;
  if (!in.names.empty()) entry.names = in.names;
  entry.regions = in.regions;
  if (!in.make.empty()) {
    const auto has = [&](const char* what) {
      return std::find(in.make.begin(), in.make.end(), what) != in.make.end();
    };
    entry.labels = has("labels");
    entry.masks = has("masks");
    entry.surfaces = has("surfaces");
  }
  return entry;
}

Scene load_scene_reporting(const SceneInput& in, const VolumeLimits& limits) {
  SceneOpenOptions options;
  options.limits = limits;
  options.preset = in.preset;
  options.labels = in.labels;
  options.segmentation = segmentation_entry(in);
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
  options.fit = in.fit;
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
  cmd->add_option("--segmentation", in.segmentation,
                  "a segmentation whose regions become labels: a label map with its names "
                  "(TotalSegmentator .nii.gz, or --names), a folder of masks, 3D Slicer .seg.nrrd, "
                  "DICOM SEG (docs/scene-format.md)");
  cmd->add_option("--names", in.names,
                  "with --segmentation: a names table (ITK-SNAP, 3D Slicer .ctbl/.csv, "
                  "FreeSurferColorLUT.txt, AAL, nnU-Net dataset.json, MONAI channel_def)");
  cmd->add_option("--regions", in.regions,
                  "with --segmentation: only these regions, by name (default: every region with "
                  "voxels)")
      ->delimiter(',')
      ->allow_extra_args(false);
  cmd->add_option("--make", in.make,
                  "with --segmentation: what its regions become: labels, masks, surfaces "
                  "(default: labels)")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->check(CLI::IsMember({"labels", "masks", "surfaces"}));
  cmd->add_option("--frame", in.frame,
                  "a 4-D volume's frame or a DICOM series' time point, from 0 (default: the first)")
      ->check(whole_range(0, 1e6));
  cmd->add_option("--window", in.window,
                  "CENTER,WIDTH: every volume shown as a grey ramp from CENTER - WIDTH/2 "
                  "(transparent) to CENTER + WIDTH/2 (opaque white) in its values, in place of its "
                  "transfer function (Hounsfield units for CT: 900,1200 bone alone, 40,400 the "
                  "skin)");
  cmd->add_option("--crop", in.crop,
                  "X0,Y0,Z0,X1,Y1,Z1: show only this box of every volume (world mm, LPS)");
  cmd->add_option("--clip", in.clip,
                  "PX,PY,PZ,NX,NY,NZ: cut every volume at the plane through P, keeping the side "
                  "N points to (world mm, LPS); up to six")
      ->allow_extra_args(false);  // one plane an --clip: the next word is not a second plane
  cmd->add_flag_callback(
      "--fit", [&in] { in.fit = true; },
      "fit the camera and the named views to what --crop and --clip keep (the default for a "
      "scene without a camera: a volume file or DICOM folder)");
  cmd->add_flag_callback(
      "--no-fit", [&in] { in.fit = false; },
      "keep the camera and the named views fitted to the whole content");
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

}  // namespace strata::app
