// DICOM, read with GDCM: a series (a folder whose image files are the slices of one volume) or one
// file, either an enhanced multi-frame CT or MR image that holds every slice, or a single slice.
//
// Two passes keep memory at one volume plus one file: the first reads every header and checks
// that the slices fit together (size, orientation, spacing, series), the second decodes the
// pixels straight into Volume::voxels, in order along the slice normal: each slice file into its
// place, a multi-frame file whole, its frames then put in order in place.
//
// An enhanced file gives each frame's position (and possibly orientation, spacing and rescale) in
// its Per-frame Functional Groups Sequence; what is the same for all frames may sit in the Shared
// Functional Groups Sequence instead, or, in converted files, at the top level. Lookups try the
// three in that order. DICOM's patient space (LPS+) is strata's, so positions and cosines are
// taken as they are.
#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>

#include <gdcmImageReader.h>
#include <gdcmReader.h>
#include <gdcmSequenceOfItems.h>
#include <gdcmStringFilter.h>
#include <gdcmTrace.h>
#include <gdcmTransferSyntax.h>

#include "engine/scene/io/dicom_elements.h"
#include "engine/scene/io/dicom_slice.h"
#include "engine/scene/io/dicom_stack.h"
#include "engine/scene/io/dicom_structure.h"
#include "engine/scene/io/volume_io.h"
#include "engine/scene/io/volume_loader.h"

namespace strata {
namespace {

using namespace volume_io;
using namespace dicom;
namespace fs = std::filesystem;

const gdcm::Tag pixel_data_tag(0x7fe0, 0x0010);

glm::dvec3 unit(const fs::path& file, const std::vector<double>& v, size_t first) {
  const glm::dvec3 d(v[first], v[first + 1], v[first + 2]);
  const double length = glm::length(d);
  if (!(length > 0.9 && length < 1.1))
    fail(file, "ImageOrientationPatient: the direction cosines are not unit vectors");
  return d / length;
}

// ---- the attributes of one slice, wherever they are

// The place value of a decimal string's last digit: 0.1 for "-12.3", 1 for "40", 0.01 for
// "1.5E-1".
double last_digit(std::string_view number) {
  number = trim(number);
  int exponent = 0;
  if (const size_t e = number.find_first_of("eE"); e != std::string_view::npos) {
    std::string_view digits = number.substr(e + 1);
    if (digits.starts_with('+')) digits.remove_prefix(1);
    std::from_chars(digits.data(), digits.data() + digits.size(), exponent);
    number = number.substr(0, e);
  }
  const size_t point = number.find('.');
  const int decimals = point == std::string_view::npos ? 0 : int(number.size() - point - 1);
  return std::pow(10.0, std::clamp(exponent - decimals, -30, 30));
}

}  // namespace

void dicom::read_position(const Elements& e, Slice& s) {
  const auto position = e.numbers(0x0020, 0x0032, "ImagePositionPatient", 3);
  s.position = glm::dvec3(position[0], position[1], position[2]);
  const std::string text = e.text(0x0020, 0x0032);
  size_t begin = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const size_t end = std::min(text.find('\\', begin), text.size());
    s.position_digit[axis] = last_digit(std::string_view(text).substr(begin, end - begin));
    begin = end + 1;
  }
  if (!std::isfinite(float(s.position.x)) || !std::isfinite(float(s.position.y)) ||
      !std::isfinite(float(s.position.z)))
    fail(e.path(), concat("ImagePositionPatient = ", position[0], " ", position[1], " ",
                          position[2], ": the position must be finite numbers"));
}

void dicom::read_orientation(const Elements& e, Slice& s) {
  const auto cosines = e.numbers(0x0020, 0x0037, "ImageOrientationPatient", 6);
  s.row_cosine = unit(e.path(), cosines, 0);
  s.column_cosine = unit(e.path(), cosines, 3);
  if (std::fabs(glm::dot(s.row_cosine, s.column_cosine)) > 1e-3)
    fail(e.path(), "ImageOrientationPatient: the row and column cosines are not perpendicular");
}

void dicom::read_pixel_measures(const Elements& e, Slice& s) {
  const auto spacing = e.numbers(0x0028, 0x0030, "PixelSpacing", 2);
  s.pixel_spacing = glm::dvec2(spacing[1], spacing[0]);  // DICOM lists the row spacing first
  if (!(spacing[0] > 0.0 && spacing[1] > 0.0 && std::isfinite(spacing[0] + spacing[1])))
    fail(e.path(),
         concat("PixelSpacing = ", spacing[0], " ", spacing[1], ": spacing must be positive"));
  s.thickness = e.numbers(0x0018, 0x0050, "SliceThickness", 1, 0.0)[0];
}

