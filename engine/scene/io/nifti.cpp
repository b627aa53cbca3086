// NIfTI-1 and NIfTI-2 (.nii, .nii.gz), either byte order; 2-D images as one slice, and of a 4-D
// image (fMRI, DCE) the one frame asked for: frames are stored one after the other, so the
// frames before it are skipped (inflated and dropped when gzipped) and only its voxels are kept.
//
// The header is parsed by hand rather than with Debian's nifticlib: the format is one fixed
// 348-byte (NIfTI-1) or 540-byte (NIfTI-2) struct, so the library would add little, and its
// nifti_image_read allocates and fills its own data buffer, where strata streams (and inflates)
// the voxels straight into Volume::voxels to keep at most two copies in memory.
//
// Orientation: NIfTI's sform/qform map voxels to RAS+ (x to the right, y anterior, z superior);
// strata's patient space is DICOM's LPS+ (as in ITK), so x and y are negated on the way in.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include "engine/scene/io/volume_io.h"
#include "engine/scene/io/volume_loader.h"

namespace strata {
namespace {

using namespace volume_io;
namespace fs = std::filesystem;

constexpr size_t nifti1_header_bytes = 348;
constexpr size_t nifti2_header_bytes = 540;

// The fields strata uses, from either version, as doubles and 64-bit integers.
struct NiftiHeader {
  int version = 1;
  bool big_endian = false;
  size_t header_bytes = nifti1_header_bytes;
  std::string magic;
  std::array<int64_t, 8> dim{};
  int datatype = 0;
  std::array<double, 8> pixdim{};
  double vox_offset = 0.0;
  Rescale rescale;
  int qform_code = 0, sform_code = 0;
  std::array<double, 3> quatern{}, qoffset{};
  std::array<std::array<double, 4>, 3> srow{};
};

// Reads little- or big-endian fields at byte offsets of the raw header.
struct Fields {
  const std::byte* bytes;
  bool swap;

