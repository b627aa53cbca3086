// DICOM Segmentation objects (PS3.3 A.51 and C.8.20): GDCM parses the data set in a child process,
// which then walks the frames into the segmentation's layers and sends those back.
//
// A SEG's frames are planes of one grid: each frame's Plane Position says which slice, its Segment
// Identification which segment (BINARY, FRACTIONAL) or its pixels the segment numbers (LABELMAP).
// Writers leave out frames where a segment has no pixels, so the slice positions may skip steps:
// the grid spans the first to the last, every position a whole number of steps from the first.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <span>

#include <gdcmImageReader.h>

#include "engine/scene/io/dicom_elements.h"
#include "engine/scene/io/dicom_structure.h"
#include "engine/scene/io/volume_io.h"
#include "engine/scene/segmentation.h"

namespace strata {
namespace {

using namespace volume_io;
using namespace dicom;
namespace fs = std::filesystem;

constexpr std::string_view kReader = "the DICOM reader (GDCM)";
constexpr std::string_view kSegmentationStorage = "1.2.840.10008.5.1.4.1.1.66.4";
constexpr std::string_view kLabelMapStorage = "1.2.840.10008.5.1.4.1.1.66.7";

bool is_seg_class(std::string_view uid) {
  return uid == kSegmentationStorage || uid == kLabelMapStorage;
}

enum class SegType { binary, fractional, labelmap };

const char* type_name(SegType type) {
  return type == SegType::binary       ? "BINARY"
         : type == SegType::fractional ? "FRACTIONAL"
                                       : "LABELMAP";
}

struct Segment {
  int number = 0;
  std::string name;
  std::optional<glm::vec3> colour;
};

struct Frame {
  Slice plane;                  // position, cosines, pixel spacing, SliceThickness
  int segment = 0;              // Referenced Segment Number (none in a LABELMAP)
  double between_slices = 0.0;  // SpacingBetweenSlices, 0 where not given
  size_t slice = 0;             // on the grid, once it is built
};

struct SegFile {
  SegType type = SegType::binary;
  uint32_t rows = 0, columns = 0;
  int bits_allocated = 0;
  int max_fractional = 0;
  std::vector<Segment> segments;
  std::vector<Frame> frames;
};

// ---- the Part 10 meta header, read without GDCM

// The value of (0002,0002) MediaStorageSOPClassUID: the meta group is explicit VR little endian
// after the 128-byte preamble and "DICM".
std::optional<std::string> media_storage_class(const fs::path& path) {
  std::error_code error;
  if (!fs::is_regular_file(path, error)) return std::nullopt;  // a FIFO would block the read
  std::ifstream in(path, std::ios::binary);
  char head[132];
  if (!in.read(head, sizeof head) || std::memcmp(head + 128, "DICM", 4) != 0) return std::nullopt;
  for (int element = 0; element < 64; ++element) {
    unsigned char tag[8];
    if (!in.read(reinterpret_cast<char*>(tag), sizeof tag)) return std::nullopt;
    const unsigned group = tag[0] | tag[1] << 8u, number = tag[2] | tag[3] << 8u;
    if (group != 0x0002) return std::nullopt;
    const std::string vr(reinterpret_cast<char*>(tag + 4), 2);
    uint32_t length = tag[6] | tag[7] << 8u;
    if (std::string_view("OBODOFOLOVOWSQSVUCUNURUTUV").find(vr) % 2 == 0) {
      unsigned char wide[4];
      if (!in.read(reinterpret_cast<char*>(wide), 4)) return std::nullopt;
      length = wide[0] | wide[1] << 8u | wide[2] << 16u | uint32_t(wide[3]) << 24u;
    }
    if (length > 4096) return std::nullopt;
    std::string value(length, '\0');
    if (!in.read(value.data(), length)) return std::nullopt;
    if (number == 0x0002) return std::string(trim(value.c_str()));
  }
  return std::nullopt;
}

// ---- segments

// Recommended Display CIELab Value: L* scaled from 0..100 and a*, b* from -128..127 to 0..65535
// (PS3.3 C.10.7.1.1), to sRGB through XYZ with the D65 white that DCMTK (dcmqi, 3D Slicer) uses.
glm::vec3 cielab_to_srgb(const std::vector<double>& scaled) {
  const double l = scaled[0] * 100.0 / 65535.0;
  const double a = scaled[1] * 255.0 / 65535.0 - 128.0;
  const double b = scaled[2] * 255.0 / 65535.0 - 128.0;
  const auto f_inverse = [](double t) {
    return t > 6.0 / 29.0 ? t * t * t : 3.0 * (6.0 / 29.0) * (6.0 / 29.0) * (t - 4.0 / 29.0);
  };
  const double fy = (l + 16.0) / 116.0;
  const glm::dvec3 xyz =
      glm::dvec3(0.95047, 1.0, 1.08883) *
      glm::dvec3(f_inverse(fy + a / 500.0), f_inverse(fy), f_inverse(fy - b / 200.0));
  const glm::dvec3 linear(3.2406 * xyz.x - 1.5372 * xyz.y - 0.4986 * xyz.z,
                          -0.9689 * xyz.x + 1.8758 * xyz.y + 0.0415 * xyz.z,
                          0.0557 * xyz.x - 0.2040 * xyz.y + 1.0570 * xyz.z);
  glm::vec3 rgb;
  for (int c = 0; c < 3; ++c) {
    const double v = std::clamp(linear[c], 0.0, 1.0);
    rgb[c] = float(v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055);
  }
  return rgb;
}

Segment read_segment(const gdcm::File& file, const gdcm::DataSet& item, const fs::path& path,
                     size_t index) {
  const Elements e(file, item, path, concat("SegmentSequence item ", index + 1, ": "));
  Segment segment;
  segment.number = e.integer(0x0062, 0x0004, "SegmentNumber");
  if (segment.number < 1)
    fail(path, concat("SegmentSequence item ", index + 1, ": SegmentNumber = ", segment.number,
                      ": must be 1 to 65535"));
  segment.name = e.text(0x0062, 0x0005);
  if (segment.name.empty())
    with_first_item(item, 0x0062, 0x000f, [&](const gdcm::DataSet& code) {
      segment.name = Elements(file, code, path).text(0x0008, 0x0104);
    });
  if (segment.name.empty()) segment.name = concat("Segment ", segment.number);
  if (e.has(0x0062, 0x000d))
    segment.colour = cielab_to_srgb(e.numbers(0x0062, 0x000d, "RecommendedDisplayCIELabValue", 3));
  return segment;
}

std::vector<Segment> read_segments(const gdcm::File& file, const fs::path& path) {
  const gdcm::Tag tag(0x0062, 0x0002);
  const gdcm::DataSet& data_set = file.GetDataSet();
  gdcm::SmartPointer<gdcm::SequenceOfItems> items;
  if (data_set.FindDataElement(tag)) items = data_set.GetDataElement(tag).GetValueAsSQ();
  if (!items || items->GetNumberOfItems() == 0)
    fail(path, "SegmentSequence is missing or empty: a Segmentation lists its segments there");
  std::vector<Segment> segments;
  std::map<int, size_t> item_of;  // segment number -> item
  for (size_t i = 0; i < items->GetNumberOfItems(); ++i) {
    segments.push_back(read_segment(file, items->GetItem(i + 1).GetNestedDataSet(), path, i));
    const auto [earlier, added] = item_of.emplace(segments.back().number, i);
    if (!added)
      fail(path, concat("SegmentSequence: SegmentNumber ", segments.back().number,
                        " is given twice (items ", earlier->second + 1, " and ", i + 1, ")"));
  }
  return segments;
}

// ---- the pixel format

SegType read_type(const Elements& e, std::string_view sop_class) {
  const std::string type = e.text(0x0062, 0x0001);
  if (type == "BINARY") return SegType::binary;
  if (type == "FRACTIONAL") return SegType::fractional;
  if (type == "LABELMAP" || (type.empty() && sop_class == kLabelMapStorage))
    return SegType::labelmap;
  fail(e.path(), concat("SegmentationType = '", printable(type),
                        "': expected BINARY, FRACTIONAL or LABELMAP"));
}

// A count the standard allows beyond an unsigned short (NumberOfFrames is an integer string).
size_t frame_count(const Elements& e) {
  const double count = e.numbers(0x0028, 0x0008, "NumberOfFrames", 1, 1.0)[0];
  if (!(count >= 1.0 && count <= double(1u << 31)) || count != std::floor(count))
    fail(e.path(), concat("NumberOfFrames = ", count, ": expected a positive whole number"));
  return size_t(count);
}

// BitsAllocated that each type has (PS3.3 C.8.20.2).
const char* bits_of(SegType type) {
  return type == SegType::binary       ? "1 bit"
         : type == SegType::fractional ? "8 bits"
                                       : "8 or 16 bits";
}

void read_pixel_format(const Elements& e, SegFile& seg) {
  const int rows = e.integer(0x0028, 0x0010, "Rows");
  const int columns = e.integer(0x0028, 0x0011, "Columns");
  if (rows < 1 || columns < 1)
    fail(e.path(), concat("Rows x Columns = ", rows, " x ", columns, ": must be positive"));
  seg.rows = uint32_t(rows);
  seg.columns = uint32_t(columns);
  if (const int samples = e.integer(0x0028, 0x0002, "SamplesPerPixel", 1.0); samples != 1)
    fail(e.path(), concat("SamplesPerPixel = ", samples, ": a Segmentation has 1"));
  const int bits = seg.bits_allocated = e.integer(0x0028, 0x0100, "BitsAllocated");
  const bool fits = seg.type == SegType::binary       ? bits == 1
                    : seg.type == SegType::fractional ? bits == 8
                                                      : bits == 8 || bits == 16;
  if (!fits)
    fail(e.path(), concat("BitsAllocated = ", bits, ": a ", type_name(seg.type),
                          " segmentation has ", bits_of(seg.type), " a pixel"));
  if (seg.type != SegType::fractional) return;
  seg.max_fractional = e.integer(0x0062, 0x000e, "MaximumFractionalValue");
  if (seg.max_fractional < 1 || seg.max_fractional > 255)
    fail(e.path(), concat("MaximumFractionalValue = ", seg.max_fractional, ": must be 1 to 255"));
}

// ---- frames

// Frame f's plane and segment, from its Per-frame Functional Groups item, else the shared one,
// else the top level of the data set.
Frame read_frame(const gdcm::File& file, const FunctionalGroups& groups, SegType type, size_t f,
                 const fs::path& path) {
  Frame frame;
  frame.plane.file = path;
  frame.plane.frame = f;
  const std::string context = concat("frame ", f + 1, ": ");  // DICOM counts frames from 1
  const Elements top(file, file.GetDataSet(), path, context);
  const auto read = [&](uint16_t group, uint16_t element,
                        void (*read_into)(const Elements&, Slice&)) {
    const bool found = groups.with_macro(f, group, element, [&](const gdcm::DataSet& attributes) {
      read_into(Elements(file, attributes, path, context), frame.plane);
    });
    if (!found) read_into(top, frame.plane);
  };
  read(0x0020, 0x9113, read_position);
  read(0x0020, 0x9116, read_orientation);
  read(0x0028, 0x9110, read_pixel_measures);
  const auto between = [&](const Elements& e) {
    frame.between_slices = e.numbers(0x0018, 0x0088, "SpacingBetweenSlices", 1, 0.0)[0];
  };
  if (!groups.with_macro(f, 0x0028, 0x9110, [&](const gdcm::DataSet& attributes) {
        between(Elements(file, attributes, path, context));
      }))
    between(top);
  if (type == SegType::labelmap) return frame;
  const bool identified =
      groups.with_macro(f, 0x0062, 0x000a, [&](const gdcm::DataSet& attributes) {
        frame.segment = Elements(file, attributes, path, context)
                            .integer(0x0062, 0x000b, "ReferencedSegmentNumber");
      });
  if (!identified)
    fail(path, context + "SegmentIdentificationSequence (ReferencedSegmentNumber) is missing");
  return frame;
}

void check_frame(const fs::path& path, const SegFile& seg, const Frame& frame) {
  const Slice& first = seg.frames.front().plane;
  const Slice& s = frame.plane;
  const std::string name = concat("frame ", s.frame + 1);
  if (glm::length(s.row_cosine - first.row_cosine) > 1e-3 ||
      glm::length(s.column_cosine - first.column_cosine) > 1e-3)
    fail(path, concat(name, ": ImageOrientationPatient differs from frame 1's"));
  if (glm::length(s.pixel_spacing - first.pixel_spacing) > 1e-3 * glm::length(first.pixel_spacing))
    fail(path, concat(name, ": PixelSpacing differs from frame 1's"));
  if (seg.type == SegType::labelmap) return;
  const bool known = std::any_of(seg.segments.begin(), seg.segments.end(),
                                 [&](const Segment& g) { return g.number == frame.segment; });
  if (!known)
    fail(path, concat(name, ": ReferencedSegmentNumber = ", frame.segment,
                      ": SegmentSequence has no such segment"));
}

void read_frames(const gdcm::File& file, const Elements& e, SegFile& seg) {
  const size_t count = frame_count(e);
  const FunctionalGroups groups(file.GetDataSet());
  if (groups.per_frame_items() != count)
    fail(e.path(), concat("PerFrameFunctionalGroupsSequence has ", groups.per_frame_items(),
                          " items, NumberOfFrames is ", count, ": each frame needs its own"));
  for (size_t f = 0; f < count; ++f) {
    seg.frames.push_back(read_frame(file, groups, seg.type, f, e.path()));
    check_frame(e.path(), seg, seg.frames.back());
  }
}

// ---- the grid

// Frames closer than this along the normal are on one slice.
constexpr double kSameSliceMm = 1e-3;

struct Position {
  double along = 0.0;  // on the slice normal
  glm::dvec3 point{0.0};
  int64_t step = 0;  // slices from the first
};

// The frames' distinct positions in order along the normal; each frame's `slice` is set to its
// position's index.
std::vector<Position> distinct_positions(const fs::path& path, std::vector<Frame>& frames,
                                         glm::dvec3 normal) {
  std::vector<size_t> order(frames.size());
  for (size_t f = 0; f < frames.size(); ++f) order[f] = f;
  const auto along = [&](size_t f) { return glm::dot(frames[f].plane.position, normal); };
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return along(a) < along(b); });
  std::vector<Position> positions;
  size_t first_here = 0;
  for (size_t f : order) {
    if (positions.empty() || along(f) - positions.back().along > kSameSliceMm) {
      positions.push_back({along(f), frames[f].plane.position});
      first_here = f;
    } else if (glm::length(frames[f].plane.position - positions.back().point) > 0.01) {
      fail(path, concat("ImagePositionPatient: frames ", first_here + 1, " and ", f + 1,
                        " are on one slice but at different places in it"));
    }
    frames[f].slice = positions.size() - 1;
  }
  return positions;
}

