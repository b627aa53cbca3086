// Volume files: NIfTI-1 and NIfTI-2 (.nii, .nii.gz), MetaImage (.mhd + raw, .mha), NRRD (.nrrd,
// .nhdr; raw and gzip), FreeSurfer MGH (.mgh, .mgz), DICOM series (a folder of single-slice
// files) and DICOM files (.dcm: an enhanced multi-frame CT or MR, or one slice). 2-D images load
// one voxel thick; of a 4-D image one frame (a 3-D volume) is read. Every failure is one
// strata::Error that names the file, the field when there is one, and the reason.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "engine/scene/io/isolated_read.h"
#include "engine/scene/scene.h"

namespace strata {

// What load_volume reads, for messages.
inline constexpr const char* kVolumeExtensions =
    ".nii, .nii.gz, .mhd, .mha, .nrrd, .nhdr, .mgz, .mgh, .dcm and DICOM folders";

// Whether load_volume takes `path` for a volume: a folder (a DICOM series), a volume extension,
// or a file that starts as DICOM does. Says nothing of whether it loads.
bool is_volume_path(const std::filesystem::path& path);

// What a volume may take, checked against its header before a voxel is read, so that a volume
// that cannot fit is refused at once with the limit named instead of after minutes of reading.
struct VolumeLimits {
  uint64_t memory_bytes = 0;  // host memory for the voxels; 0: the machine's physical memory
  // The device that will render it (set by the programs once it is open; 0 and "": none known).
  uint32_t max_side = 0;            // voxels per side
  uint64_t max_device_voxels = 0;   // voxels in one volume
  uint32_t device_voxel_bytes = 0;  // bytes a voxel takes there (named in the message)
  std::string device;
};

struct VolumeReadOptions {
  std::optional<int> frame;  // 4-D images: which frame (default 0)
  // A DICOM folder holding several series: the one with this SeriesNumber or SeriesInstanceUID
  // (default: the largest 3-D image series, with a warning naming the others).
  std::string series;
  VolumeLimits limits;
  ParserLimits parser;  // DICOM: GDCM's child process (isolated_read.h)
};

// Picks the reader by extension (a folder is a DICOM series; a file with a DICOM preamble is
// DICOM whatever its extension). The voxels are read straight into the returned volume: at most
// two copies of them exist at any time while loading. What the user should know but that does
// not stop the load (a 4-D image's frame, a 2-D image shown as a volume) is added to `warnings`
// as "<file>: <what>".
Volume load_volume(const std::filesystem::path& path, const VolumeReadOptions& options,
                   std::vector<std::string>& warnings);
// The same with default options; warnings go to stderr as "strata: warning: <warning>".
Volume load_volume(const std::filesystem::path& path);

Volume load_nifti(const std::filesystem::path& path, const VolumeReadOptions& options,
                  std::vector<std::string>& warnings);
Volume load_metaimage(const std::filesystem::path& path, const VolumeReadOptions& options,
                      std::vector<std::string>& warnings);
Volume load_nrrd(const std::filesystem::path& path, const VolumeReadOptions& options,
                 std::vector<std::string>& warnings);
// FreeSurfer's .mgh and .mgz (gzipped .mgh).
Volume load_mgh(const std::filesystem::path& path, const VolumeReadOptions& options,
                std::vector<std::string>& warnings);
Volume load_dicom_series(const std::filesystem::path& folder, const VolumeReadOptions& options,
                         std::vector<std::string>& warnings);
// One series of a DICOM folder, as its first slice describes it.
struct DicomSeries {
  std::string uid;          // SeriesInstanceUID ("" where the files give none)
  std::string number;       // SeriesNumber as written ("" where none)
  std::string description;  // SeriesDescription
  std::string modality;     // CT, MR, ...
  uint32_t columns = 0, rows = 0;
  uint32_t images = 0;       // slices (frames of a multi-frame file)
  uint32_t time_points = 1;  // distinct temporal positions among them
  std::string orientation;   // axial, sagittal, coronal, oblique (or unplaced: no position)
};
// Every series of a DICOM folder, in the order of their first files (GDCM in this process: run
// it through list_dicom_series_isolated).
std::vector<DicomSeries> list_dicom_series(const std::filesystem::path& folder);
// The same in a child process (isolated_read.h).
std::vector<DicomSeries> list_dicom_series_isolated(const std::filesystem::path& folder,
                                                    const ParserLimits& limits = {});

Volume load_dicom_file(const std::filesystem::path& path, const VolumeReadOptions& options,
                       std::vector<std::string>& warnings);

// Writes .mha (header and data in one file) or .mhd (+ .raw beside it), optionally
// zlib-compressed; reading it back gives the same voxels, spacing, origin and direction.
void write_metaimage(const std::filesystem::path& path, const Volume& volume,
                     bool compress = false);

}  // namespace strata
