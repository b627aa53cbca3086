// `strata info FILE`: what a scene, volume, mesh, transfer-function or label file holds, as plain
// text.
// Needs no device, so it also checks scene files on machines without Vulkan.
#include <algorithm>
#include <cctype>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include "app/commands.h"
#include "engine/core/font.h"
#include "engine/scene/io/label_file_loader.h"
#include "engine/scene/io/mesh_loader.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/io/transfer_function_loader.h"
#include "engine/scene/io/volume_loader.h"
#include "engine/scene/scene_bounds.h"
#include "engine/scene/segmentation.h"

namespace strata::app {

namespace {

namespace fs = std::filesystem;

std::string format(const char* pattern, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* pattern, ...) {
  va_list args;
  va_start(args, pattern);
  va_list again;
  va_copy(again, args);
  const int length = std::vsnprintf(nullptr, 0, pattern, args);
  va_end(args);
  std::string text(size_t(std::max(length, 0)) + 1, '\0');  // (a long label text is kept whole)
  std::vsnprintf(text.data(), text.size(), pattern, again);
  va_end(again);
  text.pop_back();
  return text;
}

// Adding 0 turns the -0 that inverted view matrices give into 0.
std::string vec(glm::vec3 v) {
  return format("(%.6g, %.6g, %.6g)", v.x + 0.0f, v.y + 0.0f, v.z + 0.0f);
}
std::string rgba(glm::vec4 c) {
  return format("(%.3g, %.3g, %.3g, %.3g)", c.r, c.g, c.b, c.a);
}

std::string bytes(size_t count) {
  return format("%zu bytes (%.1f MiB)", count, double(count) / (1024.0 * 1024.0));
}

void describe_volumes(const Scene& scene, std::string& out) {
  out += format("volumes: %zu\n", scene.volumes.size());
  for (const Volume& v : scene.volumes) {
    const auto [lo, hi] = v.world_bounds();
    out += format("  %s: %ux%ux%u %s\n", printable_text(v.name).c_str(), v.dims.x, v.dims.y,
                  v.dims.z, to_string(v.type));
    if (!v.source.empty()) out += "    file: " + v.source.string() + "\n";
    out += format("    spacing: %g x %g x %g mm\n", v.spacing.x, v.spacing.y, v.spacing.z);
    out += "    world bounds: " + vec(lo) + " .. " + vec(hi) + "\n";
    out += "    voxels: " + bytes(v.byte_size()) + "\n";
    out += format("    values: %g .. %g\n", v.value_range.x, v.value_range.y);
    if (v.transfer_function >= 0 && size_t(v.transfer_function) < scene.transfer_functions.size()) {
      out +=
          "    transfer function: " + scene.transfer_functions[size_t(v.transfer_function)].name +
          "\n";
    } else {
      out += "    transfer function: none\n";
    }
  }
}

void describe_transfer_functions(const Scene& scene, std::string& out) {
  out += format("transfer functions: %zu\n", scene.transfer_functions.size());
  for (const TransferFunction& tf : scene.transfer_functions) {
    out += format("  %s: %zu stops", printable_text(tf.name).c_str(), tf.stops.size());
    out += tf.source.empty() ? "\n" : " (" + tf.source.string() + ")\n";
    for (const TransferFunction::Stop& stop : tf.stops) {
      out += format("    %-9.6g rgba ", stop.position) + rgba(stop.color) + "\n";
    }
  }
}

void describe_meshes(const Scene& scene, std::string& out) {
  out += format("meshes: %zu\n", scene.meshes.size());
  for (const Mesh& m : scene.meshes) {
    out += format("  %s: %zu triangles, %zu vertices, colour ", printable_text(m.name).c_str(),
                  m.triangle_count(), m.positions.size());
    out += rgba(m.color) + (m.transform != glm::mat4(1.0f) ? ", transformed" : "") + "\n";
    if (!m.source.empty()) out += "    file: " + m.source.string() + "\n";
  }
}

void describe_labels(const Scene& scene, std::string& out) {
  out += format("labels: %zu\n", scene.labels.size());
  for (const Label& l : scene.labels) {
    const std::string size = l.size == glm::vec2(0.0f) ? std::string("from the text")
                                                       : format("%gx%g", l.size.x, l.size.y);
    std::string image;
    if (l.image) {
      image = format("  image %s (%ux%u, %g px high, %s)", l.image->file.filename().c_str(),
                     l.image->pixels.width, l.image->pixels.height, l.image->height,
                     l.image->side == LabelImage::Side::left ? "left" : "above");
    }
    // (control characters written \u0007, so that a text can neither drive the terminal nor end
    // at a U+0000)
    out += format("  %4d  %-24s anchor ", l.id, ("\"" + printable_text(l.text) + "\"").c_str()) +
           vec(l.anchor) + "  size " + size + image + "\n";
  }
}

void describe_camera_and_settings(const Scene& scene, std::string& out) {
  const Camera& c = scene.camera;
  const glm::vec3 eye = c.eye();
  out += format("camera: fov_y %g degrees, near %g, far %g, eye ", c.fov_y_degrees, c.near_plane,
                c.far_plane) +
         vec(eye) + "\n";
  out += format("  positions: %zu\n", scene.camera_positions.size());
  for (const CameraPose& p : scene.camera_positions) {
    out +=
        "    " + printable_text(p.name) + ": eye " + vec(glm::vec3(glm::inverse(p.view)[3])) + "\n";
  }
  const CostWeights& w = scene.settings.weights;
  out += format("settings: %d layers\n", scene.settings.layer_count);
  out += format(
      "  weights: label_shadow %g, anchor_constraint %g, connector_shadow %g, integral_costs %g,\n"
      "           distance_to_anchor %g, connector_direction %g, previous_position %g,\n"
      "           leader_crossing %g, illegible %g\n",
      w.label_shadow, w.anchor_constraint, w.connector_shadow, w.integral_costs,
      w.distance_to_anchor, w.connector_direction, w.previous_position, w.leader_crossing,
      w.illegible);
}

// A single volume, mesh or transfer-function file shows only its own section; a scene shows all.
std::string describe(const Scene& scene, bool whole_scene) {
  std::string out;
  if (whole_scene || !scene.volumes.empty()) describe_volumes(scene, out);
  if (whole_scene || !scene.transfer_functions.empty()) describe_transfer_functions(scene, out);
  if (whole_scene || !scene.meshes.empty()) describe_meshes(scene, out);
  if (!whole_scene) return out;
  describe_labels(scene, out);
  describe_camera_and_settings(scene, out);
  out += format("warnings: %zu\n", scene.warnings.size());
  for (const std::string& w : scene.warnings) out += "  " + printable_text(w) + "\n";
  return out;
}

bool is_label_file(const fs::path& path) {
  std::string name = path.filename().string();
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return name.ends_with(".mrk.json") || name.ends_with(".fcsv") || name.ends_with(".csv");
}

// A label file: how many points, the coordinate system they were written in, their bounds (LPS,
// strata's world, and RAS) and, given a scene, which anchors lie outside all of its volumes.
std::string describe_label_file(const LabelFile& file, const Scene* scene) {
  std::string systems;
  for (const std::string& s : file.coordinate_systems) systems += (systems.empty() ? "" : ", ") + s;
  std::string out = format("labels: %zu, written in %s\n", file.labels.size(), systems.c_str());
  if (const auto problem =
          label_limit_problem(file.labels.size(), scene ? scene->labels.size() : 0))
    out += "  too many for a scene: " + *problem + "\n";
  Bounds bounds;
  for (const Label& l : file.labels) bounds.add(l.anchor);
  const glm::vec3 ras_lo(-bounds.hi.x, -bounds.hi.y, bounds.lo.z);
  const glm::vec3 ras_hi(-bounds.lo.x, -bounds.lo.y, bounds.hi.z);
  out += "  bounds: LPS " + vec(bounds.lo) + " .. " + vec(bounds.hi) + " mm, RAS " + vec(ras_lo) +
         " .. " + vec(ras_hi) + " mm\n";
  std::vector<const Label*> outside;
  if (scene) {
    std::vector<glm::vec3> anchors;
    for (const Label& l : file.labels) anchors.push_back(l.anchor);
    std::vector<bool> inside(anchors.size(), false);
    for (const Volume& v : scene->volumes) {
      const std::vector<bool> in = inside_volume(v, anchors);
      for (size_t a = 0; a < anchors.size(); ++a) inside[a] = inside[a] || in[a];
    }
    for (size_t a = 0; a < anchors.size(); ++a)
      if (!inside[a]) outside.push_back(&file.labels[a]);
  }
  if (!scene) {
    out += "  inside a scene's volumes: not checked (--scene SCENE)\n";
  } else {
    out += format("  inside the volumes of %s: %zu of %zu\n", scene->source.string().c_str(),
                  file.labels.size() - outside.size(), file.labels.size());
    for (const Label* l : outside) {
      out += format("    outside: %4d  \"%s\" at LPS ", l->id, printable_text(l->text).c_str()) +
             vec(l->anchor) + "\n";
    }
  }
  for (const Label& l : file.labels) {
    out += format("  %4d  %-24s LPS ", l.id, ("\"" + printable_text(l.text) + "\"").c_str()) +
           vec(l.anchor) + "\n";
  }
  return out;
}

bool is_scene_file(const fs::path& path) {
  return !is_volume_path(path) && !is_transfer_function_file(path) &&
         (path.extension() == ".json" || path.extension() == ".xml");
}

// A scene holding the one volume, transfer function or mesh file, for describe().
Scene load_single_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(path.string() + ": no such file");
  Scene scene;
  scene.source = path;
  if (is_volume_path(path)) {
    scene.volumes.push_back(load_volume(path, {}, scene.warnings));
  } else if (is_transfer_function_file(path)) {
    scene.transfer_functions.push_back(load_transfer_function(path));
  } else {
    scene.meshes = load_meshes(path);
  }
  return scene;
}

// A segmentation's regions: value, name, colour, voxels, volume and anchor (LPS and RAS).
std::string describe_segmentation(const fs::path& path, const std::optional<fs::path>& names) {
  std::vector<std::string> warnings;
  const Segmentation seg = load_segmentation(path, names, {}, warnings);
  for (const std::string& w : warnings) std::fprintf(stderr, "strata: warning: %s\n", w.c_str());
  const std::vector<RegionSummary> summaries = summarise_regions(seg);
  std::string out = format("segmentation: %s\n", seg.format.c_str());
  if (!seg.layers.empty()) {
    const Volume& g = seg.layers.front();
    out += format("  grid: %ux%ux%u, spacing %g x %g x %g mm, %zu layer%s\n", g.dims.x, g.dims.y,
                  g.dims.z, g.spacing.x, g.spacing.y, g.spacing.z, seg.layers.size(),
                  seg.layers.size() == 1 ? "" : "s");
  }
  out += format("regions: %zu\n", seg.regions.size());
  out += format("  %5s  %-28s %-17s %9s %10s  %-26s %s\n", "value", "name", "colour", "voxels",
                "ml", "anchor LPS (mm)", "anchor RAS (mm)");
  for (size_t r = 0; r < seg.regions.size(); ++r) {
    const SegmentRegion& region = seg.regions[r];
    const RegionSummary& sum = summaries[r];
    const std::string colour = region.colour ? format("(%.2f, %.2f, %.2f)", region.colour->r,
                                                      region.colour->g, region.colour->b)
                                             : "-";
    const glm::vec3 lps = sum.anchor, ras(-lps.x, -lps.y, lps.z);
    out += format("  %5d  %-28s %-17s %9zu %10.3f  ", region.number,
                  printable_text(region.name).c_str(), colour.c_str(), sum.voxels, sum.millilitres);
    out += sum.voxels == 0 ? "(no voxels)\n"
                           : format("%-26s %s", vec(lps).c_str(), vec(ras).c_str()) +
                                 (sum.parts > 1 ? format("  (%d parts)", sum.parts) : "") + "\n";
  }
  return out;
}

}  // namespace