namespace {

void read_rescale(const Elements& e, Slice& s) {
  s.rescale.slope = e.numbers(0x0028, 0x1053, "RescaleSlope", 1, 1.0)[0];
  s.rescale.intercept = e.numbers(0x0028, 0x1052, "RescaleIntercept", 1, 0.0)[0];
  // Unlike NIfTI's scl_slope, DICOM has no "0 means none": such a value is a broken file.
  if (!std::isfinite(s.rescale.slope) || s.rescale.slope == 0.0)
    fail(e.path(),
         concat("RescaleSlope = ", s.rescale.slope, ": expected a finite, non-zero number"));
  if (!std::isfinite(s.rescale.intercept))
    fail(e.path(),
         concat("RescaleIntercept = ", s.rescale.intercept, ": expected a finite number"));
}

void read_frame_content(const Elements& e, Slice& s) {
  s.stack = e.text(0x0020, 0x9056);
  s.time = e.text(0x0020, 0x9128);
}

// One sample per pixel is a grey value only in MONOCHROME1/2 (or when the field is missing, as in
// old files); a PALETTE COLOR pixel is an index into a colour table.
void check_grey(const Elements& e, const Slice& s) {
  const std::string photometric = e.text(0x0028, 0x0004);
  if (photometric.empty() || photometric == "MONOCHROME1" || photometric == "MONOCHROME2") return;
  if (photometric == "PALETTE COLOR") {
    const bool table = (e.has(0x0028, 0x1201) && e.has(0x0028, 0x1202) && e.has(0x0028, 0x1203)) ||
                       (e.has(0x0028, 0x1221) && e.has(0x0028, 0x1222) && e.has(0x0028, 0x1223));
    if (!table)
      fail(s.file,
           "PhotometricInterpretation = PALETTE COLOR without a lookup table (no Red, Green and "
           "Blue Palette Color Lookup Table Data): the pixel values are indices into a missing "
           "table");
    fail(s.file,
         "PhotometricInterpretation = PALETTE COLOR: the pixel values are indices into a colour "
         "table, not intensities; strata reads greyscale (MONOCHROME1, MONOCHROME2) images");
  }
  fail(s.file, concat("PhotometricInterpretation = ", printable(photometric),
                      ": strata reads greyscale (MONOCHROME1, MONOCHROME2) images"));
}

void read_pixel_format(const Elements& e, Slice& s) {
  s.rows = static_cast<uint32_t>(e.integer(0x0028, 0x0010, "Rows"));
  s.columns = static_cast<uint32_t>(e.integer(0x0028, 0x0011, "Columns"));
  if (const int samples = e.integer(0x0028, 0x0002, "SamplesPerPixel", 1.0); samples != 1)
    fail(s.file, concat("SamplesPerPixel = ", samples, ": only grayscale images are supported"));
  check_grey(e, s);
  s.bits_allocated = e.integer(0x0028, 0x0100, "BitsAllocated");
  if (s.bits_allocated != 8 && s.bits_allocated != 16)
    fail(s.file, concat("BitsAllocated = ", s.bits_allocated, ": only 8 and 16 are supported"));
  s.bits_stored = e.integer(0x0028, 0x0101, "BitsStored", s.bits_allocated);
  if (s.bits_stored < 1 || s.bits_stored > s.bits_allocated)
    fail(s.file, concat("BitsStored = ", s.bits_stored, ": must be 1 to BitsAllocated (",
                        s.bits_allocated, ")"));
  s.high_bit = e.integer(0x0028, 0x0102, "HighBit", s.bits_stored - 1);
  if (s.high_bit < s.bits_stored - 1 || s.high_bit >= s.bits_allocated)
    fail(s.file, concat("HighBit = ", s.high_bit, ": must be BitsStored - 1 (", s.bits_stored - 1,
                        ") to BitsAllocated - 1 (", s.bits_allocated - 1, ")"));
  s.is_signed = e.integer(0x0028, 0x0103, "PixelRepresentation", 0.0) == 1;
}

// A single image without ImagePositionPatient (a secondary capture, a scanned film): one slice at
// the origin, rows along x, columns along y unless ImageOrientationPatient says otherwise, in
// PixelSpacing, else ImagerPixelSpacing, else 1 mm.
void read_unplaced(const Elements& e, Slice& s) {
  s.placed = false;
  if (e.has(0x0020, 0x0037)) {
    read_orientation(e, s);
  } else {
    s.row_cosine = glm::dvec3(1.0, 0.0, 0.0);
    s.column_cosine = glm::dvec3(0.0, 1.0, 0.0);
  }
  if (e.has(0x0028, 0x0030)) {
    read_pixel_measures(e, s);
    return;
  }
  const auto spacing = e.numbers(0x0018, 0x1164, "ImagerPixelSpacing", 2, 1.0);
  if (!(spacing[0] > 0.0 && spacing[1] > 0.0 && std::isfinite(spacing[0] + spacing[1])))
    fail(e.path(), concat("ImagerPixelSpacing = ", spacing[0], " ", spacing[1],
                          ": spacing must be positive"));
  s.pixel_spacing = glm::dvec2(spacing[1], spacing[0]);
  s.thickness = e.numbers(0x0018, 0x0050, "SliceThickness", 1, 0.0)[0];
}

// ---- enhanced multi-frame files

// Frame f's slice: the file's pixel format (in `common`) and the frame's own attributes.
Slice read_frame(const gdcm::File& file, const FunctionalGroups& groups, const Slice& common,
                 size_t f) {
  Slice s = common;
  s.frame = f;
  const std::string context = concat("frame ", f + 1, ": ");  // DICOM counts frames from 1
  const Elements top(file, file.GetDataSet(), s.file, context);
  const auto read = [&](uint16_t group, uint16_t element,
                        void (*read_into)(const Elements&, Slice&)) {
    const bool found = groups.with_macro(f, group, element, [&](const gdcm::DataSet& attributes) {
      read_into(Elements(file, attributes, s.file, context), s);
    });
    if (!found) read_into(top, s);
  };
  read(0x0020, 0x9113, read_position);
  read(0x0020, 0x9116, read_orientation);
  read(0x0028, 0x9110, read_pixel_measures);
  read(0x0028, 0x9145, read_rescale);
  groups.with_macro(f, 0x0020, 0x9111, [&](const gdcm::DataSet& attributes) {
    read_frame_content(Elements(file, attributes, s.file, context), s);
  });
  return s;
}

// One stack at one time: the frames must be slices of one volume.
void check_one_volume(const fs::path& file, const std::vector<Slice>& frames) {
  const Slice& first = frames.front();
  for (const Slice& s : frames) {
    if (s.stack != first.stack)
      fail(file, concat("holds several stacks (frame 1 has StackID '", first.stack, "', frame ",
                        s.frame + 1, " '", s.stack, "'): strata reads one stack of slices"));
    if (s.time != first.time)
      fail(file, concat("holds several time points (frame 1 has TemporalPositionIndex ", first.time,
                        ", frame ", s.frame + 1, " ", s.time,
                        "): strata reads an enhanced file of one time point; dcm2niix converts "
                        "it to a 4-D NIfTI, whose --frame picks one"));
  }
}

std::vector<Slice> read_frames(const gdcm::File& file, const Elements& e, const Slice& common) {
  const int count = e.integer(0x0028, 0x0008, "NumberOfFrames", 1.0);
  if (count < 1) fail(common.file, concat("NumberOfFrames = ", count, ": must be positive"));
  const FunctionalGroups groups(file.GetDataSet());
  if (!groups.present()) {
    if (count > 1)
      fail(common.file, concat("NumberOfFrames = ", count,
                               " without a Per-frame Functional Groups Sequence: only enhanced "
                               "multi-frame images (CT, MR) are supported"));
    Slice s = common;
    if (e.has(0x0020, 0x0032)) {
      read_position(e, s);
      read_orientation(e, s);
      read_pixel_measures(e, s);
    } else {
      read_unplaced(e, s);
    }
    read_rescale(e, s);
    return {s};
  }
  if (groups.per_frame_items() != 0 && groups.per_frame_items() != size_t(count))
    fail(common.file, concat("PerFrameFunctionalGroupsSequence has ", groups.per_frame_items(),
                             " items, NumberOfFrames is ", count));
  std::vector<Slice> frames;
  for (size_t f = 0; f < size_t(count); ++f) {
    frames.push_back(read_frame(file, groups, common, f));
    frames.back().frames_in_file = size_t(count);
  }
  check_one_volume(common.file, frames);
  return frames;
}

// ---- files

// Native (uncompressed) pixel data must hold every frame; GDCM checks compressed data itself.
void check_pixel_data_length(const Elements& e, const Slice& s) {
  const gdcm::DataElement& pixels = e.data_set().GetDataElement(pixel_data_tag);
  const gdcm::ByteValue* value = pixels.GetByteValue();
  const uint64_t needed =
      uint64_t{s.rows} * s.columns * uint64_t(s.bits_allocated / 8) * s.frames_in_file;
  if (value && value->GetLength() < needed)
    fail(s.file, concat("PixelData has ", value->GetLength(), " bytes, Rows x Columns",
                        s.frames_in_file > 1 ? " x NumberOfFrames" : "", " needs ", needed));
}

// A file of a series folder that is not DICOM is skipped (a README, a thumbnail database), but one
// that is a damaged slice must not be: the volume would load a slice short, or with a gap.
// Empty files, files that cannot be read and files that begin with zero bytes (a preamble
// without 'DICM' after it) are errors.
void check_not_a_damaged_slice(const fs::path& file) {
  std::error_code error;
  const uintmax_t size = fs::file_size(file, error);
  if (error) fail(file, concat("cannot read: ", error.message()));
  if (size == 0) fail(file, "empty file in a DICOM folder (a damaged slice?)");
  if (file_kind(file) != Kind::other) return;  // DICOM: damage there is found when it is read
  std::ifstream in(file, std::ios::binary);
  char head[128] = {};
  in.read(head, sizeof head);
  if (!in && !in.eof()) fail(file, "cannot read");
  const auto got = static_cast<size_t>(in.gcount());
  if (got == 0) fail(file, "cannot read");
  if (std::all_of(head, head + got, [](char c) { return c == 0; }))
    fail(file, got == 128 ? "no 'DICM' after the 128-byte preamble of zeros: a damaged DICOM file"
                          : "only zero bytes: a damaged DICOM file");
}

// The file's slices (one, or one per frame), or none for files that are not DICOM images.
std::vector<Slice> read_file_slices(const fs::path& file) {
  const Kind kind = file_kind(file);
  if (kind == Kind::other) return {};
  // A bare data set (no preamble) that does not hold together is an error too: it begins like
  // DICOM (a group 0008 tag), so it is most likely a damaged slice.
  check_structure(file, kind);
  gdcm::Reader reader;
  reader.SetFileName(file.string().c_str());
  bool read = false;
  try {
    read = reader.Read();
  } catch (const std::exception&) {
    read = false;
  }
  if (!read) fail_to_parse(file, reader);
  const Elements e(reader.GetFile(), reader.GetFile().GetDataSet(), file);
  // DICOMDIRs, reports and other non-image objects may sit beside the slices.
  if (!e.has(0x0028, 0x0010) || !e.has(0x0028, 0x0011)) return {};
  if (!e.has(0x7fe0, 0x0010)) fail(file, "an image without PixelData (truncated?)");
  Slice common{.file = file};
  read_pixel_format(e, common);
  common.series = e.text(0x0020, 0x000e);
  common.series_number = e.text(0x0020, 0x0011);
  common.description = e.text(0x0008, 0x103e);
  common.modality = e.text(0x0008, 0x0060);
  common.instance = e.text(0x0008, 0x0018);
  for (size_t key = 0; key < kKeyTags.size(); ++key)
    common.keys[key] = e.text(kKeyTags[key].group, kKeyTags[key].element);
  // A Siemens mosaic tiles a whole stack of slices into one image; read as one slice it would
  // show as a grid of stripes.
  const std::string image_type = e.text(0x0008, 0x0008);
  if (image_type.find("MOSAIC") != std::string::npos)
    fail(file, concat("a Siemens mosaic (ImageType ", printable(image_type, 80),
                      "): its slices are tiles of one image, which strata does not unpack; "
                      "convert the series to NIfTI first (dcm2niix, in Debian's dcm2niix "
                      "package) and open that"));
  const char* syntax = reader.GetFile().GetHeader().GetDataSetTransferSyntax().GetString();
  common.syntax = syntax ? syntax : "";
  std::vector<Slice> slices = read_frames(reader.GetFile(), e, common);
  check_pixel_data_length(e, slices.front());
  return slices;
}

void check_consistent(const fs::path& where, const Slice& first, const Slice& s) {
  if (s.rows != first.rows || s.columns != first.columns)
    fail(where, concat("mixed Rows/Columns: ", name_of(first), " is ", first.columns, "x",
                       first.rows, ", ", name_of(s), " is ", s.columns, "x", s.rows));
  if (glm::length(s.row_cosine - first.row_cosine) > 1e-3 ||
      glm::length(s.column_cosine - first.column_cosine) > 1e-3)
    fail(where,
         concat("mixed ImageOrientationPatient: ", name_of(first), " and ", name_of(s), " differ"));
  if (glm::length(s.pixel_spacing - first.pixel_spacing) > 1e-3 * glm::length(first.pixel_spacing))
    fail(where, concat("mixed PixelSpacing: ", name_of(first), " and ", name_of(s), " differ"));
  if (s.bits_allocated != first.bits_allocated || s.is_signed != first.is_signed ||
      s.bits_stored != first.bits_stored || s.high_bit != first.high_bit)
    fail(where, concat("mixed pixel formats: ", name_of(first), " and ", name_of(s), " differ"));
  if (!s.series.empty() && !first.series.empty() && s.series != first.series)
    fail(where, concat("holds more than one series: ", name_of(first), " and ", name_of(s),
                       " have different SeriesInstanceUIDs"));
}

// Where DICOM files are below a folder that holds none itself (a DICOM/PA0/ST0/SE0 tree, an
// archive unpacked into a folder of its own): the subfolders, at most 4 levels down, that hold a
// file which begins as DICOM does; at most `most` of them, the first 10000 files looked at.
std::vector<fs::path> dicom_subfolders(const fs::path& folder, size_t most) {
  std::vector<fs::path> found;
  std::error_code error;
  fs::recursive_directory_iterator entry(folder, fs::directory_options::skip_permission_denied,
                                         error);
  for (size_t looked = 0; !error && entry != fs::recursive_directory_iterator() && looked < 10000;
       entry.increment(error)) {
    if (entry.depth() >= 3) entry.disable_recursion_pending();
    std::error_code entry_error;
    const fs::path parent = entry->path().parent_path();
    if (!entry->is_regular_file(entry_error) || parent == folder ||
        std::find(found.begin(), found.end(), parent) != found.end())
      continue;
    ++looked;
    if (file_kind(entry->path()) == Kind::other) continue;
    found.push_back(parent);
    if (found.size() == most) break;
  }
  std::sort(found.begin(), found.end());
  return found;
}

[[noreturn]] void fail_no_dicom(const fs::path& folder, size_t files) {
  const std::string what = files == 0 ? std::string("the folder is empty")
                                      : concat("none of its ", files, " files is a DICOM image");
  const std::vector<fs::path> below = dicom_subfolders(folder, 4);
  if (below.empty()) fail(folder, concat("no DICOM files (", what, ")"));
  std::string names;
  for (size_t i = 0; i < below.size() && i < 3; ++i)
    names += (i ? ", " : "") + printable(below[i].lexically_relative(folder).string(), 80);
  const std::string here = concat("no DICOM files in the folder itself (",
                                  files == 0 ? "it holds only subfolders" : what, ")");
  if (below.size() == 1)
    fail(folder, concat(here, "; its subfolder ", names, " holds DICOM files: open ",
                        below[0].string(), " (strata reads one folder's files as a series)"));
  fail(folder, concat(here, "; its subfolders ", names, below.size() > 3 ? " and more" : "",
                      " hold DICOM files: open one of them (strata reads one folder's files as a "
                      "series)"));
}

// A folder's image files, as slices, and the names of the files that are not DICOM images.
struct FolderSlices {
  std::vector<Slice> slices;
  std::vector<std::string> skipped;  // hidden files (".DS_Store") left out
};

// Every image file's slices; a folder holds single-frame slices or one multi-frame file.
FolderSlices read_folder(const fs::path& folder) {
  std::vector<fs::path> files;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(folder, error)) {
    std::error_code entry_error;
    if (entry.is_symlink(entry_error) && !fs::exists(entry.path(), entry_error))
      fail(entry.path(), "cannot read: a link to a file that does not exist (a missing slice?)");
    if (entry.is_regular_file(entry_error)) files.push_back(entry.path());
  }
  if (error) fail(folder, concat("cannot list the folder: ", error.message()));
  std::sort(files.begin(), files.end());
  FolderSlices read;
  for (const fs::path& file : files) {
    const std::string name = file.filename().string();
    if (name.front() != '.') check_not_a_damaged_slice(file);
    std::vector<Slice> more = read_file_slices(file);
    if (more.empty() && name.front() != '.') read.skipped.push_back(name);
    read.slices.insert(read.slices.end(), more.begin(), more.end());
  }
  if (read.slices.empty()) fail_no_dicom(folder, files.size());
  return read;
}

