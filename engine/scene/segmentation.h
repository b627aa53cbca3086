// Segmentations as label sources: the files segmentation tools write (TotalSegmentator, 3D
// Slicer, DICOM SEG, a label map with a names table) read into one model, each region's anchor
// placed deepest inside it, and the regions made into labels, masks and surfaces.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/scene/io/volume_loader.h"
#include "engine/scene/scene.h"

namespace strata {

// The largest region value a layer holds (layers are uint16 label maps).
inline constexpr int kMaxRegionValue = 65535;

struct SegmentRegion {
  int number = 0;  // what the file calls it: label value, Segment Number, table key
  int layer = 0;   // the layer (Segmentation::layers) its voxels are in
  int value = 0;   // its voxels' value in that layer (often equal to number)
  std::string name;
  std::optional<glm::vec3> colour;  // RGB in 0..1 as the file gives it; none where it gives none
};

// Label maps on one grid: a region's voxels are those of its layer holding its value. Regions
// that overlap (DICOM SEG segments, Slicer segments in several layers, a folder of masks) are in
// different layers; most files need one.
struct Segmentation {
  std::filesystem::path source;
  std::string format;  // how it was read, for `strata info`: "DICOM SEG (BINARY)", ...
  std::vector<Volume> layers;
  std::vector<SegmentRegion> regions;  // in the file's order
};

// A names table: value -> name (and colour where the format has one).
struct NamedValue {
  int value = 0;
  std::string name;
  std::optional<glm::vec3> colour;  // RGB in 0..1
};
struct NamesTable {
  std::string format;  // "ITK-SNAP label descriptions", "3D Slicer colour table", ...
  std::vector<NamedValue> entries;
};

// ---- building a segmentation (the readers use these)

// An empty layer on `grid`'s geometry (dims, spacing, origin, direction; its voxels are not
// read): uint16 zeros.
Volume empty_layer(const Volume& grid);

// Adds a region whose voxels are the nonzero bytes of `inside` (one per voxel of the
// segmentation's grid, x fastest) to the first layer in which none of them is taken and
// `region.number` is free, else to a new layer; region.value becomes region.number. `grid` gives
// the geometry of the first layer when there is none yet. An Error if the number is outside
// 1..kMaxRegionValue or `inside` does not match the grid.
void add_region_voxels(Segmentation& segmentation, const Volume& grid,
                       const std::vector<uint8_t>& inside, SegmentRegion region);

// A label map (integer values; float volumes holding whole numbers) with a names table: every
// value the table names that has voxels is a region (values with voxels the table does not name
// are listed in `warnings`). The map itself is the one layer.
Segmentation segmentation_from_label_map(Volume label_map, const NamesTable& names,
                                         std::vector<std::string>& warnings);

// ---- the formats

// Reads any of the formats, detected by content and extension:
// - a folder of DICOM files or a .dcm whose SOP class is Segmentation Storage: DICOM SEG;
// - a folder of .nii/.nii.gz masks: TotalSegmentator's one file per structure;
// - .seg.nrrd (a NRRD with Segment0_ fields): 3D Slicer;
// - a NIfTI whose header extension holds a label table: TotalSegmentator's --ml output;
// - any other label map (NIfTI, NRRD, MetaImage, FreeSurfer .mgz/.mgh) with a names table.
// `names`, when given, is a names table (load_names_table) that replaces the file's own names
// (matched by number). An Error naming the file when nothing gives the regions names.
Segmentation load_segmentation(const std::filesystem::path& path,
                               const std::optional<std::filesystem::path>& names,
                               const VolumeReadOptions& options,
                               std::vector<std::string>& warnings);

// Whether load_segmentation reads the file without a names table: a folder of masks or holding a
// DICOM SEG, a DICOM SEG, a 3D Slicer segmentation, a NIfTI with a label table in its header.
bool is_segmentation(const std::filesystem::path& path);

// The names-table formats, detected by content: ITK-SNAP label descriptions, 3D Slicer colour
// tables (.ctbl/.txt and .csv), FreeSurfer's FreeSurferColorLUT.txt, AAL's "index name colour",
// nnU-Net dataset.json ("labels") and MONAI's "channel_def". Errors: "<file>: line N: <reason>".
NamesTable load_names_table(const std::filesystem::path& path);
NamesTable parse_names_table(std::string_view text, const std::filesystem::path& file);

// The label table a NIfTI-1 header extension holds (TotalSegmentator writes an XML table of
// <Label Key=".." Red=".." Green=".." Blue=".." Alpha="..">name</Label> with extension code 0;
// recognised by content, whatever the code). None when no extension holds one.
std::optional<NamesTable> nifti_label_table(const std::filesystem::path& nifti);
// The walk over a NIfTI-1 file's bytes from its start (for fuzzing: no file needed).
std::optional<NamesTable> nifti_label_table_from_bytes(std::string_view bytes,
                                                       const std::filesystem::path& file);

// 3D Slicer's .seg.nrrd: SegmentN_Name, _Color, _LabelValue, _Layer, _Extent; 3-D, or 4-D with
// the layers on the first (list) axis.
Segmentation load_slicer_segmentation(const std::filesystem::path& path,
                                      const VolumeReadOptions& options,
                                      std::vector<std::string>& warnings);

// A folder of binary masks, one <name>.nii.gz (or .nii) per structure on one grid
// (TotalSegmentator without --ml); the region is named after the file.
Segmentation load_mask_folder(const std::filesystem::path& folder, const VolumeReadOptions& options,
                              std::vector<std::string>& warnings);
// Whether load_mask_folder reads the file as a mask: a .nii or .nii.gz that is not hidden.
bool is_mask_file(const std::filesystem::path& file);

// A DICOM Segmentation object (a .dcm file, or a folder holding one): BINARY, FRACTIONAL
// (inside where the value is at least half the Maximum Fractional Value) and LABELMAP. GDCM
// reads the dataset in a child process (isolated_read.h).
Segmentation load_dicom_seg(const std::filesystem::path& path, const VolumeReadOptions& options,
                            std::vector<std::string>& warnings);
// Whether the file is a DICOM Segmentation object (SOP Class UID 1.2.840.10008.5.1.4.1.1.66.4,
// or the LABELMAP one ...66.7).
bool is_dicom_seg(const std::filesystem::path& path);

// ---- regions

struct RegionSummary {
  size_t voxels = 0;
  double millilitres = 0.0;
  glm::vec3 anchor{0.0f};  // world (LPS), deepest inside the region's largest connected part
  int parts = 0;           // its 6-connected parts
};

// For each region of the segmentation, in its order: voxel count, volume, and the anchor: the
// voxel of the region's largest 6-connected part farthest (Euclidean, in mm, spacing respected)
// from any voxel outside it, ties broken toward that part's centroid. Regions without voxels
// have voxels == 0.
std::vector<RegionSummary> summarise_regions(const Segmentation& segmentation);
// The same for the regions `which` (indices into segmentation.regions), in that order: only
// their anchors are computed.
std::vector<RegionSummary> summarise_regions(const Segmentation& segmentation,
                                             const std::vector<size_t>& which);

// Whether the region holds the voxel of its layer nearest to `world`.
bool region_contains(const Segmentation& segmentation, const SegmentRegion& region,
                     glm::vec3 world);

// Checks the segmentation against the scan it labels: an Error naming both files when their
// boxes do not overlap, or when an axis of one is not parallel (within 1 degree) to an axis of
// the other.
void check_segmentation_fits(const Segmentation& segmentation, const Volume& scan);

// A uint8 mask (255 inside) on the segmentation's grid, named after the region.
Volume region_mask(const Segmentation& segmentation, const SegmentRegion& region);
// The region's surface (world space), as atlas_surface makes it.
Mesh region_surface(const Segmentation& segmentation, const SegmentRegion& region);

// ---- in a scene

// Reads the segmentation and adds, for each chosen region with voxels, a label at its anchor
// (summarise_regions; text: the name with '_' as ' '), a mask volume and a surface mesh in its
// colour as the entry asks, and its layers as atlases (so a point can be named). Checked
// against the scene's first volume (check_segmentation_fits). A region without voxels is
// skipped with a warning naming it; a name in `regions` the file does not have, or more
// regions than the scene has room for (kMaxLabels), is an Error that says how to choose.
void add_segmentation(Scene& scene, const SegmentationEntry& entry,
                      const VolumeReadOptions& options);

}  // namespace strata
