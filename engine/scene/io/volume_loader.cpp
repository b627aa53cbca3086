// load_volume's dispatch by extension, and the helpers every volume reader shares (volume_io.h):
// size checks, reading straight into the voxel buffer with on-the-fly inflate, byte order, type
// conversion, rescale and value range.
#include "engine/scene/io/volume_loader.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <system_error>

#include <unistd.h>

#include <zlib.h>

#include "engine/core/text_file.h"
#include "engine/scene/io/dicom_structure.h"
#include "engine/scene/io/volume_io.h"
#include "engine/scene/value_limits.h"

namespace strata {
namespace {

enum class Format { none, dicom_folder, nifti, metaimage, nrrd, mgh, dicom_file };

Format format_of(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (fs::is_directory(path, error)) return Format::dicom_folder;
  const std::string name = volume_io::lowercase(path.filename().string());
  const auto ends_with = [&](std::string_view suffix) { return name.ends_with(suffix); };
  if (ends_with(".nii") || ends_with(".nii.gz")) return Format::nifti;
  if (ends_with(".mhd") || ends_with(".mha")) return Format::metaimage;
  if (ends_with(".nrrd") || ends_with(".nhdr")) return Format::nrrd;
  if (ends_with(".mgz") || ends_with(".mgh")) return Format::mgh;
  // Scanners and PACS exports often write DICOM files without an extension.
  if (ends_with(".dcm") || ends_with(".dicom")) return Format::dicom_file;
  if (fs::is_regular_file(path, error) && dicom::file_kind(path) == dicom::Kind::part10)
    return Format::dicom_file;
  return Format::none;
}

// Voxels that are not numbers (NaN, infinity) have no place on a transfer function's value axis.
// Float images use NaN for "no data" (a masked statistics map, a resampled image's outside), so
// they are kept as the lowest value, which presets show as transparent, with a warning that
// counts them; a volume of nothing else is an error. A value range wider than a float holds
// (-3e38 to 3e38) would normalise every voxel to 0: an error too.
void check_voxel_values(const std::filesystem::path& path, Volume& volume,
                        std::vector<std::string>& warnings) {
  using volume_io::concat;
  if (volume.type == VoxelType::float32) {
    const size_t count = volume.voxel_count();
    size_t not_finite = 0;
    for (size_t i = 0; i < count; ++i) {
      float v;
      std::memcpy(&v, volume.voxels.data() + i * sizeof(float), sizeof v);
      if (!std::isfinite(v)) ++not_finite;
    }
    if (not_finite == count)
      volume_io::fail(
          path, concat("voxels: none of the ", count, " is a finite number (all NaN or infinite)"));
    if (not_finite > 0) {
      const float lowest = volume.value_range.x;
      for (size_t i = 0; i < count; ++i) {
        std::byte* p = volume.voxels.data() + i * sizeof(float);
        float v;
        std::memcpy(&v, p, sizeof v);
        if (!std::isfinite(v)) std::memcpy(p, &lowest, sizeof lowest);
      }
      warnings.push_back(concat(path.string(), ": ", not_finite, " of ", count,
                                " voxels are NaN or infinite; shown as the lowest value, ", lowest,
                                " (no data)"));
    }
  }
  const double lo = volume.value_range.x, hi = volume.value_range.y;
  if (!(hi - lo <= double(std::numeric_limits<float>::max())))
    volume_io::fail(path, concat("voxels: values from ", lo, " to ", hi,
                                 ": the range is wider than a 32-bit float holds (", hi - lo,
                                 "), so no transfer function can span it"));
}

constexpr std::string_view kDicomReader = "the DICOM reader (GDCM)";

}  // namespace

std::vector<DicomSeries> list_dicom_series_isolated(const std::filesystem::path& folder,
                                                    const ParserLimits& limits) {
  // (each series as its nine fields, in the order of DicomSeries)
  constexpr size_t kFields = 9;
  const std::vector<std::string> texts = read_texts_isolated(folder, kDicomReader, limits, [&] {
    std::vector<std::string> out;
    for (const DicomSeries& s : list_dicom_series(folder)) {
      for (const std::string& field :
           {s.uid, s.number, s.description, s.modality, std::to_string(s.columns),
            std::to_string(s.rows), std::to_string(s.images), std::to_string(s.time_points),
            s.orientation})
        out.push_back(field);
    }
    return out;
  });
  std::vector<DicomSeries> series;
  for (size_t i = 0; i + kFields <= texts.size(); i += kFields) {
    const auto number = [&](size_t k) { return uint32_t(std::stoul(texts[i + k])); };
    series.push_back({texts[i], texts[i + 1], texts[i + 2], texts[i + 3], number(4), number(5),
                      number(6), number(7), texts[i + 8]});
  }
  return series;
}

namespace {

Volume read_by_extension(const std::filesystem::path& path, const VolumeReadOptions& options,
                         std::vector<std::string>& warnings) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) volume_io::fail(path, "no such file");
  switch (format_of(path)) {
    // GDCM reads in a child process: its assertions abort (a PALETTE COLOR image without a
    // palette), and an abort there must be an Error here. The whole series is one child.
    case Format::dicom_folder:
      return read_volume_isolated(
          path, kDicomReader, options.parser, warnings,
          [&](auto& child_warnings) { return load_dicom_series(path, options, child_warnings); });
    case Format::nifti:
      return load_nifti(path, options, warnings);
    case Format::metaimage:
      return load_metaimage(path, options, warnings);
    case Format::nrrd:
      return load_nrrd(path, options, warnings);
    case Format::mgh:
      return load_mgh(path, options, warnings);
    case Format::dicom_file:
      return read_volume_isolated(
          path, kDicomReader, options.parser, warnings,
          [&](auto& child_warnings) { return load_dicom_file(path, options, child_warnings); });
    case Format::none:
      break;
  }
  volume_io::fail(path, "unknown volume extension '" + path.extension().string() +
                            "' (strata reads " + kVolumeExtensions + ")");
}

}  // namespace