// How far a position may lie from its place on the grid: 1% of the step, or what rounding of the
// printed positions explains (at most a tenth of the step).
double tolerance(const std::vector<Frame>& frames, glm::dvec3 normal, double step) {
  glm::dvec3 digit = frames.front().plane.position_digit;
  for (const Frame& f : frames) digit = glm::min(digit, f.plane.position_digit);
  const double rounding = glm::dot(digit, glm::abs(normal));
  return std::max({kSameSliceMm, 0.01 * step, std::min(rounding, 0.1 * step)});
}

// The k axis (direction and spacing) through the positions, each set to its steps from the first.
// Refused: positions that are not whole steps apart, or off the line through the first and last.
glm::dvec3 stack_axis(const fs::path& path, std::vector<Position>& positions,
                      const std::vector<Frame>& frames, glm::dvec3 normal) {
  double step = positions[1].along - positions[0].along;
  for (size_t k = 1; k + 1 < positions.size(); ++k)
    step = std::min(step, positions[k + 1].along - positions[k].along);
  // Where no two frames are on neighbouring slices, SpacingBetweenSlices gives the step.
  const double between = frames.front().between_slices;
  if (between > 0.0 && step > 1.5 * between) {
    const double slices = std::round(step / between);
    if (std::fabs(step - slices * between) <= tolerance(frames, normal, between)) step /= slices;
  }
  const double allowed = tolerance(frames, normal, step);
  for (Position& p : positions) {
    const double steps = (p.along - positions[0].along) / step;
    if (steps > 1e6)
      fail(path, concat("ImagePositionPatient: the frames span ", steps, " slices of ", step,
                        " mm: not one grid"));
    p.step = std::llround(steps);
    if (std::fabs(steps - double(p.step)) * step > allowed)
      fail(path, concat("ImagePositionPatient: uneven slice spacing: a slice ",
                        p.along - positions[0].along, " mm from the first is not a whole number",
                        " of ", step, " mm steps (the closest slices' distance)"));
  }
  const glm::dvec3 axis =
      (positions.back().point - positions.front().point) / double(positions.back().step);
  for (const Position& p : positions)
    if (glm::length(p.point - (positions.front().point + double(p.step) * axis)) > allowed)
      fail(path, "ImagePositionPatient: the slices do not lie on one line");
  if (glm::dot(glm::normalize(axis), normal) < std::cos(glm::radians(45.0)))
    fail(path, "ImagePositionPatient: the slices are sheared by more than 45 degrees");
  return axis;
}

