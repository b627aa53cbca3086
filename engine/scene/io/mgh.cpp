// FreeSurfer's MGH volumes (.mgh, and .mgz: the same gzipped). A big-endian header: int32
// version (1), width, height, depth, nframes, type, dof; int16 goodRASflag; when it is set,
// float32 xsize, ysize, zsize, the direction of each voxel axis in RAS (x_r x_a x_s, y_r y_a y_s,
// z_r z_a z_s) and c_ras, the RAS position of the centre voxel (width/2, height/2, depth/2). The
// voxels start at byte 284, frames one after the other; what follows them (scan parameters,
// tags) is not read.
//
// Geometry: index to RAS = Mdc * diag(size) * (index - dims/2) + c_ras, as FreeSurfer and nibabel
// compute it. A direction that is not of unit length scales its axis's spacing (as a NIfTI
// sform's column does), so positions match theirs. Without goodRASflag FreeSurfer takes 1 mm
// voxels in its coronal (LIA) orientation centred at 0. RAS becomes strata's LPS by negating x
// and y.
#include <array>
#include <cmath>
#include <cstring>

#include "engine/scene/io/volume_io.h"
#include "engine/scene/io/volume_loader.h"

namespace strata {
namespace {

using namespace volume_io;
namespace fs = std::filesystem;

constexpr size_t kHeaderBytes = 284;  // where the voxels start
constexpr size_t kFieldBytes = 90;    // the fields read, up to c_ras

struct MghHeader {
  std::array<int32_t, 7> ints{};  // version, width, height, depth, nframes, type, dof
  int16_t good_ras = 0;
  std::array<float, 3> size{};
  std::array<std::array<float, 3>, 3> direction{};  // one per voxel axis, in RAS
  std::array<float, 3> c_ras{};
};

template <class T>
T big_endian_at(const std::byte* bytes, size_t offset) {
  std::array<std::byte, sizeof(T)> raw;
  std::memcpy(raw.data(), bytes + offset, sizeof(T));
  if constexpr (std::endian::native == std::endian::little) std::reverse(raw.begin(), raw.end());
  T value;
  std::memcpy(&value, raw.data(), sizeof(T));
  return value;
}

MghHeader read_header(InputFile& in, const fs::path& path) {
  std::array<std::byte, kHeaderBytes> raw{};
  const size_t got = in.read(raw.data(), raw.size());
  if (got < kHeaderBytes)
    fail(path, concat("header is truncated: ", got, " of ", kHeaderBytes, " bytes"));
  MghHeader h;
  for (size_t i = 0; i < 7; ++i) h.ints[i] = big_endian_at<int32_t>(raw.data(), 4 * i);
  h.good_ras = big_endian_at<int16_t>(raw.data(), 28);
  for (size_t i = 0; i < 3; ++i) h.size[i] = big_endian_at<float>(raw.data(), 30 + 4 * i);
  for (size_t axis = 0; axis < 3; ++axis)
    for (size_t i = 0; i < 3; ++i)
      h.direction[axis][i] = big_endian_at<float>(raw.data(), 42 + 12 * axis + 4 * i);
  for (size_t i = 0; i < 3; ++i) h.c_ras[i] = big_endian_at<float>(raw.data(), 78 + 4 * i);
  static_assert(78 + 12 == kFieldBytes);
  if (h.good_ras <= 0) {  // FreeSurfer's defaults: 1 mm, LIA, centred at 0
    h.size = {1.0f, 1.0f, 1.0f};
    h.direction = {{{-1.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -1.0f}, {0.0f, 1.0f, 0.0f}}};
    h.c_ras = {0.0f, 0.0f, 0.0f};
  }
  return h;
}

StoredType stored_type(int32_t type, const fs::path& path) {
  switch (type) {
    case 0:
      return StoredType::uint8;
    case 1:
      return StoredType::int32;  // converted to float32
    case 3:
      return StoredType::float32;
    case 4:
      return StoredType::int16;
  }
  fail(path,
       concat("type = ", type,
              ": not supported (strata reads 0 uchar, 4 short, 3 float, and 1 int as float)"));
}

// Spacing from the axis sizes times their directions' lengths, the directions made unit, and
// the origin (voxel 0) placed from the centre voxel, all in LPS.
void set_geometry(Volume& volume, const MghHeader& h, const fs::path& path) {
  check_spacing(path, "xsize, ysize, zsize",
                {double(h.size[0]), double(h.size[1]), double(h.size[2])});
  const glm::dvec3 to_lps(-1.0, -1.0, 1.0);
  glm::dvec3 centre(h.c_ras[0], h.c_ras[1], h.c_ras[2]);
  for (int axis = 0; axis < 3; ++axis) {
    const auto& d = h.direction[size_t(axis)];
    const glm::dvec3 step = glm::dvec3(d[0], d[1], d[2]) * double(h.size[size_t(axis)]);
    const double length = glm::length(step);
    if (!std::isfinite(length) || !(length > 0.0))
      fail(path, concat("Mdc: the direction of axis ", axis, " (", d[0], " ", d[1], " ", d[2],
                        ") has no length"));
    volume.spacing[axis] = float(length);
    volume.direction[axis] = glm::vec3(to_lps * step / length);
    centre -= step * (double(volume.dims[axis]) / 2.0);
  }
  volume.origin = glm::vec3(to_lps * centre);
  check_geometry(path, "c_ras", "Mdc", volume);
}

}  // namespace

Volume load_mgh(const std::filesystem::path& path, const VolumeReadOptions& options,
                std::vector<std::string>& warnings) {
  existing_file_size(path);
  InputFile in(
      {.file = path, .report_as = path, .what = "voxel data", .compressed = is_gzip_file(path)});
  const MghHeader h = read_header(in, path);
  if (h.ints[0] != 1)
    fail(path, concat("version = ", h.ints[0], ": expected 1 (not a FreeSurfer MGH file?)"));
  const StoredType stored = stored_type(h.ints[5], path);
  const std::array<int64_t, 3> dims{h.ints[1], h.ints[2], h.ints[3]};
  const size_t bytes =
      checked_voxel_bytes(path, "width, height, depth", dims, stored_size(stored), options.limits);
  if (h.ints[4] < 1)
    fail(path, concat("nframes = ", h.ints[4], ": the frame count must be positive"));
  const uint64_t frame = choose_frame(path, uint64_t(h.ints[4]), options, warnings);

  Volume volume;
  volume.name = volume_name(path);
  volume.source = path;
  volume.dims = to_dims(dims);
  set_geometry(volume, h, path);
  skip_frames(in, frame, bytes);
  read_voxels(in, bytes, volume);
  finish_voxels(volume, {.stored = stored, .big_endian = true, .per_slice = {Rescale{}}});
  return volume;
}

}  // namespace strata