  template <class T>
  T at(size_t offset) const {
    std::array<std::byte, sizeof(T)> raw;
    std::memcpy(raw.data(), bytes + offset, sizeof(T));
    if (swap) std::reverse(raw.begin(), raw.end());
    T value;
    std::memcpy(&value, raw.data(), sizeof(T));
    return value;
  }
  // n consecutive fields of type T from offset, as double.
  template <class T, size_t N>
  std::array<double, N> doubles(size_t offset) const {
    std::array<double, N> values{};
    for (size_t i = 0; i < N; ++i) values[i] = static_cast<double>(at<T>(offset + i * sizeof(T)));
    return values;
  }
  std::string text(size_t offset, size_t length) const {
    std::string s(reinterpret_cast<const char*>(bytes + offset), length);
    return s.substr(0, s.find('\0'));
  }
};

// Offsets from the NIfTI-1 header (nifti1.h).
void parse_nifti1(const Fields& f, NiftiHeader& h) {
  for (size_t i = 0; i < 8; ++i) h.dim[i] = f.at<int16_t>(40 + 2 * i);
  h.datatype = f.at<int16_t>(70);
  h.pixdim = f.doubles<float, 8>(76);
  h.vox_offset = f.at<float>(108);
  h.rescale = {f.at<float>(112), f.at<float>(116)};
  h.qform_code = f.at<int16_t>(252);
  h.sform_code = f.at<int16_t>(254);
  h.quatern = f.doubles<float, 3>(256);
  h.qoffset = f.doubles<float, 3>(268);
  for (size_t row = 0; row < 3; ++row) h.srow[row] = f.doubles<float, 4>(280 + 16 * row);
  h.magic = f.text(344, 4);
}

// Offsets from the NIfTI-2 header (nifti2.h): the same fields, wider and reordered.
void parse_nifti2(const Fields& f, NiftiHeader& h) {
  h.magic = f.text(4, 8);
  h.datatype = f.at<int16_t>(12);
  for (size_t i = 0; i < 8; ++i) h.dim[i] = f.at<int64_t>(16 + 8 * i);
  h.pixdim = f.doubles<double, 8>(104);
  h.vox_offset = static_cast<double>(f.at<int64_t>(168));
  h.rescale = {f.at<double>(176), f.at<double>(184)};
  h.qform_code = f.at<int32_t>(344);
  h.sform_code = f.at<int32_t>(348);
  h.quatern = f.doubles<double, 3>(352);
  h.qoffset = f.doubles<double, 3>(376);
  for (size_t row = 0; row < 3; ++row) h.srow[row] = f.doubles<double, 4>(400 + 32 * row);
}

int32_t sizeof_hdr(const std::byte* bytes, bool swap) {
  return Fields{bytes, swap}.at<int32_t>(0);
}

NiftiHeader read_header(InputFile& in, const fs::path& path) {
  std::array<std::byte, nifti2_header_bytes> raw{};
  size_t got = in.read(raw.data(), nifti1_header_bytes);
  if (got < 4) fail(path, concat("header is truncated: ", got, " of 348 bytes"));
  NiftiHeader h;
  // sizeof_hdr tells both the version and the byte order: 348 or 540 read one way or the other.
  bool swap = false;
  int32_t size = sizeof_hdr(raw.data(), false);
  if (size != 348 && size != 540 &&
      (sizeof_hdr(raw.data(), true) == 348 || sizeof_hdr(raw.data(), true) == 540)) {
    swap = true;
    size = sizeof_hdr(raw.data(), true);
  }
  if (size != 348 && size != 540)
    fail(path, concat("not a NIfTI file: sizeof_hdr is ", size, " (expected 348 or 540)"));
  h.version = size == 348 ? 1 : 2;
  h.header_bytes = static_cast<size_t>(size);
  h.big_endian = swap != (std::endian::native == std::endian::big);
  if (h.version == 2 && got == nifti1_header_bytes)
    got += in.read(raw.data() + got, nifti2_header_bytes - nifti1_header_bytes);
  if (got < h.header_bytes)
    fail(path, concat("header is truncated: ", got, " of ", h.header_bytes, " bytes"));
  const Fields fields{raw.data(), swap};
  if (h.version == 1) {
    parse_nifti1(fields, h);
  } else {
    parse_nifti2(fields, h);
  }
  return h;
}

void check_magic(const NiftiHeader& h, const fs::path& path) {
  const std::string expected = h.version == 1 ? "n+1" : "n+2";
  if (h.magic == expected) return;
  if (h.magic == (h.version == 1 ? "ni1" : "ni2"))
    fail(path, concat("magic '", h.magic,
                      "' marks a separate .hdr/.img pair, which strata does not read"));
  fail(path, concat("wrong magic '", printable(h.magic, 8), "' (expected '", expected, "')"));
}

StoredType stored_type(const NiftiHeader& h, const fs::path& path) {
  switch (h.datatype) {
    case 2:
      return StoredType::uint8;
    case 4:
      return StoredType::int16;
    case 512:
      return StoredType::uint16;
    case 16:
      return StoredType::float32;
    // Converted to float32 after reading:
    case 256:
      return StoredType::int8;
    case 8:
      return StoredType::int32;
    case 768:
      return StoredType::uint32;
    case 64:
      return StoredType::float64;
  }
  fail(path, concat("datatype ", h.datatype,
                    " is not supported (strata reads uint8, int16, uint16, float32, and int8, "
                    "int32, uint32, float64 as float32)"));
}

// A volume's three dimensions (a 2-D image is one slice) and the frame count (dim[4]).
struct Extent {
  std::array<int64_t, 3> dims{};
  int64_t frames = 1;
};

Extent image_extent(const NiftiHeader& h, const fs::path& path) {
  const int64_t rank = h.dim[0];
  if (rank < 2 || rank > 7)
    fail(path, concat("dim[0] = ", rank, ": expected 2, 3 or 4 (a 2-D, 3-D or 4-D image)"));
  for (int64_t axis = 5; axis <= rank; ++axis)
    if (h.dim[static_cast<size_t>(axis)] != 1)
      fail(path, concat("dim[", axis, "] = ", h.dim[static_cast<size_t>(axis)],
                        ": images of more than 4 dimensions are not supported (one component)"));
  const int64_t frames = rank >= 4 ? h.dim[4] : 1;
  if (frames < 1) fail(path, concat("dim[4] = ", frames, ": the frame count must be positive"));
  return {{h.dim[1], h.dim[2], rank >= 3 ? h.dim[3] : 1}, frames};
}

// Voxel index to RAS+ as a 3x4 matrix (rows x, y, z; the last column is the translation).
using Affine = std::array<std::array<double, 4>, 3>;

// One slice may leave pixdim[3] at 0: it is then 1 mm.
std::array<double, 3> pixdim_spacing(const NiftiHeader& h, const fs::path& path, bool one_slice) {
  std::array<double, 3> spacing{h.pixdim[1], h.pixdim[2], h.pixdim[3]};
  if (one_slice && !(spacing[2] > 0.0 && std::isfinite(spacing[2]))) spacing[2] = 1.0;
  check_spacing(path, "pixdim[1..3]", spacing, "pixdim", 1);
  return spacing;
}

// The quaternion method (NIfTI-1 "method 2"): rotation from (b, c, d), a = sqrt(1 - b²-c²-d²),
// qfac = pixdim[0] flips k.
Affine qform_affine(const NiftiHeader& h, const fs::path& path, bool one_slice) {
  const std::array<double, 3> spacing = pixdim_spacing(h, path, one_slice);
  double b = h.quatern[0], c = h.quatern[1], d = h.quatern[2];
  double a = 1.0 - (b * b + c * c + d * d);
  if (a < 1e-7) {  // a 180° rotation written with |(b,c,d)| ~ 1: renormalise, as the spec says
    const double norm = std::sqrt(b * b + c * c + d * d);
    if (!(norm > 0.0)) fail(path, "quatern_b/c/d: not a rotation");
    b /= norm, c /= norm, d /= norm;
    a = 0.0;
  } else {
    a = std::sqrt(a);
  }
  const double rotation[3][3] = {
      {a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)},
      {2 * (b * c + a * d), a * a + c * c - b * b - d * d, 2 * (c * d - a * b)},
      {2 * (b * d - a * c), 2 * (c * d + a * b), a * a + d * d - c * c - b * b}};
  const double qfac = h.pixdim[0] < 0.0 ? -1.0 : 1.0;
  const std::array<double, 3> scale{spacing[0], spacing[1], qfac * spacing[2]};
  Affine m{};
  for (size_t row = 0; row < 3; ++row) {
    for (size_t col = 0; col < 3; ++col) m[row][col] = rotation[row][col] * scale[col];
    m[row][3] = h.qoffset[row];
  }
  return m;
}

Affine orientation(const NiftiHeader& h, const fs::path& path, bool one_slice) {
  if (h.sform_code > 0) return h.srow;
  if (h.qform_code > 0) return qform_affine(h, path, one_slice);
  // Neither: ANALYZE-style, scale by pixdim only.
  const std::array<double, 3> spacing = pixdim_spacing(h, path, one_slice);
  Affine m{};
  for (size_t axis = 0; axis < 3; ++axis) m[axis][axis] = spacing[axis];
  return m;
}

// Splits the affine into spacing (column lengths), direction and origin, converting RAS to LPS.
// A 2-D image's sform may leave k's column zero: k is then the slice normal, 1 mm.
void set_geometry(Volume& volume, const NiftiHeader& h, const fs::path& path) {
  const bool one_slice = volume.dims.z == 1;
  const Affine m = orientation(h, path, one_slice);
  const double to_lps[3] = {-1.0, -1.0, 1.0};
  for (int col = 0; col < 3; ++col) {
    glm::dvec3 axis(0.0);
    for (int row = 0; row < 3; ++row) axis[row] = to_lps[row] * m[size_t(row)][size_t(col)];
    if (col == 2 && one_slice && glm::length(axis) == 0.0)
      axis = glm::normalize(
          glm::cross(glm::dvec3(volume.direction[0]), glm::dvec3(volume.direction[1])));
    const double length = glm::length(axis);
    if (!std::isfinite(length) || length <= 0.0)
      fail(path, concat(h.sform_code > 0 ? "srow_x/y/z" : "qform", " column ", col,
                        length > 0.0 ? ": the column's length is not a finite number"
                                     : ": spacing must be positive (the column has zero length)"));
    volume.spacing[col] = static_cast<float>(length);
    volume.direction[col] = glm::vec3(axis / length);
  }
  for (int row = 0; row < 3; ++row)
    volume.origin[row] = static_cast<float>(to_lps[row] * m[size_t(row)][3]);
  if (h.sform_code > 0)
    check_geometry(path, "srow_x/y/z[3]", "srow_x/y/z", volume);
  else
    check_geometry(path, "qoffset_x/y/z", "quatern_b/c/d", volume);
}

}  // namespace