// The grid's geometry (its voxels are not allocated) and each frame's slice on it.
Volume build_grid(const fs::path& path, SegFile& seg, const VolumeLimits& limits) {
  const Slice& first = seg.frames.front().plane;
  const glm::dvec3 normal = slice_normal(first);
  std::vector<Position> positions = distinct_positions(path, seg.frames, normal);
  glm::dvec3 axis = normal;
  if (positions.size() > 1) {
    axis = stack_axis(path, positions, seg.frames, normal);
    for (Frame& frame : seg.frames) frame.slice = size_t(positions[frame.slice].step);
  } else {
    const Frame& f = seg.frames.front();
    axis *= f.between_slices > 0.0    ? f.between_slices
            : f.plane.thickness > 0.0 ? f.plane.thickness
                                      : 1.0;
  }
  const std::array<int64_t, 3> dims{seg.columns, seg.rows, positions.back().step + 1};
  checked_voxel_bytes(path, "Columns x Rows x slices", dims, 2, limits);
  Volume grid;
  grid.name = volume_name(path);
  grid.source = path;
  grid.dims = to_dims(dims);
  grid.spacing = glm::vec3(first.pixel_spacing.x, first.pixel_spacing.y, glm::length(axis));
  grid.origin = glm::vec3(positions.front().point);
  grid.direction = glm::mat3(glm::vec3(first.row_cosine), glm::vec3(first.column_cosine),
                             glm::vec3(glm::normalize(axis)));
  check_plausible_geometry(path, "ImagePositionPatient", "ImageOrientationPatient", grid);
  return grid;
}

