// DICOM series: a folder whose image files are the slices of one volume, read with GDCM.
//
// Two passes keep memory at one volume plus one slice: the first reads every file's header and
// checks that the slices fit together (size, orientation, spacing, series), the second decodes
// each slice's pixels straight into its place in Volume::voxels, in order along the slice normal.
// DICOM's patient space (LPS+) is strata's, so positions and cosines are taken as they are.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <gdcmImageReader.h>
#include <gdcmReader.h>
#include <gdcmStringFilter.h>
#include <gdcmTrace.h>

#include "engine/scene/io/dicom_structure.h"
#include "engine/scene/io/volume_io.h"
#include "engine/scene/io/volume_loader.h"

namespace strata {
namespace {

using namespace volume_io;
using namespace dicom;
namespace fs = std::filesystem;

const gdcm::Tag pixel_data_tag(0x7fe0, 0x0010);

struct Slice {
  fs::path file;
  uint32_t rows = 0, columns = 0;
  glm::dvec3 position{0.0}, row_cosine{0.0}, column_cosine{0.0};
  glm::dvec2 pixel_spacing{0.0};  // (along a row = between columns, between rows)
  int bits_allocated = 0, bits_stored = 0, high_bit = 0;
  bool is_signed = false;
  Rescale rescale;
  std::string series;
  double thickness = 0.0;
  double along_normal = 0.0;  // the position projected onto the slice normal
};

// Element values as text (GDCM's StringFilter renders binary VRs such as US too), parsed by hand
// so that malformed values become errors instead of zeros.
class Elements {
 public:
  Elements(const gdcm::File& file, fs::path path) : data_set_(file.GetDataSet()), path_(path) {
    filter_.SetFile(file);
  }
  bool has(uint16_t group, uint16_t element) const {
    const gdcm::Tag tag(group, element);
    return data_set_.FindDataElement(tag) && !data_set_.GetDataElement(tag).IsEmpty();
  }
  std::string text(uint16_t group, uint16_t element) const {
    return has(group, element) ? std::string(trim(filter_.ToString(gdcm::Tag(group, element))))
                               : std::string();
  }
  // The backslash-separated numbers of a required element (or of an optional one, if present).
  std::vector<double> numbers(uint16_t group, uint16_t element, const char* name, size_t count,
                              std::optional<double> fallback = std::nullopt) const {
    if (!has(group, element)) {
      if (!fallback) fail(path_, concat(name, " is missing"));
      return std::vector<double>(count, *fallback);
    }
    std::string value = text(group, element);
    std::replace(value.begin(), value.end(), '\\', ' ');
    const std::vector<double> result = parse_numbers<double>(path_, name, value);
    if (result.size() != count)
      fail(path_, concat(name, " = '", printable(value), "': expected ", count, " numbers"));
    return result;
  }
  int integer(uint16_t group, uint16_t element, const char* name,
              std::optional<double> fallback = std::nullopt) const {
    const double v = numbers(group, element, name, 1, fallback)[0];
    if (v != std::floor(v) || std::fabs(v) > 65535.0)
      fail(path_, concat(name, " = ", v, ": expected a whole number"));
    return static_cast<int>(v);
  }
  const gdcm::DataSet& data_set() const { return data_set_; }