Volume load_nifti(const std::filesystem::path& path, const VolumeReadOptions& options,
                  std::vector<std::string>& warnings) {
  existing_file_size(path);
  InputFile in(
      {.file = path, .report_as = path, .what = "voxel data", .compressed = is_gzip_file(path)});
  const NiftiHeader h = read_header(in, path);
  check_magic(h, path);
  const StoredType stored = stored_type(h, path);
  const Extent extent = image_extent(h, path);
  const size_t bytes =
      checked_voxel_bytes(path, "dim[1..3]", extent.dims, stored_size(stored), options.limits);
  const uint64_t frame = choose_frame(path, uint64_t(extent.frames), options, warnings);

  Volume volume;
  volume.name = volume_name(path);
  volume.source = path;
  volume.dims = to_dims(extent.dims);
  set_geometry(volume, h, path);

  // The upper bound only keeps the conversion defined; skip() finds offsets past the end.
  if (!(h.vox_offset >= double(h.header_bytes) && h.vox_offset < 0x1p62) ||
      !in.skip(static_cast<uint64_t>(h.vox_offset) - h.header_bytes))
    fail(path, concat("vox_offset = ", h.vox_offset,
                      ": not between the header's end and the "
                      "file's end"));
  skip_frames(in, frame, bytes);
  read_voxels(in, bytes, volume);
  finish_voxels(volume, {.stored = stored,
                         .big_endian = h.big_endian,
                         .per_slice = {h.rescale},
                         .rescale_field = "scl_slope, scl_inter"});
  return volume;
}

}  // namespace strata