// ---- pixels

bool native_little_endian(const gdcm::File& file) {
  const gdcm::TransferSyntax syntax = file.GetHeader().GetDataSetTransferSyntax();
  return syntax == gdcm::TransferSyntax::ImplicitVRLittleEndian ||
         syntax == gdcm::TransferSyntax::ExplicitVRLittleEndian ||
         syntax == gdcm::TransferSyntax::DeflatedExplicitVRLittleEndian;
}

// The frames' pixels as stored: bit-packed without padding between frames (BINARY), one byte a
// pixel (FRACTIONAL) or 1 or 2 (LABELMAP). Compressed ones are decoded into `decoded`.
std::span<const std::byte> pixel_bytes(const fs::path& path, const gdcm::File& file,
                                       const SegFile& seg, std::vector<std::byte>& decoded) {
  const uint64_t pixels = uint64_t{seg.rows} * seg.columns * seg.frames.size();
  const uint64_t needed =
      seg.bits_allocated == 1 ? (pixels + 7) / 8 : pixels * uint64_t(seg.bits_allocated / 8);
  const gdcm::Tag tag(0x7fe0, 0x0010);
  if (!file.GetDataSet().FindDataElement(tag)) fail(path, "PixelData is missing");
  const gdcm::ByteValue* value = file.GetDataSet().GetDataElement(tag).GetByteValue();
  if (value && native_little_endian(file)) {
    if (value->GetLength() < needed)
      fail(path, concat("PixelData has ", value->GetLength(), " bytes, Rows x Columns x ",
                        "NumberOfFrames (", seg.columns, " x ", seg.rows, " x ", seg.frames.size(),
                        ") at ", seg.bits_allocated, " bits needs ", needed));
    return {reinterpret_cast<const std::byte*>(value->GetPointer()), size_t(needed)};
  }
  if (seg.bits_allocated == 1)
    fail(path,
         "PixelData: BINARY frames in a compressed or big-endian transfer syntax are not "
         "supported");
  gdcm::ImageReader reader;
  reader.SetFileName(path.string().c_str());
  bool read = false;
  try {
    read = reader.Read() && reader.GetImage().GetBufferLength() == needed;
    if (read) {
      decoded.resize(size_t(needed));
      read = reader.GetImage().GetBuffer(reinterpret_cast<char*>(decoded.data()));
    }
  } catch (const std::exception&) {
    read = false;
  }
  if (!read) fail(path, "PixelData: cannot decode the frames to Rows x Columns x NumberOfFrames");
  return decoded;
}