 private:
  const gdcm::DataSet& data_set_;
  fs::path path_;
  gdcm::StringFilter filter_;
};

glm::dvec3 unit(const fs::path& file, const std::vector<double>& v, size_t first) {
  const glm::dvec3 d(v[first], v[first + 1], v[first + 2]);
  const double length = glm::length(d);
  if (!(length > 0.9 && length < 1.1))
    fail(file, "ImageOrientationPatient: the direction cosines are not unit vectors");
  return d / length;
}

void read_geometry(const Elements& e, Slice& s) {
  const auto position = e.numbers(0x0020, 0x0032, "ImagePositionPatient", 3);
  s.position = glm::dvec3(position[0], position[1], position[2]);
  const auto cosines = e.numbers(0x0020, 0x0037, "ImageOrientationPatient", 6);
  s.row_cosine = unit(s.file, cosines, 0);
  s.column_cosine = unit(s.file, cosines, 3);
  if (std::fabs(glm::dot(s.row_cosine, s.column_cosine)) > 1e-3)
    fail(s.file, "ImageOrientationPatient: the row and column cosines are not perpendicular");
  const auto spacing = e.numbers(0x0028, 0x0030, "PixelSpacing", 2);
  s.pixel_spacing = glm::dvec2(spacing[1], spacing[0]);  // DICOM lists the row spacing first
  if (!(spacing[0] > 0.0 && spacing[1] > 0.0 && std::isfinite(spacing[0] + spacing[1])))
    fail(s.file,
         concat("PixelSpacing = ", spacing[0], " ", spacing[1], ": spacing must be positive"));
  s.thickness = e.numbers(0x0018, 0x0050, "SliceThickness", 1, 0.0)[0];
}

void read_pixel_format(const Elements& e, Slice& s) {
  s.rows = static_cast<uint32_t>(e.integer(0x0028, 0x0010, "Rows"));
  s.columns = static_cast<uint32_t>(e.integer(0x0028, 0x0011, "Columns"));
  if (const int samples = e.integer(0x0028, 0x0002, "SamplesPerPixel", 1.0); samples != 1)
    fail(s.file, concat("SamplesPerPixel = ", samples, ": only grayscale images are supported"));
  if (const int frames = e.integer(0x0028, 0x0008, "NumberOfFrames", 1.0); frames > 1)
    fail(s.file, concat("NumberOfFrames = ", frames, ": multi-frame files are not supported"));
  s.bits_allocated = e.integer(0x0028, 0x0100, "BitsAllocated");
  if (s.bits_allocated != 8 && s.bits_allocated != 16)
    fail(s.file, concat("BitsAllocated = ", s.bits_allocated, ": only 8 and 16 are supported"));
  s.bits_stored = e.integer(0x0028, 0x0101, "BitsStored", s.bits_allocated);
  s.high_bit = e.integer(0x0028, 0x0102, "HighBit", s.bits_stored - 1);
  s.is_signed = e.integer(0x0028, 0x0103, "PixelRepresentation", 0.0) == 1;
  s.rescale.slope = e.numbers(0x0028, 0x1053, "RescaleSlope", 1, 1.0)[0];
  s.rescale.intercept = e.numbers(0x0028, 0x1052, "RescaleIntercept", 1, 0.0)[0];
}

// Native (uncompressed) pixel data must hold the whole slice; GDCM checks compressed data itself.
void check_pixel_data_length(const Elements& e, const Slice& s) {
  const gdcm::DataElement& pixels = e.data_set().GetDataElement(pixel_data_tag);
  const gdcm::ByteValue* value = pixels.GetByteValue();
  const uint64_t needed = uint64_t{s.rows} * s.columns * uint64_t(s.bits_allocated / 8);
  if (value && value->GetLength() < needed)
    fail(s.file,
         concat("PixelData has ", value->GetLength(), " bytes, Rows x Columns needs ", needed));
}

// The slice's header, or nothing for files that are not DICOM images (skipped).
std::optional<Slice> read_slice_header(const fs::path& file) {
  const Kind kind = file_kind(file);
  if (kind == Kind::other) return std::nullopt;
  try {
    check_structure(file, kind);
  } catch (const Error&) {
    if (kind == Kind::part10) throw;
    return std::nullopt;  // a bare data set that does not hold together: probably not DICOM
  }
  gdcm::Reader reader;
  reader.SetFileName(file.string().c_str());
  bool read = false;
  try {
    read = reader.Read();
  } catch (const std::exception&) {
    read = false;
  }
  if (!read) {
    if (kind == Kind::part10) fail(file, "DICOM file cannot be parsed (truncated or malformed)");
    return std::nullopt;
  }
  const Elements e(reader.GetFile(), file);
  // DICOMDIRs, reports and other non-image objects may sit beside the slices.
  if (!e.has(0x0028, 0x0010) || !e.has(0x0028, 0x0011)) return std::nullopt;
  if (!e.has(0x7fe0, 0x0010)) fail(file, "an image without PixelData (truncated?)");
  Slice s{.file = file};
  read_pixel_format(e, s);
  read_geometry(e, s);
  check_pixel_data_length(e, s);
  s.series = e.text(0x0020, 0x000e);
  return s;
}

std::string name_of(const Slice& s) {
  return s.file.filename().string();
}

void check_consistent(const fs::path& folder, const Slice& first, const Slice& s) {
  if (s.rows != first.rows || s.columns != first.columns)
    fail(folder, concat("mixed Rows/Columns: ", name_of(first), " is ", first.columns, "x",
                        first.rows, ", ", name_of(s), " is ", s.columns, "x", s.rows));
  if (glm::length(s.row_cosine - first.row_cosine) > 1e-3 ||
      glm::length(s.column_cosine - first.column_cosine) > 1e-3)
    fail(folder,
         concat("mixed ImageOrientationPatient: ", name_of(first), " and ", name_of(s), " differ"));
  if (glm::length(s.pixel_spacing - first.pixel_spacing) > 1e-3 * glm::length(first.pixel_spacing))
    fail(folder, concat("mixed PixelSpacing: ", name_of(first), " and ", name_of(s), " differ"));
  if (s.bits_allocated != first.bits_allocated || s.is_signed != first.is_signed ||
      s.bits_stored != first.bits_stored)
    fail(folder, concat("mixed pixel formats: ", name_of(first), " and ", name_of(s), " differ"));
  if (!s.series.empty() && !first.series.empty() && s.series != first.series)
    fail(folder, concat("holds more than one series: ", name_of(first), " and ", name_of(s),
                        " have different SeriesInstanceUIDs"));
}

std::vector<Slice> read_headers(const fs::path& folder) {
  std::vector<fs::path> files;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(folder, error))
    if (entry.is_regular_file(error)) files.push_back(entry.path());
  if (error) fail(folder, concat("cannot list the folder: ", error.message()));
  std::sort(files.begin(), files.end());
  std::vector<Slice> slices;
  for (const fs::path& file : files)
    if (auto slice = read_slice_header(file)) slices.push_back(std::move(*slice));
  if (slices.empty())
    fail(folder, files.empty() ? std::string("no DICOM files (the folder is empty)")
                               : concat("no DICOM files (none of its ", files.size(),
                                        " files is a DICOM image)"));
  for (const Slice& s : slices) check_consistent(folder, slices.front(), s);
  return slices;
}

// Sorts along the normal and returns the uniform distance between slices.
double sort_and_space(const fs::path& folder, std::vector<Slice>& slices, glm::dvec3 normal) {
  for (Slice& s : slices) s.along_normal = glm::dot(s.position, normal);
  std::stable_sort(slices.begin(), slices.end(),
                   [](const Slice& a, const Slice& b) { return a.along_normal < b.along_normal; });
  if (slices.size() == 1) return slices[0].thickness > 0.0 ? slices[0].thickness : 1.0;
  const double mean = (slices.back().along_normal - slices.front().along_normal) /
                      static_cast<double>(slices.size() - 1);
  for (size_t k = 0; k + 1 < slices.size(); ++k)
    if (slices[k + 1].along_normal - slices[k].along_normal < 1e-4)
      fail(folder,
           concat(name_of(slices[k]), " and ", name_of(slices[k + 1]),
                  " are at the same position (", slices[k].along_normal, " mm along the normal)"));
  for (size_t k = 0; k + 1 < slices.size(); ++k) {
    const double step = slices[k + 1].along_normal - slices[k].along_normal;
    if (std::fabs(step - mean) > std::max(1e-3, 0.01 * mean))
      fail(folder,
           concat("slice spacing is not uniform: ", step, " mm between ", name_of(slices[k]),
                  " and ", name_of(slices[k + 1]), ", ", mean, " mm on average"));
  }
  return mean;
}

void decode_slice(const Slice& s, std::byte* destination, size_t bytes) {
  gdcm::ImageReader reader;
  reader.SetFileName(s.file.string().c_str());
  bool decoded = false;
  try {
    if (reader.Read()) {
      const gdcm::Image& image = reader.GetImage();
      const bool same_size = image.GetColumns() == s.columns && image.GetRows() == s.rows &&
                             image.GetPixelFormat().GetBitsAllocated() == s.bits_allocated &&
                             image.GetBufferLength() == bytes;
      if (!same_size)
        fail(s.file, "the decoded pixel data does not match Rows, Columns and BitsAllocated");
      decoded = image.GetBuffer(reinterpret_cast<char*>(destination));
    }
  } catch (const Error&) {
    throw;
  } catch (const std::exception&) {
    decoded = false;
  }
  if (!decoded) fail(s.file, "cannot decode the pixel data");
}

// Clears bits above BitsStored (overlays live there in old files) and sign-extends signed data.
template <class Unsigned>
void clean_unused_bits(std::vector<std::byte>& voxels, int bits_stored, bool is_signed) {
  const auto mask = static_cast<Unsigned>((1u << bits_stored) - 1u);
  const auto sign = static_cast<Unsigned>(1u << (bits_stored - 1));
  for (size_t i = 0; i + sizeof(Unsigned) <= voxels.size(); i += sizeof(Unsigned)) {
    Unsigned v;
    std::memcpy(&v, voxels.data() + i, sizeof v);
    v = static_cast<Unsigned>(v & mask);
    if (is_signed && (v & sign)) v = static_cast<Unsigned>(v | ~mask);
    std::memcpy(voxels.data() + i, &v, sizeof v);
  }
}

std::vector<Rescale> rescales(const std::vector<Slice>& slices) {
  std::vector<Rescale> result;
  for (const Slice& s : slices) result.push_back(s.rescale);
  const bool uniform = std::all_of(result.begin(), result.end(), [&](const Rescale& r) {
    return r.slope == result[0].slope && r.intercept == result[0].intercept;
  });
  if (uniform) result.resize(1);
  return result;
}

}  // namespace