// One line however many: the first names, then how many more.
std::string skipped_warning(const fs::path& folder, const std::vector<std::string>& skipped) {
  constexpr size_t kNamed = 8;
  std::string names;
  for (size_t i = 0; i < skipped.size() && i < kNamed; ++i)
    names += (i ? ", " : "") + printable(skipped[i], 60);
  if (skipped.size() > kNamed) names += concat(" and ", skipped.size() - kNamed, " more");
  return concat(folder.string(), ": skipped ", skipped.size(),
                skipped.size() == 1 ? " file that is not a DICOM image: "
                                    : " files that are not DICOM images: ",
                names);
}

// A folder's slices by series (SeriesInstanceUID; files without one together), in the order
// their first files sort. Within a series: single-frame slices or one multi-frame file.
std::vector<std::vector<Slice>> by_series(const fs::path& folder, std::vector<Slice> slices) {
  std::vector<std::vector<Slice>> groups;
  for (Slice& s : slices) {
    auto group = std::find_if(groups.begin(), groups.end(), [&](const std::vector<Slice>& g) {
      return g.front().series == s.series;
    });
    if (group == groups.end()) {
      groups.emplace_back();
      group = groups.end() - 1;
    }
    group->push_back(std::move(s));
  }
  for (const std::vector<Slice>& g : groups) {
    const auto multi =
        std::find_if(g.begin(), g.end(), [](const Slice& s) { return s.frames_in_file > 1; });
    if (multi == g.end()) continue;
    const auto other =
        std::find_if(g.begin(), g.end(), [&](const Slice& s) { return s.file != multi->file; });
    if (other != g.end())
      fail(folder, concat("holds the multi-frame file ", multi->file.filename().string(),
                          " and other images of its series: strata reads a series of "
                          "single-frame slices or one multi-frame file"));
  }
  return groups;
}