// Whether pixel p of frame f is inside its segment.
bool inside(const SegFile& seg, std::span<const std::byte> bytes, size_t f, size_t p) {
  const size_t index = f * size_t{seg.rows} * seg.columns + p;
  if (seg.type == SegType::binary)
    return (std::to_integer<unsigned>(bytes[index / 8]) >> (index % 8)) & 1u;
  return 2 * std::to_integer<int>(bytes[index]) >= seg.max_fractional;
}

// Each overlap adds a layer as large as the grid: all of them must fit the memory a volume may
// take, so that a small file cannot ask for many.
void check_layers(const Segmentation& out, const Volume& grid, const VolumeLimits& limits) {
  const uint64_t memory = limits.memory_bytes ? limits.memory_bytes : physical_memory_bytes();
  const uint64_t bytes = out.layers.size() * uint64_t{grid.voxel_count()} * 2;
  if (memory > 0 && bytes + grid.voxel_count() > memory / 2)
    fail(out.source,
         concat("SegmentSequence: the segments overlap so that they need ", out.layers.size(),
                " layers of ", grid.voxel_count() * 2 >> 20,
                " MiB, more than this machine's memory allows (", memory >> 20, " MiB)"));
}

// One segment at a time into a mask on the grid, so that memory holds one mask besides the
// layers however many segments there are.
void add_segments(Segmentation& out, const Volume& grid, const SegFile& seg,
                  std::span<const std::byte> bytes, const VolumeLimits& limits) {
  std::map<int, std::vector<size_t>> frames_of;
  for (size_t f = 0; f < seg.frames.size(); ++f) frames_of[seg.frames[f].segment].push_back(f);
  const size_t frame_pixels = size_t{seg.rows} * seg.columns;
  std::vector<uint8_t> mask(grid.voxel_count());
  for (const Segment& segment : seg.segments) {
    const std::vector<size_t>& frames = frames_of[segment.number];
    for (size_t f : frames) {
      uint8_t* slice = mask.data() + seg.frames[f].slice * frame_pixels;
      for (size_t p = 0; p < frame_pixels; ++p)
        if (inside(seg, bytes, f, p)) slice[p] = 1;
    }
    add_region_voxels(out, grid, mask, {segment.number, 0, 0, segment.name, segment.colour});
    check_layers(out, grid, limits);
    for (size_t f : frames)  // only these slices were written
      std::fill_n(mask.begin() + ptrdiff_t(seg.frames[f].slice * frame_pixels), frame_pixels,
                  uint8_t{0});
  }
}