bool is_volume_path(const std::filesystem::path& path) {
  return format_of(path) != Format::none;
}

Volume load_volume(const std::filesystem::path& path, const VolumeReadOptions& options,
                   std::vector<std::string>& warnings) {
  if (!options.series.empty() && format_of(path) != Format::dicom_folder)
    volume_io::fail(path, "a series (" + options.series +
                              ") is chosen in a DICOM folder only; this is not one");
  Volume volume = read_by_extension(path, options, warnings);
  // Every format, DICOM too: its reader names the fields it read, this names what they gave.
  volume_io::check_plausible_geometry(path, "origin", "spacing", volume);
  check_voxel_values(path, volume, warnings);
  if (volume.dims.z == 1)
    warnings.push_back(volume_io::concat(path.string(), ": 2-D image (one slice of ", volume.dims.x,
                                         "x", volume.dims.y, "); shown as a volume one voxel (",
                                         volume.spacing.z, " mm) thick"));
  return volume;
}

Volume load_volume(const std::filesystem::path& path) {
  std::vector<std::string> warnings;
  Volume volume = load_volume(path, {}, warnings);
  for (const std::string& warning : warnings)
    std::fprintf(stderr, "strata: warning: %s\n", warning.c_str());
  return volume;
}

}  // namespace strata

namespace strata::volume_io {

void fail(const std::filesystem::path& file, const std::string& what) {
  throw Error(file.string() + ": " + what);
}

// ---- element types and sizes

size_t stored_size(StoredType type) {
  switch (type) {
    case StoredType::uint8:
    case StoredType::int8:
      return 1;
    case StoredType::int16:
    case StoredType::uint16:
      return 2;
    case StoredType::int32:
    case StoredType::uint32:
    case StoredType::float32:
      return 4;
    case StoredType::float64:
      return 8;
  }
  return 1;
}

const char* to_string(StoredType type) {
  constexpr const char* names[] = {"uint8", "int8",   "int16",   "uint16",
                                   "int32", "uint32", "float32", "float64"};
  return names[static_cast<int>(type)];
}

uint64_t physical_memory_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page_size > 0 ? uint64_t(pages) * uint64_t(page_size) : 0;
}

