// Volume files: NIfTI-1 and NIfTI-2 (.nii, .nii.gz), MetaImage (.mhd + raw, .mha), NRRD (.nrrd,
// .nhdr; raw and gzip) and DICOM series (a folder). Every failure is one strata::Error that
// names the file, the field when there is one, and the reason.
#pragma once

#include <filesystem>

#include "engine/scene/scene.h"

namespace strata {

// Picks the reader by extension (a folder is a DICOM series). The voxels are read straight into
// the returned volume: at most two copies of them exist at any time while loading.
Volume load_volume(const std::filesystem::path& path);

Volume load_nifti(const std::filesystem::path& path);
Volume load_metaimage(const std::filesystem::path& path);
Volume load_nrrd(const std::filesystem::path& path);
Volume load_dicom_series(const std::filesystem::path& folder);

// Writes .mha (header and data in one file) or .mhd (+ .raw beside it), optionally
// zlib-compressed; reading it back gives the same voxels, spacing, origin and direction.
void write_metaimage(const std::filesystem::path& path, const Volume& volume,
                     bool compress = false);

}  // namespace strata