// The pixel values are segment numbers: one layer, values no segment has left out with a warning.
void fill_label_map(Segmentation& out, const Volume& grid, const SegFile& seg,
                    std::span<const std::byte> bytes, std::vector<std::string>& warnings) {
  std::vector<bool> known(65536, false);
  for (const Segment& s : seg.segments) known[size_t(s.number)] = true;
  Volume layer = empty_layer(grid);
  const size_t frame_pixels = size_t{seg.rows} * seg.columns;
  std::map<unsigned, size_t> unknown;
  for (size_t f = 0; f < seg.frames.size(); ++f) {
    std::byte* slice = layer.voxels.data() + 2 * seg.frames[f].slice * frame_pixels;
    for (size_t p = 0; p < frame_pixels; ++p) {
      const size_t index = f * frame_pixels + p;
      uint16_t value =
          std::to_integer<uint16_t>(bytes[seg.bits_allocated == 8 ? index : 2 * index]);
      if (seg.bits_allocated == 16)
        value = uint16_t(value | std::to_integer<uint16_t>(bytes[2 * index + 1]) << 8);
      if (value == 0) continue;
      if (!known[value]) {
        ++unknown[value];
        continue;
      }
      std::memcpy(slice + 2 * p, &value, 2);
    }
  }
  if (!unknown.empty())
    warnings.push_back(concat(out.source.string(), ": ", unknown.size(),
                              " pixel value(s) that no segment of SegmentSequence has (from ",
                              unknown.begin()->first, ") are left out"));
  out.layers.push_back(std::move(layer));
  for (const Segment& s : seg.segments)
    out.regions.push_back({s.number, 0, s.number, s.name, s.colour});
}