namespace {

std::string gibibytes(uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f GiB", double(bytes) / double(uint64_t{1} << 30));
  return text;
}

void check_limits(const std::filesystem::path& file, const std::string& shown,
                  const std::array<int64_t, 3>& dims, uint64_t bytes, const VolumeLimits& limits) {
  // Loading holds the voxels and, while converting them, at most one more copy of their size.
  const uint64_t memory = limits.memory_bytes ? limits.memory_bytes : physical_memory_bytes();
  if (memory > 0 && bytes > memory / 2)
    fail(file, concat(shown, ": the voxels need ", gibibytes(bytes),
                      " twice while loading; this machine has ", gibibytes(memory), " of memory"));
  if (limits.max_side > 0) {
    for (int64_t d : dims)
      if (uint64_t(d) > limits.max_side)
        fail(file, concat(shown, ": the device (", limits.device, ") renders at most ",
                          limits.max_side, " voxels per side"));
  }
  const uint64_t voxels = uint64_t(dims[0]) * uint64_t(dims[1]) * uint64_t(dims[2]);
  if (limits.max_device_voxels > 0 && voxels > limits.max_device_voxels)
    fail(file, concat(shown, ": ", voxels, " voxels; the device (", limits.device,
                      ") holds at most ", limits.max_device_voxels, " (", limits.device_voxel_bytes,
                      " bytes a voxel in the renderer's volume atlas, in its largest allocation)"));
}

}  // namespace

size_t checked_voxel_bytes(const std::filesystem::path& file, std::string_view field,
                           const std::array<int64_t, 3>& dims, size_t element_size,
                           const VolumeLimits& limits) {
  const std::string shown = concat(field, " = ", dims[0], "x", dims[1], "x", dims[2]);
  for (int64_t d : dims)
    if (d < 1) fail(file, shown + ": dimensions must be positive");
  uint64_t bytes = element_size;
  bool overflow = false;
  for (int64_t d : dims)
    overflow |= __builtin_mul_overflow(bytes, static_cast<uint64_t>(d), &bytes);
  if (overflow || bytes > std::numeric_limits<size_t>::max())
    fail(file, shown + ": voxel count overflows");
  for (int64_t d : dims)
    if (d > int64_t{std::numeric_limits<uint32_t>::max()})
      fail(file, shown + ": a dimension exceeds 4294967295");
  if (bytes > max_voxel_bytes)
    fail(file, concat(shown, ": ", bytes, " bytes of voxels, more than the 16 GiB strata accepts"));
  check_limits(file, shown, dims, bytes, limits);
  return static_cast<size_t>(bytes);
}

void check_spacing(const std::filesystem::path& file, std::string_view field,
                   const std::array<double, 3>& spacing, std::string_view axis_field,
                   int first_axis) {
  for (double s : spacing)
    if (!std::isfinite(s) || s <= 0.0)
      fail(file, concat(field, " = ", spacing[0], " ", spacing[1], " ", spacing[2],
                        ": spacing must be positive"));
  for (int axis = 0; axis < 3; ++axis)
    if (const auto problem = value_limits::spacing_problem(spacing[size_t(axis)]))
      fail(file, concat(axis_field.empty() ? field : axis_field, "[", first_axis + axis,
                        "]: ", *problem));
}