Volume load_dicom_series(const std::filesystem::path& folder) {
  std::error_code error;
  if (!fs::exists(folder, error)) fail(folder, "no such file");
  if (!fs::is_directory(folder, error)) fail(folder, "not a folder (a DICOM series is a folder)");
  // Files that are not DICOM are skipped on purpose; GDCM must not print about them.
  gdcm::Trace::DebugOff();
  gdcm::Trace::WarningOff();
  gdcm::Trace::ErrorOff();

  std::vector<Slice> slices = read_headers(folder);
  const Slice& first = slices.front();
  const glm::dvec3 normal = glm::normalize(glm::cross(first.row_cosine, first.column_cosine));
  const double step = sort_and_space(folder, slices, normal);

  const StoredType stored = first.bits_allocated == 8
                                ? (first.is_signed ? StoredType::int8 : StoredType::uint8)
                                : (first.is_signed ? StoredType::int16 : StoredType::uint16);
  const std::array<int64_t, 3> dims{first.columns, first.rows, int64_t(slices.size())};
  const size_t bytes =
      checked_voxel_bytes(folder, "Columns x Rows x files", dims, stored_size(stored));
  Volume volume;
  volume.name = volume_name(folder);
  volume.source = folder;
  volume.dims = to_dims(dims);
  volume.spacing = glm::vec3(first.pixel_spacing.x, first.pixel_spacing.y, step);
  volume.origin = glm::vec3(slices.front().position);
  volume.direction =
      glm::mat3(glm::vec3(first.row_cosine), glm::vec3(first.column_cosine), glm::vec3(normal));

  volume.voxels.resize(bytes);
  const size_t slice_bytes = bytes / slices.size();
  for (size_t k = 0; k < slices.size(); ++k)
    decode_slice(slices[k], volume.voxels.data() + k * slice_bytes, slice_bytes);
  if (first.bits_stored < first.bits_allocated && first.bits_stored > 0 &&
      first.high_bit == first.bits_stored - 1) {
    if (first.bits_allocated == 16)
      clean_unused_bits<uint16_t>(volume.voxels, first.bits_stored, first.is_signed);
    else
      clean_unused_bits<uint8_t>(volume.voxels, first.bits_stored, first.is_signed);
  }
  finish_voxels(volume, {.stored = stored,
                         .big_endian = std::endian::native == std::endian::big,
                         .per_slice = rescales(slices),
                         .int16_when_exact = true});
  return volume;
}

}  // namespace strata