// The plane of the slices, from their normal: the patient axis it is nearest (within 10
// degrees), else oblique.
std::string orientation_name(const Slice& s) {
  const glm::dvec3 n = glm::cross(s.row_cosine, s.column_cosine);
  if (glm::length(n) < 0.5) return "unknown";
  const glm::dvec3 a = glm::abs(glm::normalize(n));
  const double cos10 = std::cos(10.0 * 3.14159265358979 / 180.0);
  if (a.z >= cos10) return "axial";
  if (a.x >= cos10) return "sagittal";
  if (a.y >= cos10) return "coronal";
  return "oblique";
}

DicomSeries describe_series(const std::vector<Slice>& g) {
  const Slice& first = g.front();
  DicomSeries out;
  out.uid = first.series;
  out.number = first.series_number;
  out.description = first.description;
  out.modality = first.modality;
  out.columns = first.columns;
  out.rows = first.rows;
  out.images = uint32_t(g.size());
  out.time_points = uint32_t(count_time_points(g));
  out.orientation = first.placed ? orientation_name(first) : "unplaced";
  return out;
}

// "series 3 'T1 MPRAGE' (MR, 256x256x176)", or by its UID where it has no number.
std::string series_name(const DicomSeries& s) {
  std::string name = s.number.empty()
                         ? "series " + (s.uid.empty() ? std::string("(no UID)") : s.uid)
                         : "series " + s.number;
  if (!s.description.empty()) name += " '" + printable(s.description, 64) + "'";
  return concat(name, " (", s.modality.empty() ? "?" : s.modality, ", ", s.columns, "x", s.rows,
                "x", s.images, ")");
}