void check_plausible_geometry(const std::filesystem::path& file, std::string_view origin_field,
                              std::string_view direction_field, const Volume& volume) {
  using namespace value_limits;
  for (int axis = 0; axis < 3; ++axis)
    if (const auto problem = spacing_problem(volume.spacing[axis]))
      fail(file, concat(direction_field, ": axis ", axis, ": ", *problem));
  if (const auto problem = position_problem("origin", glm::dvec3(volume.origin)))
    fail(file, concat(origin_field, ": ", *problem));
  // The far corner, and whether voxels there are still apart in float.
  const glm::dvec3 origin(volume.origin);
  glm::dvec3 far_corner = origin;
  double largest = glm::length(origin);
  for (int corner = 1; corner < 8; ++corner) {
    glm::dvec3 p = origin;
    for (int axis = 0; axis < 3; ++axis)
      if (corner & (1 << axis))
        p += glm::dvec3(volume.direction[axis]) * double(volume.spacing[axis]) *
             double(volume.dims[axis] - 1);
    if (glm::length(p) > largest) largest = glm::length(p), far_corner = p;
  }
  if (const auto problem =
          position_problem("the volume's far corner", far_corner, kMaxSceneCoordinateMm))
    fail(file, concat(direction_field, ": ", *problem));
  const double float_step = largest * double(std::numeric_limits<float>::epsilon());
  const float finest = std::min({volume.spacing.x, volume.spacing.y, volume.spacing.z});
  if (double(finest) < kMinFloatStepsPerVoxel * float_step)
    fail(file, concat(origin_field, ": ", origin.x, " ", origin.y, " ", origin.z, " mm: ", finest,
                      " mm voxels ", largest,
                      " mm from the origin are too fine for the float "
                      "positions the renderer uses (",
                      float_step, " mm steps there)"));
}

void check_geometry(const std::filesystem::path& file, std::string_view origin_field,
                    std::string_view direction_field, Volume& volume) {
  // Spacing taken from a matrix's column lengths (NIfTI sform, NRRD directions) is checked here;
  // a length finite as a double can still overflow the float the volume keeps.
  const glm::vec3 sp = volume.spacing;
  if (!(std::isfinite(sp.x) && std::isfinite(sp.y) && std::isfinite(sp.z) && sp.x > 0.0f &&
        sp.y > 0.0f && sp.z > 0.0f))
    fail(file, concat(direction_field, ": spacing ", sp.x, " ", sp.y, " ", sp.z,
                      " must be positive and finite"));
  const glm::vec3 o = volume.origin;
  if (!std::isfinite(o.x) || !std::isfinite(o.y) || !std::isfinite(o.z))
    fail(file, concat(origin_field, " = ", o.x, " ", o.y, " ", o.z,
                      ": the origin must be finite numbers"));
  for (int axis = 0; axis < 3; ++axis) {
    const glm::vec3 d = volume.direction[axis];
    const float length = glm::length(d);
    if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z) || !(length > 0.9f) ||
        !(length < 1.1f))
      fail(file, concat(direction_field, ": the direction of axis ", axis, " (", d.x, " ", d.y, " ",
                        d.z, ") is not a unit vector"));
    volume.direction[axis] = d / length;
  }
  if (!(std::fabs(glm::determinant(volume.direction)) > 1e-3f))
    fail(file, concat(direction_field,
                      ": the axes' directions lie in one plane (a singular matrix): the voxels "
                      "have no place in space"));
  check_plausible_geometry(file, origin_field, direction_field, volume);
}

// ---- reading

// zlib's state plus its input buffer; kept out of the header's way.
struct InputFile::Inflater {
  z_stream stream{};
  std::vector<unsigned char> input = std::vector<unsigned char>(1 << 16);
  bool gzip = false;      // gzip streams may be concatenated members; zlib streams end once
  bool finished = false;  // the stream's end was reached
  ~Inflater() { inflateEnd(&stream); }
};

InputFile::InputFile(Source source) : source_(std::move(source)) {
  const uint64_t size = source_.file == source_.report_as
                            ? check_input_file(source_.file)
                            : data_file_size(source_.report_as, source_.what, source_.file);
  in_.open(source_.file, std::ios::binary);
  if (!in_) fail(source_.report_as, concat(source_.what, ": cannot open ", source_.file));
  file_bytes_left_ = source_.offset < size ? size - source_.offset : 0;
  in_.seekg(static_cast<std::streamoff>(std::min(source_.offset, size)));
  if (!source_.compressed) return;
  if (source_.compressed_size)
    file_bytes_left_ = std::min(file_bytes_left_, *source_.compressed_size);
  compressed_total_ = file_bytes_left_;
  inflater_ = std::make_unique<Inflater>();
  // 15 + 32: the largest window, and accept either a zlib or a gzip header.
  if (inflateInit2(&inflater_->stream, 15 + 32) != Z_OK)
    fail(source_.report_as, concat(source_.what, ": cannot start zlib"));
}