void add_info_command(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand(
      "info",
      "Describe a scene (.json, thesis .xml), volume, mesh, transfer-function or label file");
  auto file = std::make_shared<std::string>();
  cmd->add_option("FILE", *file, "the file to describe")->required();
  auto scene_file = std::make_shared<std::string>();
  cmd->add_option("--scene", *scene_file,
                  "for a label file (.mrk.json, .fcsv, .csv): check its anchors against this "
                  "scene's volumes");
  auto names = std::make_shared<std::string>();
  cmd->add_option("--names", *names,
                  "for a label map: list its regions with this names table (a segmentation with "
                  "names of its own lists them without)");
  cmd->callback([file, scene_file, names] {
    const fs::path path(*file);
    if (!names->empty() || is_segmentation(path)) {
      if (!scene_file->empty()) throw UsageError("--scene goes with a label file only");
      std::optional<fs::path> table;
      if (!names->empty()) table = *names;
      std::printf("%s\n%s", file->c_str(), describe_segmentation(path, table).c_str());
      return;
    }
    if (is_label_file(path)) {
      const LabelFile labels = read_label_file(path);
      std::optional<Scene> scene;
      if (!scene_file->empty()) scene = load_scene(*scene_file);
      std::printf("%s\n%s", file->c_str(),
                  describe_label_file(labels, scene ? &*scene : nullptr).c_str());
      return;
    }
    if (!scene_file->empty()) throw UsageError("--scene goes with a label file only");
    std::error_code error;
    if (fs::is_directory(path, error)) {
      // A DICOM folder: every series in it, then the volume a load opens by default.
      const std::vector<DicomSeries> all = list_dicom_series_isolated(path);
      std::string listed = format("series: %zu\n", all.size());
      for (const DicomSeries& s : all) {
        listed += format("  %s  %s  %s %ux%ux%u, %s", s.number.empty() ? "-" : s.number.c_str(),
                         s.uid.empty() ? "(no SeriesInstanceUID)" : s.uid.c_str(),
                         s.modality.empty() ? "?" : s.modality.c_str(), s.columns, s.rows, s.images,
                         s.orientation.c_str());
        if (s.time_points > 1) listed += format(", %u time points", s.time_points);
        listed += s.description.empty() ? "\n" : "  \"" + printable_text(s.description) + "\"\n";
      }
      const Scene scene = load_single_file(path);
      std::printf("%s\n%s%s", file->c_str(), listed.c_str(), describe(scene, false).c_str());
      for (const std::string& w : scene.warnings)
        std::fprintf(stderr, "strata: warning: %s\n", w.c_str());
      return;
    }
    const bool whole_scene = is_scene_file(path);
    const Scene scene = whole_scene ? load_scene(path) : load_single_file(path);
    std::printf("%s\n%s", file->c_str(), describe(scene, whole_scene).c_str());
  });
}

}  // namespace strata::app