// The series a load opens: the one `wanted` names (its SeriesNumber or SeriesInstanceUID), else
// the only one, else the largest 3-D image series (most voxels among those of more than one
// slice), with a warning naming the others and how to choose.
size_t choose_series(const fs::path& folder, const std::vector<std::vector<Slice>>& groups,
                     const std::string& wanted, std::vector<std::string>& warnings) {
  std::vector<DicomSeries> all;
  for (const auto& g : groups) all.push_back(describe_series(g));
  std::string listed;
  for (const DicomSeries& s : all) listed += (listed.empty() ? "" : "; ") + series_name(s);
  if (!wanted.empty()) {
    std::vector<size_t> matches;
    for (size_t i = 0; i < all.size(); ++i)
      if (all[i].uid == wanted || all[i].number == wanted) matches.push_back(i);
    if (matches.empty())
      fail(folder, concat("no series '", printable(wanted, 80),
                          "' (SeriesNumber or "
                          "SeriesInstanceUID); the folder holds: ",
                          listed));
    if (matches.size() > 1)
      fail(folder, concat("SeriesNumber ", wanted, " names ", matches.size(),
                          " series: give the SeriesInstanceUID (strata info ", folder.string(),
                          " lists them)"));
    return matches.front();
  }
  if (all.size() == 1) return 0;
  const auto voxels = [](const DicomSeries& s) {
    return uint64_t{s.columns} * s.rows * s.images * (s.images > 1 ? 1u : 0u);
  };
  size_t best = 0;
  for (size_t i = 1; i < all.size(); ++i) {
    const bool more = voxels(all[i]) > voxels(all[best]) ||
                      (voxels(all[best]) == 0 &&
                       all[i].images * uint64_t{all[i].columns} * all[i].rows >
                           all[best].images * uint64_t{all[best].columns} * all[best].rows);
    if (more) best = i;
  }
  std::string others;
  for (size_t i = 0; i < all.size(); ++i)
    if (i != best) others += (others.empty() ? "" : "; ") + series_name(all[i]);
  warnings.push_back(
      concat(folder.string(), ": holds ", all.size(), " series; opened ", series_name(all[best]),
             voxels(all[best]) > 0 ? ", the largest 3-D image" : ", the largest image",
             "; the others: ", others,
             ". --series NUMBER or UID (or the scene's \"series\") opens another; "
             "strata info ",
             folder.string(), " lists them"));
  return best;
}