InputFile::~InputFile() = default;

bool InputFile::refill() {
  if (file_bytes_left_ == 0) return false;
  Inflater& z = *inflater_;
  const uint64_t want = std::min<uint64_t>(z.input.size(), file_bytes_left_);
  in_.read(reinterpret_cast<char*>(z.input.data()), static_cast<std::streamsize>(want));
  const auto got = static_cast<uint64_t>(in_.gcount());
  file_bytes_left_ = got == want ? file_bytes_left_ - got : 0;
  if (produced_ == 0 && z.stream.total_in == 0 && got > 0) z.gzip = z.input[0] == 0x1f;
  z.stream.next_in = z.input.data();
  z.stream.avail_in = static_cast<uInt>(got);
  return got > 0;
}

size_t InputFile::read_compressed(std::byte* destination, size_t n) {
  Inflater& z = *inflater_;
  size_t done = 0;
  while (done < n && !z.finished) {
    if (z.stream.avail_in == 0 && !refill()) break;  // the compressed data ends early
    const size_t chunk = std::min<size_t>(n - done, size_t{1} << 30);
    z.stream.next_out = reinterpret_cast<Bytef*>(destination + done);
    z.stream.avail_out = static_cast<uInt>(chunk);
    const int result = inflate(&z.stream, Z_NO_FLUSH);
    done += chunk - z.stream.avail_out;
    if (result == Z_STREAM_END) {
      // A gzip file may hold several members one after another (what `cat a.gz b.gz` makes).
      if (z.stream.avail_in == 0) refill();
      const bool next_member = z.gzip && z.stream.avail_in > 0 && z.stream.next_in[0] == 0x1f;
      if (next_member) {
        inflateReset(&z.stream);
      } else {
        z.finished = true;
      }
    } else if (result != Z_OK && !(result == Z_BUF_ERROR && z.stream.avail_in == 0)) {
      fail(source_.report_as, concat(source_.what, ": compressed data is corrupt (zlib: ",
                                     z.stream.msg ? z.stream.msg : "error", ")"));
    }
  }
  produced_ += done;
  return done;
}

size_t InputFile::read(std::byte* destination, size_t n) {
  if (source_.compressed) return read_compressed(destination, n);
  const uint64_t want = std::min<uint64_t>(n, file_bytes_left_);
  in_.read(reinterpret_cast<char*>(destination), static_cast<std::streamsize>(want));
  const auto got = static_cast<uint64_t>(in_.gcount());
  file_bytes_left_ = got == want ? file_bytes_left_ - got : 0;
  produced_ += got;
  return static_cast<size_t>(got);
}

bool InputFile::skip(uint64_t n) {
  if (!source_.compressed) {
    if (n > file_bytes_left_) return false;
    in_.seekg(static_cast<std::streamoff>(n), std::ios::cur);
    file_bytes_left_ -= n;
    return true;
  }
  std::vector<std::byte> scratch(std::min<uint64_t>(n, 1 << 16));
  while (n > 0) {
    const size_t chunk = static_cast<size_t>(std::min<uint64_t>(n, scratch.size()));
    if (read(scratch.data(), chunk) != chunk) return false;
    n -= chunk;
  }
  return true;
}

uint64_t InputFile::max_remaining() const {
  if (!source_.compressed) return file_bytes_left_;
  // Deflate cannot expand data by more than 1032:1; the slack covers stream headers.
  const uint64_t bound = compressed_total_ * 1032 + (uint64_t{1} << 20);
  return bound > produced_ ? bound - produced_ : 0;
}

bool is_gzip_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  unsigned char magic[2] = {0, 0};
  in.read(reinterpret_cast<char*>(magic), 2);
  return in.gcount() == 2 && magic[0] == 0x1f && magic[1] == 0x8b;
}