// ---- the file

std::string sop_class(const gdcm::File& file, const fs::path& path) {
  std::string uid = Elements(file, file.GetDataSet(), path).text(0x0008, 0x0016);
  if (uid.empty()) uid = Elements(file, file.GetHeader(), path).text(0x0002, 0x0002);
  return std::string(trim(uid.c_str()));
}

// Runs in the child: GDCM parses the file, then the frames are walked into the layers.
Segmentation read_seg_file(const fs::path& path, const VolumeReadOptions& options,
                           std::vector<std::string>& warnings) {
  quiet_gdcm();
  const Kind kind = file_kind(path);
  if (kind == Kind::other) fail(path, "not a DICOM file (no 'DICM' after the 128-byte preamble)");
  check_structure(path, kind);
  gdcm::Reader reader;
  reader.SetFileName(path.string().c_str());
  bool read = false;
  try {
    read = reader.Read();
  } catch (const std::exception&) {
    read = false;
  }
  if (!read) fail_to_parse(path, reader);
  const gdcm::File& file = reader.GetFile();
  const Elements e(file, file.GetDataSet(), path);
  const std::string uid = sop_class(file, path);
  if (!is_seg_class(uid))
    fail(path, concat("SOPClassUID = '", printable(uid, 64), "': not a DICOM Segmentation (",
                      kSegmentationStorage, " or ", kLabelMapStorage, ")"));
  SegFile seg;
  seg.type = read_type(e, uid);
  seg.segments = read_segments(file, path);
  read_pixel_format(e, seg);
  read_frames(file, e, seg);
  const Volume grid = build_grid(path, seg, options.limits);
  std::vector<std::byte> decoded;
  const std::span<const std::byte> bytes = pixel_bytes(path, file, seg, decoded);
  Segmentation out;
  out.source = path;
  out.format = concat("DICOM SEG (", type_name(seg.type), ")");
  if (seg.type == SegType::labelmap)
    fill_label_map(out, grid, seg, bytes, warnings);
  else
    add_segments(out, grid, seg, bytes, options.limits);
  return out;
}

// A folder holding one SEG file opens that file.
fs::path seg_file_in(const fs::path& folder) {
  std::vector<fs::path> found;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(folder, error)) {
    std::error_code entry_error;
    if (entry.is_regular_file(entry_error) && is_dicom_seg(entry.path()))
      found.push_back(entry.path());
  }
  if (error) fail(folder, concat("cannot list the folder: ", error.message()));
  std::sort(found.begin(), found.end());
  if (found.empty()) fail(folder, "no DICOM Segmentation file in the folder");
  if (found.size() > 1)
    fail(folder, concat("holds ", found.size(), " DICOM Segmentation files (",
                        found[0].filename().string(), ", ", found[1].filename().string(),
                        found.size() > 2 ? ", ..." : "", "): open one of them"));
  return found.front();
}

}  // namespace

bool is_dicom_seg(const std::filesystem::path& path) {
  try {
    const std::optional<std::string> uid = media_storage_class(path);
    return uid && is_seg_class(*uid);
  } catch (const std::exception&) {
    return false;
  }
}

Segmentation load_dicom_seg(const std::filesystem::path& path, const VolumeReadOptions& options,
                            std::vector<std::string>& warnings) {
  std::error_code error;
  const fs::path file = fs::is_directory(path, error) ? seg_file_in(path) : path;
  existing_file_size(file);
  choose_frame(file, 1, options, warnings);
  return read_segmentation_isolated(file, kReader, options.parser, warnings,
                                    [&](std::vector<std::string>& child_warnings) {
                                      return read_seg_file(file, options, child_warnings);
                                    });
}

}  // namespace strata
