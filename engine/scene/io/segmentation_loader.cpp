// Segmentations read whatever their format (load_segmentation) and made into a scene's labels,
// masks and surfaces (add_segmentation).
#include <algorithm>
#include <cmath>

#include "engine/core/error.h"
#include "engine/scene/atlas.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/io/volume_io.h"
#include "engine/scene/segmentation.h"

namespace strata {
namespace {

bool is_nifti_name(const std::filesystem::path& path) {
  const std::string name = volume_io::lowercase(path.filename().string());
  return name.ends_with(".nii") || name.ends_with(".nii.gz");
}

// A folder of NIfTI masks (TotalSegmentator) rather than a DICOM folder.
bool holds_masks(const std::filesystem::path& folder) {
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error))
    if (is_mask_file(entry.path())) return true;
  return false;
}

// A NRRD whose header has 3D Slicer's segment fields.
bool is_slicer_segmentation(const std::filesystem::path& path) {
  const std::string name = volume_io::lowercase(path.filename().string());
  if (name.ends_with(".seg.nrrd")) return true;
  if (!name.ends_with(".nrrd") && !name.ends_with(".nhdr")) return false;
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return false;  // (a FIFO would block)
  const std::string header = volume_io::read_prefix(path, 64 * 1024);
  return header.substr(0, header.find("\n\n")).find("Segment0_") != std::string::npos;
}

// The file's own names replaced (matched by number) by the table's.
void rename_regions(Segmentation& segmentation, const NamesTable& names,
                    const std::filesystem::path& table) {
  for (SegmentRegion& region : segmentation.regions) {
    const auto it = std::find_if(names.entries.begin(), names.entries.end(),
                                 [&](const NamedValue& e) { return e.value == region.number; });
    if (it == names.entries.end())
      throw Error(table.string() + ": names no region " + std::to_string(region.number) + " ('" +
                  region.name + "' in " + segmentation.source.string() + ")");
    region.name = it->name;
    if (it->colour) region.colour = it->colour;
  }
}

std::string spaced(std::string name) {
  std::replace(name.begin(), name.end(), '_', ' ');
  return name;
}

// The regions the entry asks for, in its order (else the file's).
std::vector<size_t> chosen_regions(const Segmentation& segmentation,
                                   const SegmentationEntry& entry) {
  std::vector<size_t> chosen;
  if (entry.regions.empty()) {
    for (size_t r = 0; r < segmentation.regions.size(); ++r) chosen.push_back(r);
    return chosen;
  }
  for (const std::string& wanted : entry.regions) {
    const auto it = std::find_if(
        segmentation.regions.begin(), segmentation.regions.end(),
        [&](const SegmentRegion& r) { return r.name == wanted || spaced(r.name) == wanted; });
    if (it == segmentation.regions.end()) {
      std::string some;
      for (size_t r = 0; r < segmentation.regions.size() && r < 6; ++r)
        some += (r ? ", " : "") + segmentation.regions[r].name;
      throw Error(entry.file.string() + ": no region '" + wanted + "' (it has " +
                  std::to_string(segmentation.regions.size()) + ": " + some +
                  (segmentation.regions.size() > 6 ? ", ...; `strata info` lists them)" : ")"));
    }
    chosen.push_back(size_t(it - segmentation.regions.begin()));
  }
  return chosen;
}

// A colour for a region its file gives none: hues a golden angle apart, by its number.
glm::vec3 default_colour(int number) {
  const float hue = std::fmod(float(number) * 0.618034f, 1.0f) * 6.0f;
  const float x = 1.0f - std::fabs(std::fmod(hue, 2.0f) - 1.0f);
  const glm::vec3 rgb = hue < 1   ? glm::vec3(1, x, 0)
                        : hue < 2 ? glm::vec3(x, 1, 0)
                        : hue < 3 ? glm::vec3(0, 1, x)
                        : hue < 4 ? glm::vec3(0, x, 1)
                        : hue < 5 ? glm::vec3(x, 0, 1)
                                  : glm::vec3(1, 0, x);
  return 0.35f + 0.6f * rgb;
}

void add_region(Scene& scene, const Segmentation& segmentation, const SegmentRegion& region,
                const RegionSummary& summary, const SegmentationEntry& entry, int id) {
  const glm::vec3 colour = region.colour.value_or(default_colour(region.number));
  if (entry.labels) {
    Label label;
    label.id = id;
    label.text = spaced(region.name);
    label.anchor = summary.anchor;
    label.colour = colour;
    scene.labels.push_back(std::move(label));
  }
  if (entry.masks) {
    scene.transfer_functions.push_back(
        mask_transfer_function(region.name, glm::vec4(colour, 0.5f)));
    scene.volumes.push_back(region_mask(segmentation, region));
    scene.volumes.back().transfer_function = int(scene.transfer_functions.size()) - 1;
    scene.volumes.back().source.clear();  // (made, not read: see Scene::segmentations)
  }
  if (entry.surfaces) {
    scene.meshes.push_back(region_surface(segmentation, region));
    scene.meshes.back().color = glm::vec4(colour, 0.5f);
    scene.meshes.back().source.clear();
  }
}