void read_voxels(InputFile& in, size_t bytes, Volume& volume) {
  const InputFile::Source& source = in.source();
  const uint64_t available = in.max_remaining();
  if (bytes > available) {
    if (!in.compressed())
      fail(source.report_as,
           concat(source.what, " has ", available, " bytes, the header needs ", bytes));
    fail(source.report_as, concat(source.what, " is too short: its compressed bytes inflate to at ",
                                  "most ", available, " bytes, the header needs ", bytes));
  }
  volume.voxels.resize(bytes);
  const size_t got = in.read(volume.voxels.data(), bytes);
  if (got < bytes)
    fail(source.report_as,
         concat(source.what, " ends after ", got, " of the ", bytes, " bytes the header needs"));
}

std::string read_prefix(const std::filesystem::path& file, size_t max_bytes) {
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(file, "cannot open");
  // Headers are a few hundred bytes: allocating (and zeroing) the whole limit for each one made
  // a header read cost a millisecond.
  std::error_code error;
  const uint64_t size = std::filesystem::file_size(file, error);
  std::string text(error ? max_bytes : static_cast<size_t>(std::min<uint64_t>(size, max_bytes)),
                   '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<size_t>(in.gcount()));
  return text;
}

uint64_t data_file_size(const std::filesystem::path& header, std::string_view what,
                        const std::filesystem::path& file) {
  std::error_code error;
  if (!std::filesystem::exists(file, error))
    fail(header, concat(what, ": no such file (", file.string(), ")"));
  try {
    return check_input_file(file);
  } catch (const Error& e) {
    fail(header, concat(what, ": ", e.what()));
  }
}

uint64_t existing_file_size(const std::filesystem::path& file) {
  return check_input_file(file);
}

uint64_t choose_frame(const std::filesystem::path& file, uint64_t frames,
                      const VolumeReadOptions& options, std::vector<std::string>& warnings) {
  const int64_t frame = options.frame.value_or(0);
  if (frame < 0 || uint64_t(frame) >= frames)
    fail(file, frames == 1 ? concat("frame ", frame, " is out of range: the image has one frame, 0")
                           : concat("frame ", frame, " is out of range: the image has ", frames,
                                    " frames, 0 to ", frames - 1));
  if (frames > 1)
    warnings.push_back(concat(file.string(), ": 4-D image with ", frames, " frames; showing frame ",
                              frame, " (choose with --frame)"));
  return uint64_t(frame);
}

void skip_frames(InputFile& in, uint64_t frame, size_t frame_bytes) {
  if (frame == 0) return;
  uint64_t bytes = 0;
  if (__builtin_mul_overflow(frame, uint64_t{frame_bytes}, &bytes) || !in.skip(bytes) ||
      in.max_remaining() == 0) {
    const InputFile::Source& source = in.source();
    fail(source.report_as,
         concat(source.what, " ends before frame ", frame, " (", frame_bytes, " bytes a frame)"));
  }
}

// ---- voxel conversion

void swap_bytes(std::span<std::byte> data, size_t element_size) {
  if (element_size < 2) return;
  for (size_t i = 0; i + element_size <= data.size(); i += element_size)
    std::reverse(data.begin() + static_cast<std::ptrdiff_t>(i),
                 data.begin() + static_cast<std::ptrdiff_t>(i + element_size));
}

bool Rescale::applies() const {
  return std::isfinite(slope) && std::isfinite(intercept) && slope != 0.0 &&
         !(slope == 1.0 && intercept == 0.0);
}

namespace {

template <class T>
T load(const std::byte* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

// Calls fn with a value of the C++ type a StoredType names (the value itself is unused).
template <class Fn>
void with_type(StoredType type, Fn&& fn) {
  switch (type) {
    case StoredType::uint8:
      return fn(uint8_t{});
    case StoredType::int8:
      return fn(int8_t{});
    case StoredType::int16:
      return fn(int16_t{});
    case StoredType::uint16:
      return fn(uint16_t{});
    case StoredType::int32:
      return fn(int32_t{});
    case StoredType::uint32:
      return fn(uint32_t{});
    case StoredType::float32:
      return fn(float{});
    case StoredType::float64:
      return fn(double{});
  }
}

StoredType stored_type_of(VoxelType type) {
  switch (type) {
    case VoxelType::uint8:
      return StoredType::uint8;
    case VoxelType::int16:
      return StoredType::int16;
    case VoxelType::uint16:
      return StoredType::uint16;
    case VoxelType::float32:
      return StoredType::float32;
  }
  return StoredType::uint8;
}

std::optional<VoxelType> held_as_is(StoredType type) {
  switch (type) {
    case StoredType::uint8:
      return VoxelType::uint8;
    case StoredType::int16:
      return VoxelType::int16;
    case StoredType::uint16:
      return VoxelType::uint16;
    case StoredType::float32:
      return VoxelType::float32;
    default:
      return std::nullopt;
  }
}

// Rewrites every element as Dst = op(Src, index). In place when Dst is not larger than Src
// (element i is read before it is written, and its write ends where element i + 1 starts);
// otherwise through the one extra buffer the loaders are allowed.
template <class Src, class Dst, class Op>
void convert_elements(Volume& volume, VoxelType to, Op op) {
  const size_t count = volume.voxels.size() / sizeof(Src);
  constexpr bool in_place = sizeof(Dst) <= sizeof(Src);
  std::vector<std::byte> grown(in_place ? 0 : count * sizeof(Dst));
  std::byte* out = in_place ? volume.voxels.data() : grown.data();
  const std::byte* in = volume.voxels.data();
  for (size_t i = 0; i < count; ++i) {
    const Dst value = op(load<Src>(in + i * sizeof(Src)), i);
    std::memcpy(out + i * sizeof(Dst), &value, sizeof(Dst));
  }
  if (in_place) {
    volume.voxels.resize(count * sizeof(Dst));
  } else {
    volume.voxels = std::move(grown);
  }
  volume.type = to;
}

bool is_integer(double v) {
  return std::nearbyint(v) == v && std::fabs(v) < 1e9;
}

// DICOM CT keeps int16 when the rescale maps the stored range onto integers that fit int16.
bool rescale_fits_int16(const Volume& volume, const std::vector<Rescale>& per_slice) {
  if (volume.type == VoxelType::float32) return false;
  const glm::vec2 range = compute_value_range(volume);
  for (const Rescale& r : per_slice) {
    if (!is_integer(r.slope) || !is_integer(r.intercept)) return false;
    for (float v : {range.x, range.y}) {
      const double result = r.slope * v + r.intercept;
      if (result < -32768.0 || result > 32767.0) return false;
    }
  }
  return true;
}

void apply_rescale(Volume& volume, const std::vector<Rescale>& per_slice, bool int16_when_exact) {
  if (std::none_of(per_slice.begin(), per_slice.end(), [](auto& r) { return r.applies(); })) return;
  const size_t slice_voxels = size_t{volume.dims.x} * volume.dims.y;
  const auto rescale_of = [&](size_t index) {
    const Rescale& r = per_slice.size() == 1 ? per_slice[0] : per_slice[index / slice_voxels];
    return r.applies() ? r : Rescale{};
  };
  const bool to_int16 = int16_when_exact && rescale_fits_int16(volume, per_slice);
  with_type(stored_type_of(volume.type), [&](auto source) {
    using Src = decltype(source);
    if (to_int16) {
      convert_elements<Src, int16_t>(volume, VoxelType::int16, [&](Src v, size_t i) {
        const Rescale r = rescale_of(i);
        return static_cast<int16_t>(std::lround(r.slope * v + r.intercept));
      });
    } else {
      convert_elements<Src, float>(volume, VoxelType::float32, [&](Src v, size_t i) {
        const Rescale r = rescale_of(i);
        return static_cast<float>(r.slope * v + r.intercept);
      });
    }
  });
}

}  // namespace

namespace {

// A rescale that takes the stored values out of float's range would leave infinities in every
// voxel it touches.
void check_rescale(const Volume& volume, const Conversion& conversion) {
  const auto applies = [](const Rescale& r) { return r.applies(); };
  if (std::none_of(conversion.per_slice.begin(), conversion.per_slice.end(), applies)) return;
  const glm::vec2 stored = compute_value_range(volume);
  for (const Rescale& r : conversion.per_slice) {
    if (!r.applies()) continue;
    for (const double v : {double(stored.x), double(stored.y)}) {
      const double result = r.slope * v + r.intercept;
      if (!(std::fabs(result) <= double(std::numeric_limits<float>::max())))
        fail(volume.source, concat(conversion.rescale_field, " = ", r.slope, ", ", r.intercept,
                                   ": the stored value ", v, " becomes ", result,
                                   ", outside the range of a 32-bit float"));
    }
  }
}

}  // namespace

void finish_voxels(Volume& volume, const Conversion& conversion) {
  const size_t size = stored_size(conversion.stored);
  if (conversion.big_endian != (std::endian::native == std::endian::big))
    swap_bytes(volume.voxels, size);
  if (const auto type = held_as_is(conversion.stored)) {
    volume.type = *type;
  } else {
    with_type(conversion.stored, [&](auto source) {
      using Src = decltype(source);
      convert_elements<Src, float>(volume, VoxelType::float32,
                                   [](Src v, size_t) { return static_cast<float>(v); });
    });
  }
  check_rescale(volume, conversion);
  apply_rescale(volume, conversion.per_slice, conversion.int16_when_exact);
  volume.value_range = compute_value_range(volume);
}

glm::vec2 compute_value_range(const Volume& volume) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  with_type(stored_type_of(volume.type), [&](auto tag) {
    using T = decltype(tag);
    T min_value = std::numeric_limits<T>::max(), max_value = std::numeric_limits<T>::lowest();
    const size_t count = volume.voxels.size() / sizeof(T);
    for (size_t i = 0; i < count; ++i) {
      const T v = load<T>(volume.voxels.data() + i * sizeof(T));
      if constexpr (std::is_floating_point_v<T>)
        if (!std::isfinite(v)) continue;
      min_value = std::min(min_value, v);
      max_value = std::max(max_value, v);
    }
    if (min_value <= max_value) {
      lo = static_cast<double>(min_value);
      hi = static_cast<double>(max_value);
    }
  });
  if (lo > hi) return glm::vec2(0.0f);
  return glm::vec2(static_cast<float>(lo), static_cast<float>(hi));
}

std::string volume_name(const std::filesystem::path& path) {
  std::filesystem::path name = path.filename();
  if (name.empty()) name = path.parent_path().filename();  // "folder/"
  if (lowercase(name.extension().string()) == ".gz") name = name.stem();
  const std::string extension = lowercase(name.extension().string());
  for (const char* known : {".nii", ".mhd", ".mha", ".nrrd", ".nhdr", ".mgz", ".mgh", ".dcm", ".dicom"})
    if (extension == known) return name.stem().string();
  return name.string();
}

// ---- text headers

std::string_view trim(std::string_view text) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!text.empty() && space(text.front())) text.remove_prefix(1);
  while (!text.empty() && space(text.back())) text.remove_suffix(1);
  return text;
}

