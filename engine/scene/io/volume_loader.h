// Volume files: NIfTI-1 and NIfTI-2 (.nii, .nii.gz), MetaImage (.mhd + raw, .mha), NRRD (.nrrd,
// .nhdr; raw and gzip), DICOM series (a folder of single-slice files) and DICOM files (.dcm: an
// enhanced multi-frame CT or MR, or one slice). 2-D images load one voxel thick; of a 4-D image
// one frame (a 3-D volume) is read. Every failure is one strata::Error that names the file, the
// field when there is one, and the reason.
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
    ".nii, .nii.gz, .mhd, .mha, .nrrd, .nhdr, .dcm and DICOM folders";

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
Volume load_dicom_series(const std::filesystem::path& folder, const VolumeReadOptions& options,
                         std::vector<std::string>& warnings);
Volume load_dicom_file(const std::filesystem::path& path, const VolumeReadOptions& options,
                       std::vector<std::string>& warnings);

// Writes .mha (header and data in one file) or .mhd (+ .raw beside it), optionally
// zlib-compressed; reading it back gives the same voxels, spacing, origin and direction.
void write_metaimage(const std::filesystem::path& path, const Volume& volume,
                     bool compress = false);

}  // namespace strata