// ---- pixels

// Decodes a file's pixel data (all its frames) into `bytes` bytes at destination.
// Little-endian native pixel data is copied as it is: GDCM's raw codec goes through string
// streams, up to four copies of a multi-frame file's pixels at once.
bool is_native_little_endian(const Slice& s) {
  return s.syntax == "1.2.840.10008.1.2" || s.syntax == "1.2.840.10008.1.2.1";
}

bool copy_native(const Slice& s, std::byte* destination, size_t bytes) {
  if (!is_native_little_endian(s)) return false;
  gdcm::Reader reader;
  reader.SetFileName(s.file.string().c_str());
  bool read = false;
  try {
    read = reader.Read();
  } catch (const std::exception&) {
    read = false;
  }
  const gdcm::DataSet& data_set = reader.GetFile().GetDataSet();
  const gdcm::ByteValue* value = read && data_set.FindDataElement(pixel_data_tag)
                                     ? data_set.GetDataElement(pixel_data_tag).GetByteValue()
                                     : nullptr;
  if (!value || value->GetLength() < bytes) fail(s.file, "cannot read the pixel data");
  std::memcpy(destination, value->GetPointer(), bytes);
  return true;
}

void decode_file(const Slice& s, std::byte* destination, size_t bytes) {
  if (copy_native(s, destination, bytes)) return;
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
        fail(s.file,
             "the decoded pixel data does not match Rows, Columns, BitsAllocated and "
             "NumberOfFrames");
      decoded = image.GetBuffer(reinterpret_cast<char*>(destination));
    }
  } catch (const Error&) {
    throw;
  } catch (const std::exception&) {
    decoded = false;
  }
  if (!decoded)
    fail(s.file, concat("cannot decode the pixel data (transfer syntax ", s.syntax,
                        ": corrupt, or a compression GDCM has no codec for)"));
}