std::string lowercase(std::string_view text) {
  std::string result(text);
  for (char& c : result)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return result;
}

std::string printable(std::string_view text, size_t max_length) {
  std::string shown(text.substr(0, max_length));
  for (char& c : shown)
    if (c < 32 || c > 126) c = '?';
  return shown;
}

std::optional<std::string_view> TextHeader::get(std::string_view name) const {
  const std::string key = lowercase(name);
  for (const auto& [field, value] : fields)
    if (field == key) return value;
  return std::nullopt;
}

std::optional<std::string_view> TextHeader::first_of(
    std::initializer_list<std::string_view> names) const {
  for (std::string_view name : names)
    if (const auto value = get(name)) return value;
  return std::nullopt;
}

std::string_view TextHeader::require(std::string_view name) const {
  const auto value = get(name);
  if (!value)
    fail(path, quote_names ? concat("no '", name, "' field") : concat("no ", name, " field"));
  return *value;
}

TextLine next_line(std::string_view text, size_t& pos) {
  size_t end = text.find('\n', pos);
  const bool complete = end != std::string_view::npos;
  if (!complete) end = text.size();
  std::string_view line = text.substr(pos, end - pos);
  if (line.ends_with('\r')) line.remove_suffix(1);
  pos = complete ? end + 1 : end;
  return {line, complete};
}

}  // namespace strata::volume_io