// A folder holding a DICOM SEG file.
bool holds_dicom_seg(const std::filesystem::path& folder) {
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error))
    if (entry.is_regular_file(error) && is_dicom_seg(entry.path())) return true;
  return false;
}

}  // namespace

bool is_segmentation(const std::filesystem::path& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) return holds_masks(path) || holds_dicom_seg(path);
  if (!std::filesystem::is_regular_file(path, error)) return false;
  if (is_slicer_segmentation(path) || is_dicom_seg(path)) return true;
  try {
    return is_nifti_name(path) && nifti_label_table(path).has_value();
  } catch (const Error&) {
    return false;  // (reading it as a volume reports the problem)
  }
}

Segmentation load_segmentation(const std::filesystem::path& path,
                               const std::optional<std::filesystem::path>& names,
                               const VolumeReadOptions& options,
                               std::vector<std::string>& warnings) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) throw Error(path.string() + ": no such file");
  Segmentation segmentation;
  if (std::filesystem::is_directory(path, error)) {
    segmentation = holds_masks(path) ? load_mask_folder(path, options, warnings)
                                     : load_dicom_seg(path, options, warnings);
  } else if (is_dicom_seg(path)) {
    segmentation = load_dicom_seg(path, options, warnings);
  } else if (is_slicer_segmentation(path)) {
    segmentation = load_slicer_segmentation(path, options, warnings);
  } else {
    if (!is_volume_path(path))
      throw Error(path.string() + ": not a segmentation (expected a label map: " +
                  kVolumeExtensions + ", .mgz; a .seg.nrrd, a DICOM SEG or a folder of masks)");
    std::optional<NamesTable> table;
    if (names) {
      table = load_names_table(*names);
    } else if (is_nifti_name(path)) {
      table = nifti_label_table(path);
    }
    if (!table)
      throw Error(path.string() +
                  ": the label map names no regions (no label table in its header): give a "
                  "names table (--names, or \"names\" in the scene)");
    segmentation =
        segmentation_from_label_map(load_volume(path, options, warnings), *table, warnings);
    segmentation.format = "label map, names from " + table->format;
    return segmentation;
  }
  if (names) {
    rename_regions(segmentation, load_names_table(*names), *names);
    segmentation.format += ", names from " + names->string();
  }
  return segmentation;
}

void add_segmentation(Scene& scene, const SegmentationEntry& entry,
                      const VolumeReadOptions& options) {
  Segmentation segmentation = load_segmentation(entry.file, entry.names, options, scene.warnings);
  if (!scene.volumes.empty()) check_segmentation_fits(segmentation, scene.volumes.front());
  const std::vector<size_t> chosen = chosen_regions(segmentation, entry);
  const std::vector<RegionSummary> summaries = summarise_regions(segmentation, chosen);
  std::vector<size_t> kept;  // indices into chosen
  for (size_t i = 0; i < chosen.size(); ++i) {
    if (summaries[i].voxels > 0) {
      kept.push_back(i);
      continue;
    }
    const SegmentRegion& region = segmentation.regions[chosen[i]];
    scene.warnings.push_back(entry.file.string() + ": region '" + region.name + "' (" +
                             std::to_string(region.number) + ") has no voxels: skipped");
  }
  const size_t room = size_t(kMaxLabels) - std::min(scene.labels.size(), size_t(kMaxLabels));
  if (entry.labels && kept.size() > room)
    throw Error(entry.file.string() + ": " + std::to_string(kept.size()) +
                " regions with voxels, but a scene holds at most " + std::to_string(kMaxLabels) +
                " labels" +
                (room < size_t(kMaxLabels) ? " (" + std::to_string(room) + " left)" : "") +
                ": choose regions with --regions NAME,... or the entry's \"regions\"");
  if (entry.masks && scene.volumes.size() + kept.size() > kMaxVolumes)
    throw Error(entry.file.string() + ": " + std::to_string(kept.size()) + " masks and " +
                std::to_string(scene.volumes.size()) +
                " volume(s) already: strata renders at most " + std::to_string(kMaxVolumes) +
                " volumes: choose regions with --regions NAME,... or the entry's \"regions\", or "
                "make surfaces");
  const std::vector<int> ids = unused_label_ids(scene.labels, entry.labels ? kept.size() : 0);
  for (size_t i = 0; i < kept.size(); ++i)
    add_region(scene, segmentation, segmentation.regions[chosen[kept[i]]], summaries[kept[i]],
               entry, entry.labels ? ids[i] : 0);
  scene.segmentations.push_back(entry);
  for (size_t l = 0; l < segmentation.layers.size(); ++l) {
    SceneAtlas atlas{std::move(segmentation.layers[l]), {}};
    for (const SegmentRegion& region : segmentation.regions)
      if (region.layer == int(l)) atlas.names[region.value] = region.name;
    scene.atlases.push_back(std::move(atlas));
  }
}

}  // namespace strata