// Puts frame slices[k].frame into slot k for every k, in place: each cycle of the permutation is
// followed with one slice of scratch.
void order_frames(std::vector<std::byte>& voxels, const std::vector<Slice>& slices,
                  size_t slice_bytes) {
  std::vector<bool> placed(slices.size(), false);
  std::vector<std::byte> scratch(slice_bytes);
  const auto slot = [&](size_t k) { return voxels.data() + k * slice_bytes; };
  for (size_t start = 0; start < slices.size(); ++start) {
    if (placed[start] || slices[start].frame == start) continue;
    std::memcpy(scratch.data(), slot(start), slice_bytes);
    size_t k = start;
    while (slices[k].frame != start) {
      std::memcpy(slot(k), slot(slices[k].frame), slice_bytes);
      placed[k] = true;
      k = slices[k].frame;
    }
    std::memcpy(slot(k), scratch.data(), slice_bytes);
    placed[k] = true;
  }
}

// Moves the BitsStored bits that end at HighBit down to bit 0, clears the bits above them
// (overlays live there in old files) and sign-extends signed data.
template <class Unsigned>
void clean_unused_bits(std::vector<std::byte>& voxels, int bits_stored, int high_bit,
                       bool is_signed) {
  const auto mask = static_cast<Unsigned>((1u << bits_stored) - 1u);
  const auto sign = static_cast<Unsigned>(1u << (bits_stored - 1));
  const int shift = high_bit + 1 - bits_stored;
  for (size_t i = 0; i + sizeof(Unsigned) <= voxels.size(); i += sizeof(Unsigned)) {
    Unsigned v;
    std::memcpy(&v, voxels.data() + i, sizeof v);
    v = static_cast<Unsigned>((v >> shift) & mask);
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

void decode(Volume& volume, const std::vector<Slice>& slices, size_t bytes) {
  volume.voxels.resize(bytes);
  const size_t slice_bytes = bytes / slices.size();
  if (slices.front().frames_in_file > 1) {
    decode_file(slices.front(), volume.voxels.data(), bytes);
    order_frames(volume.voxels, slices, slice_bytes);
  } else {
    for (size_t k = 0; k < slices.size(); ++k)
      decode_file(slices[k], volume.voxels.data() + k * slice_bytes, slice_bytes);
  }
  const Slice& first = slices.front();
  if (first.bits_stored < first.bits_allocated) {
    if (first.bits_allocated == 16)
      clean_unused_bits<uint16_t>(volume.voxels, first.bits_stored, first.high_bit,
                                  first.is_signed);
    else
      clean_unused_bits<uint8_t>(volume.voxels, first.bits_stored, first.high_bit, first.is_signed);
  }
}

// Pixels whose HighBit is above BitsStored - 1 are moved down after decoding; that is known to be
// right for uncompressed data only (a codec may have moved them already).
void check_high_bit(const std::vector<Slice>& slices) {
  for (const Slice& s : slices)
    if (s.high_bit != s.bits_stored - 1 && !is_native_little_endian(s))
      fail(s.file, concat("HighBit = ", s.high_bit, " with BitsStored = ", s.bits_stored,
                          " in transfer syntax ", s.syntax,
                          ": strata reads such pixels uncompressed (little endian) only"));
}

// A slice without a position can only be shown alone, as a 2-D image.
void check_placed(const fs::path& where, const std::vector<Slice>& slices,
                  std::vector<std::string>& warnings) {
  for (const Slice& s : slices)
    if (!s.placed && slices.size() > 1)
      fail(s.file, "ImagePositionPatient is missing: a slice of a series needs its position");
  const Slice& s = slices.front();
  if (!s.placed)
    warnings.push_back(concat(where.string(),
                              ": ImagePositionPatient is missing (a secondary capture or other "
                              "2-D image): shown as one slice at the origin of patient space, "
                              "pixels ",
                              s.pixel_spacing.x, " x ", s.pixel_spacing.y, " mm"));
}

// The volume of checked slices; `where` (the folder or file) names it in errors.
Volume assemble(const fs::path& where, std::vector<Slice> slices, const VolumeLimits& limits,
                std::vector<std::string>& warnings) {
  check_placed(where, slices, warnings);
  for (const Slice& s : slices) check_consistent(where, slices.front(), s);
  check_high_bit(slices);
  const StackAxis axis = order_stack(where, slices, warnings);
  const Slice& first = slices.front();

  const StoredType stored = first.bits_allocated == 8
                                ? (first.is_signed ? StoredType::int8 : StoredType::uint8)
                                : (first.is_signed ? StoredType::int16 : StoredType::uint16);
  const std::array<int64_t, 3> dims{first.columns, first.rows, int64_t(slices.size())};
  const size_t bytes = checked_voxel_bytes(
      where,
      first.frames_in_file > 1 ? "Columns x Rows x NumberOfFrames" : "Columns x Rows x files", dims,
      stored_size(stored), limits);
  Volume volume;
  volume.name = volume_name(where);
  volume.source = where;
  volume.dims = to_dims(dims);
  volume.spacing = glm::vec3(first.pixel_spacing.x, first.pixel_spacing.y, axis.spacing);
  volume.origin = glm::vec3(slices.front().position);
  volume.direction = glm::mat3(glm::vec3(first.row_cosine), glm::vec3(first.column_cosine),
                               glm::vec3(axis.direction));
  decode(volume, slices, bytes);
  finish_voxels(volume, {.stored = stored,
                         .big_endian = std::endian::native == std::endian::big,
                         .per_slice = rescales(slices),
                         .int16_when_exact = true,
                         .rescale_field = "RescaleSlope, RescaleIntercept"});
  return volume;
}

}  // namespace

void dicom::fail_to_parse(const fs::path& file, const gdcm::Reader& reader) {
  const gdcm::FileMetaInformation& meta = reader.GetFile().GetHeader();
  const gdcm::Tag syntax_tag(0x0002, 0x0010);
  if (meta.FindDataElement(syntax_tag))
    if (const gdcm::ByteValue* value = meta.GetDataElement(syntax_tag).GetByteValue()) {
      const std::string uid(trim(std::string(value->GetPointer(), value->GetLength()).c_str()));
      if (gdcm::TransferSyntax::GetTSType(uid.c_str()) == gdcm::TransferSyntax::TS_END)
        fail(file, concat("TransferSyntaxUID ", printable(uid, 64),
                          " is not supported (GDCM does not know it; strata reads uncompressed, "
                          "RLE, JPEG, JPEG-LS and JPEG 2000 DICOM)"));
    }
  fail(file, "DICOM file cannot be parsed (truncated or malformed)");
}

void dicom::quiet_gdcm() {
  gdcm::Trace::DebugOff();
  gdcm::Trace::WarningOff();
  gdcm::Trace::ErrorOff();
}

std::string dicom::name_of(const Slice& s) {
  return s.frames_in_file > 1 ? concat("frame ", s.frame + 1) : s.file.filename().string();
}

Volume load_dicom_series(const std::filesystem::path& folder, const VolumeReadOptions& options,
                         std::vector<std::string>& warnings) {
  std::error_code error;
  if (!fs::exists(folder, error)) fail(folder, "no such file");
  if (!fs::is_directory(folder, error)) fail(folder, "not a folder (a DICOM series is a folder)");
  quiet_gdcm();
  FolderSlices read = read_folder(folder);
  if (!read.skipped.empty()) warnings.push_back(skipped_warning(folder, read.skipped));
  std::vector<std::vector<Slice>> groups = by_series(folder, std::move(read.slices));
  std::vector<Slice> chosen =
      std::move(groups[choose_series(folder, groups, options.series, warnings)]);
  const std::string series = groups.size() > 1 ? chosen.front().series : std::string();
  // A folder holding one multi-frame file: errors about its frames name the file.
  const fs::path where = chosen.front().frames_in_file > 1 ? chosen.front().file : folder;
  std::vector<Slice> slices = one_time_point(where, std::move(chosen), options, warnings);
  Volume volume = assemble(where, std::move(slices), options.limits, warnings);
  volume.name = volume_name(folder);
  volume.source = folder;
  volume.series = series;
  return volume;
}

std::vector<DicomSeries> list_dicom_series(const std::filesystem::path& folder) {
  std::error_code error;
  if (!fs::is_directory(folder, error)) fail(folder, "not a folder (a DICOM series is a folder)");
  quiet_gdcm();
  std::vector<DicomSeries> out;
  for (const std::vector<Slice>& g : by_series(folder, read_folder(folder).slices))
    out.push_back(describe_series(g));
  return out;
}

Volume load_dicom_file(const std::filesystem::path& path, const VolumeReadOptions& options,
                       std::vector<std::string>& warnings) {
  existing_file_size(path);
  choose_frame(path, 1, options, warnings);
  quiet_gdcm();
  if (file_kind(path) == Kind::other)
    fail(path, "not a DICOM file (no 'DICM' after the 128-byte preamble, no data set)");
  std::vector<Slice> slices = read_file_slices(path);
  if (slices.empty())
    fail(path, "not a DICOM image (no Rows and Columns: a DICOMDIR, report or other object)");
  return assemble(path, std::move(slices), options.limits, warnings);
}

}  // namespace strata
