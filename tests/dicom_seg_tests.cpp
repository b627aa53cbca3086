// DICOM Segmentation objects read into layers: BINARY frames bit-packed across byte boundaries,
// FRACTIONAL thresholds, LABELMAP values, names from the label or the property's code meaning,
// CIELab colours, the grid from the frames' positions (given out of slice order), overlapping
// segments in separate layers, and an Error for each way a file can be wrong. The files are
// written here with GDCM's writer; one more is written by pydicom
// (tests/data/dicom_seg_pydicom.py).
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include <sys/stat.h>

#include <gdcmDataSet.h>
#include <gdcmItem.h>
#include <gdcmSequenceOfItems.h>
#include <gdcmWriter.h>
#include <glm/glm.hpp>

#include "engine/core/error.h"
#include "engine/scene/segmentation.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using namespace strata;

constexpr const char* kSegClass = "1.2.840.10008.5.1.4.1.1.66.4";
constexpr const char* kLabelMapClass = "1.2.840.10008.5.1.4.1.1.66.7";
// 5 x 3 pixels: 15 bits a BINARY frame, so most frames start inside a byte.
constexpr int kColumns = 5, kRows = 3, kPixels = kColumns * kRows;
// Rows along +y, columns along -z: the slice normal is -x.
const glm::dvec3 kRow(0, 1, 0), kColumn(0, 0, -1), kNormal(-1, 0, 0), kBase(10, 20, 30);
constexpr double kStep = 2.5;

// ---- writing a SEG with GDCM

gdcm::DataElement text(uint16_t group, uint16_t element, gdcm::VR vr, std::string value) {
  if (value.size() % 2) value += vr == gdcm::VR::UI ? '\0' : ' ';
  gdcm::DataElement e(gdcm::Tag(group, element));
  e.SetVR(vr);
  e.SetByteValue(value.data(), uint32_t(value.size()));
  return e;
}

gdcm::DataElement us(uint16_t group, uint16_t element, std::vector<uint16_t> values) {
  gdcm::DataElement e(gdcm::Tag(group, element));
  e.SetVR(gdcm::VR::US);
  e.SetByteValue(reinterpret_cast<const char*>(values.data()), uint32_t(2 * values.size()));
  return e;
}

gdcm::DataElement sequence(uint16_t group, uint16_t element,
                           const std::vector<gdcm::DataSet>& items) {
  gdcm::SmartPointer<gdcm::SequenceOfItems> sq = new gdcm::SequenceOfItems;
  sq->SetLengthToUndefined();
  for (const gdcm::DataSet& d : items) {
    gdcm::Item item;
    item.SetVLToUndefined();
    item.SetNestedDataSet(d);
    sq->AddItem(item);
  }
  gdcm::DataElement e(gdcm::Tag(group, element));
  e.SetVR(gdcm::VR::SQ);
  e.SetValue(*sq);
  e.SetVLToUndefined();
  return e;
}

gdcm::DataSet one(const gdcm::DataElement& e) {
  gdcm::DataSet d;
  d.Insert(e);
  return d;
}

std::string ds3(glm::dvec3 p) {
  char out[96];
  std::snprintf(out, sizeof out, "%.4f\\%.4f\\%.4f", p.x, p.y, p.z);
  return out;
}

struct SegmentSpec {
  int number = 0;
  std::string label, meaning;
  std::optional<std::array<uint16_t, 3>> lab;
};

struct FrameSpec {
  int segment = 0;                         // ReferencedSegmentNumber (none: 0)
  double slice = 0;                        // steps from kBase along the normal
  glm::dvec3 offset{0.0};                  // added to its position
  std::array<uint16_t, kPixels> pixels{};  // row by row
};

struct SegSpec {
  std::string sop = kSegClass, type = "BINARY";
  int bits = 1, max_fractional = 0;
  std::vector<SegmentSpec> segments;
  std::vector<FrameSpec> frames;
  bool positions = true, orientation = true;
  std::string between;    // SpacingBetweenSlices
  glm::dvec3 shear{0.0};  // added to the position once a slice (gantry tilt)
};

std::string pixel_data(const SegSpec& spec) {
  std::string bytes;
  if (spec.bits == 1) {
    bytes.assign((spec.frames.size() * kPixels + 7) / 8, '\0');
    size_t bit = 0;
    for (const FrameSpec& f : spec.frames)
      for (uint16_t v : f.pixels) {
        if (v) bytes[bit / 8] = char(bytes[bit / 8] | 1 << (bit % 8));  // first pixel lowest
        ++bit;
      }
  } else {
    for (const FrameSpec& f : spec.frames)
      for (uint16_t v : f.pixels) {
        bytes += char(v & 0xff);
        if (spec.bits == 16) bytes += char(v >> 8);
      }
  }
  if (bytes.size() % 2) bytes += '\0';
  return bytes;
}

gdcm::DataSet segment_item(const SegmentSpec& s) {
  gdcm::DataSet d;
  d.Insert(us(0x0062, 0x0004, {uint16_t(s.number)}));
  if (!s.label.empty()) d.Insert(text(0x0062, 0x0005, gdcm::VR::LO, s.label));
  d.Insert(text(0x0062, 0x0008, gdcm::VR::CS, "MANUAL"));
  gdcm::DataSet code;
  code.Insert(text(0x0008, 0x0100, gdcm::VR::SH, "T-D0050"));
  code.Insert(text(0x0008, 0x0102, gdcm::VR::SH, "SRT"));
  code.Insert(text(0x0008, 0x0104, gdcm::VR::LO, s.meaning));
  d.Insert(sequence(0x0062, 0x000f, {code}));
  if (s.lab) d.Insert(us(0x0062, 0x000d, {(*s.lab)[0], (*s.lab)[1], (*s.lab)[2]}));
  return d;
}

gdcm::DataSet frame_item(const SegSpec& spec, const FrameSpec& f) {
  gdcm::DataSet d;
  if (spec.positions) {
    const glm::dvec3 p = kBase + f.slice * (kStep * kNormal + spec.shear) + f.offset;
    d.Insert(sequence(0x0020, 0x9113, {one(text(0x0020, 0x0032, gdcm::VR::DS, ds3(p)))}));
  }
  if (f.segment)
    d.Insert(sequence(0x0062, 0x000a, {one(us(0x0062, 0x000b, {uint16_t(f.segment)}))}));
  return d;
}

gdcm::DataSet shared_item(const SegSpec& spec) {
  gdcm::DataSet measures;
  measures.Insert(text(0x0028, 0x0030, gdcm::VR::DS, "0.7\\0.5"));  // between rows, columns
  measures.Insert(text(0x0018, 0x0050, gdcm::VR::DS, "2.5"));
  if (!spec.between.empty()) measures.Insert(text(0x0018, 0x0088, gdcm::VR::DS, spec.between));
  gdcm::DataSet d;
  d.Insert(sequence(0x0028, 0x9110, {measures}));
  if (spec.orientation)
    d.Insert(
        sequence(0x0020, 0x9116, {one(text(0x0020, 0x0037, gdcm::VR::DS, "0\\1\\0\\0\\0\\-1"))}));
  return d;
}

gdcm::DataSet seg_data_set(const SegSpec& spec) {
  gdcm::DataSet d;
  d.Insert(text(0x0008, 0x0016, gdcm::VR::UI, spec.sop));
  d.Insert(text(0x0008, 0x0018, gdcm::VR::UI, "1.2.826.0.1.3680043.2.1.99"));
  d.Insert(text(0x0008, 0x0060, gdcm::VR::CS, "SEG"));
  d.Insert(text(0x0028, 0x0008, gdcm::VR::IS, std::to_string(spec.frames.size())));
  d.Insert(us(0x0028, 0x0002, {1}));
  d.Insert(text(0x0028, 0x0004, gdcm::VR::CS, "MONOCHROME2"));
  d.Insert(us(0x0028, 0x0010, {kRows}));
  d.Insert(us(0x0028, 0x0011, {kColumns}));
  const auto bits = uint16_t(spec.bits);
  d.Insert(us(0x0028, 0x0100, {bits}));
  d.Insert(us(0x0028, 0x0101, {bits}));
  d.Insert(us(0x0028, 0x0102, {uint16_t(bits - 1)}));
  d.Insert(us(0x0028, 0x0103, {0}));
  d.Insert(text(0x0062, 0x0001, gdcm::VR::CS, spec.type));
  if (spec.max_fractional) d.Insert(us(0x0062, 0x000e, {uint16_t(spec.max_fractional)}));
  std::vector<gdcm::DataSet> segments, frames;
  for (const SegmentSpec& s : spec.segments) segments.push_back(segment_item(s));
  for (const FrameSpec& f : spec.frames) frames.push_back(frame_item(spec, f));
  d.Insert(sequence(0x0062, 0x0002, segments));
  d.Insert(sequence(0x5200, 0x9229, {shared_item(spec)}));
  d.Insert(sequence(0x5200, 0x9230, frames));
  const std::string pixels = pixel_data(spec);
  gdcm::DataElement data(gdcm::Tag(0x7fe0, 0x0010));
  data.SetVR(spec.bits == 16 ? gdcm::VR::OW : gdcm::VR::OB);
  data.SetByteValue(pixels.data(), uint32_t(pixels.size()));
  d.Insert(data);
  return d;
}

fs::path write_seg(
    const std::string& name, const gdcm::DataSet& data_set,
    gdcm::TransferSyntax::TSType syntax = gdcm::TransferSyntax::ExplicitVRLittleEndian) {
  const fs::path path = test::fresh_folder("dicom_seg", name) / "seg.dcm";
  gdcm::Writer writer;
  writer.SetFileName(path.string().c_str());
  writer.GetFile().SetDataSet(data_set);
  writer.GetFile().GetHeader().SetDataSetTransferSyntax(syntax);
  REQUIRE(writer.Write());
  return path;
}

Segmentation load(const fs::path& path) {
  std::vector<std::string> warnings;
  return load_dicom_seg(path, {}, warnings);
}

std::string error_loading(const SegSpec& spec, const std::string& name) {
  return test::error_of([&] { load(write_seg(name, seg_data_set(spec))); });
}

// ---- the reference scene: three segments on 4 slices, one segment empty

// Voxel (i column, j row, k slice) of each segment.
bool liver(int i, int, int k) {
  return i < 3 && k < 3;
}
bool kidney(int i, int j, int k) {
  return i >= 3 && j != 1 && k == 3;
}
bool tumour(int i, int j, int k) {
  return i >= 2 && j == 1 && k >= 1 && k < 3;
}

using Shape = bool (*)(int, int, int);

// D65 CIELab of sRGB red and green, scaled as DICOM stores them.
std::array<uint16_t, 3> scaled_lab(double l, double a, double b) {
  return {uint16_t(std::lround(l * 65535.0 / 100.0)),
          uint16_t(std::lround((a + 128.0) * 65535.0 / 255.0)),
          uint16_t(std::lround((b + 128.0) * 65535.0 / 255.0))};
}

// Frames of each segment on the slices it touches, listed last slice first.
void add_frames(SegSpec& spec, int segment, Shape shape) {
  for (int k = 3; k >= 0; --k) {
    FrameSpec f{.segment = segment, .slice = double(k)};
    bool any = false;
    for (int j = 0; j < kRows; ++j)
      for (int i = 0; i < kColumns; ++i)
        if (shape(i, j, k)) {
          f.pixels[size_t(j * kColumns + i)] = 1;
          any = true;
        }
    if (any) spec.frames.push_back(f);
  }
}

SegSpec reference_scene() {
  SegSpec spec;
  spec.segments = {{1, "Liver", "Liver", scaled_lab(53.2408, 80.0925, 67.2032)},
                   {2, "", "Kidney", scaled_lab(87.7347, -86.1827, 83.1793)},
                   {3, "Tumour", "Neoplasm", std::nullopt},
                   {4, "Empty", "Nothing", std::nullopt}};
  add_frames(spec, 2, kidney);
  add_frames(spec, 1, liver);
  add_frames(spec, 3, tumour);
  return spec;
}

uint16_t layer_value(const Volume& layer, int i, int j, int k) {
  const size_t index = (size_t(k) * kRows + size_t(j)) * kColumns + size_t(i);
  uint16_t v;
  std::memcpy(&v, layer.voxels.data() + 2 * index, 2);
  return v;
}

void check_region(const Segmentation& seg, const SegmentRegion& region, Shape shape) {
  const Volume& layer = seg.layers[size_t(region.layer)];
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < kRows; ++j)
      for (int i = 0; i < kColumns; ++i) {
        CAPTURE(region.name);
        CAPTURE(i);
        CAPTURE(j);
        CAPTURE(k);
        CHECK((layer_value(layer, i, j, k) == region.value) == shape(i, j, k));
      }
}

bool nowhere(int, int, int) {
  return false;
}

}  // namespace

TEST_CASE("DICOM SEG: BINARY frames straddling bytes read into named, coloured regions") {
  const fs::path path = write_seg("binary", seg_data_set(reference_scene()));
  CHECK(is_dicom_seg(path));
  const Segmentation seg = load(path);
  CHECK(seg.format == "DICOM SEG (BINARY)");
  REQUIRE(seg.regions.size() == 4);
  CHECK(seg.regions[0].name == "Liver");
  CHECK(seg.regions[1].name == "Kidney");  // no SegmentLabel: the code meaning
  CHECK(seg.regions[2].name == "Tumour");
  CHECK(seg.regions[3].name == "Empty");
  for (int r = 0; r < 4; ++r) CHECK(seg.regions[size_t(r)].number == r + 1);
  REQUIRE(seg.regions[0].colour);
  REQUIRE(seg.regions[1].colour);
  CHECK(glm::length(*seg.regions[0].colour - glm::vec3(1, 0, 0)) < 0.01f);
  CHECK(glm::length(*seg.regions[1].colour - glm::vec3(0, 1, 0)) < 0.01f);
  CHECK_FALSE(seg.regions[2].colour);
  // The tumour overlaps the liver: a layer of its own; the kidney shares the liver's.
  REQUIRE(seg.layers.size() == 2);
  CHECK(seg.regions[0].layer == 0);
  CHECK(seg.regions[1].layer == 0);
  CHECK(seg.regions[2].layer == 1);
  check_region(seg, seg.regions[0], liver);
  check_region(seg, seg.regions[1], kidney);
  check_region(seg, seg.regions[2], tumour);
  check_region(seg, seg.regions[3], nowhere);
  // Every anchor lies in its region (the one without voxels has none).
  const std::vector<RegionSummary> summaries = summarise_regions(seg);
  for (size_t r = 0; r < 3; ++r) CHECK(region_contains(seg, seg.regions[r], summaries[r].anchor));
  CHECK(summaries[3].voxels == 0);
}

TEST_CASE("DICOM SEG: the grid follows the frames' positions and orientation") {
  const Segmentation seg = load(write_seg("grid", seg_data_set(reference_scene())));
  const Volume& grid = seg.layers.front();
  CHECK(grid.dims == glm::uvec3(kColumns, kRows, 4));
  CHECK(glm::length(grid.spacing - glm::vec3(0.5f, 0.7f, 2.5f)) < 1e-4f);
  CHECK(glm::length(grid.origin - glm::vec3(kBase)) < 1e-4f);
  CHECK(glm::length(grid.direction[0] - glm::vec3(kRow)) < 1e-5f);
  CHECK(glm::length(grid.direction[1] - glm::vec3(kColumn)) < 1e-5f);
  CHECK(glm::length(grid.direction[2] - glm::vec3(kNormal)) < 1e-5f);
  CHECK(seg.layers[1].dims == grid.dims);
}

TEST_CASE("DICOM SEG: slices no frame covers are empty slices of the grid") {
  SegSpec spec;
  spec.segments = {{1, "Lesion", "Lesion", std::nullopt}};
  FrameSpec f{.segment = 1, .slice = 3};
  f.pixels[7] = 1;
  spec.frames = {f, FrameSpec{.segment = 1, .slice = 0}};
  spec.frames[1].pixels[0] = 1;
  // Without SpacingBetweenSlices the step is the closest frames' distance.
  Segmentation seg = load(write_seg("gaps_unknown", seg_data_set(spec)));
  REQUIRE(seg.layers.size() == 1);
  CHECK(seg.layers[0].dims.z == 2);
  CHECK(seg.layers[0].spacing.z == doctest::Approx(3 * kStep));
  spec.between = "2.5";
  seg = load(write_seg("gaps", seg_data_set(spec)));
  REQUIRE(seg.layers.size() == 1);
  REQUIRE(seg.layers[0].dims.z == 4);
  CHECK(seg.layers[0].spacing.z == doctest::Approx(kStep));
  CHECK(layer_value(seg.layers[0], 0, 0, 0) == 1);
  CHECK(layer_value(seg.layers[0], 2, 1, 3) == 1);
  CHECK(layer_value(seg.layers[0], 2, 1, 1) == 0);
}

TEST_CASE("DICOM SEG: one slice takes SpacingBetweenSlices as its thickness") {
  SegSpec spec;
  spec.segments = {{1, "Lesion", "Lesion", std::nullopt}};
  spec.frames = {FrameSpec{.segment = 1, .slice = 0}};
  spec.between = "4";
  const Segmentation seg = load(write_seg("one_slice", seg_data_set(spec)));
  CHECK(seg.layers.at(0).dims.z == 1);
  CHECK(seg.layers[0].spacing.z == doctest::Approx(4.0));
}

TEST_CASE("DICOM SEG: FRACTIONAL pixels are inside from half the maximum value") {
  SegSpec spec;
  spec.type = "FRACTIONAL";
  spec.bits = 8;
  spec.max_fractional = 200;
  spec.segments = {{1, "Prostate", "Prostate", std::nullopt}};
  FrameSpec f{.segment = 1, .slice = 0};
  f.pixels[0] = 99;
  f.pixels[1] = 100;
  f.pixels[2] = 200;
  spec.frames = {f};
  const Segmentation seg = load(write_seg("fractional", seg_data_set(spec)));
  CHECK(seg.format == "DICOM SEG (FRACTIONAL)");
  REQUIRE(seg.layers.size() == 1);
  CHECK(layer_value(seg.layers[0], 0, 0, 0) == 0);
  CHECK(layer_value(seg.layers[0], 1, 0, 0) == 1);
  CHECK(layer_value(seg.layers[0], 2, 0, 0) == 1);
}

TEST_CASE("DICOM SEG: a LABELMAP's pixel values are its segment numbers") {
  for (const int bits : {8, 16}) {
    CAPTURE(bits);
    const int aorta = bits == 8 ? 200 : 300;
    SegSpec spec;
    spec.sop = kLabelMapClass;
    spec.type = "LABELMAP";
    spec.bits = bits;
    spec.segments = {{1, "Spleen", "Spleen", std::nullopt},
                     {aorta, "Aorta", "Aorta", std::nullopt}};
    FrameSpec second{.slice = 1}, first{.slice = 0};
    first.pixels[0] = 1;
    first.pixels[14] = uint16_t(aorta);
    second.pixels[3] = uint16_t(aorta);
    second.pixels[4] = 7;  // no segment has it
    spec.frames = {second, first};
    const fs::path path = write_seg("labelmap" + std::to_string(bits), seg_data_set(spec));
    CHECK(is_dicom_seg(path));
    std::vector<std::string> warnings;
    const Segmentation seg = load_dicom_seg(path, {}, warnings);
    CHECK(seg.format == "DICOM SEG (LABELMAP)");
    REQUIRE(seg.layers.size() == 1);
    REQUIRE(seg.regions.size() == 2);
    CHECK(seg.regions[1].name == "Aorta");
    CHECK(seg.regions[1].value == aorta);
    CHECK(seg.regions[1].layer == 0);
    CHECK(layer_value(seg.layers[0], 0, 0, 0) == 1);
    CHECK(layer_value(seg.layers[0], 4, 2, 0) == aorta);
    CHECK(layer_value(seg.layers[0], 3, 0, 1) == aorta);
    CHECK(layer_value(seg.layers[0], 4, 0, 1) == 0);
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0].find("left out") != std::string::npos);
  }
}

TEST_CASE("DICOM SEG: an implicit VR file reads as the explicit one") {
  const Segmentation seg = load(write_seg("implicit", seg_data_set(reference_scene()),
                                          gdcm::TransferSyntax::ImplicitVRLittleEndian));
  REQUIRE(seg.regions.size() == 4);
  CHECK(seg.regions[1].name == "Kidney");
  REQUIRE(seg.layers.size() == 2);
  check_region(seg, seg.regions[0], liver);
  check_region(seg, seg.regions[2], tumour);
}

TEST_CASE("DICOM SEG: a sheared stack keeps each slice at its position") {
  SegSpec spec = reference_scene();
  spec.shear = glm::dvec3(0.0, 0.4, 0.0);  // along the rows, 0.4 mm a slice
  const Segmentation seg = load(write_seg("sheared", seg_data_set(spec)));
  const Volume& grid = seg.layers.at(0);
  const glm::vec3 step = grid.direction[2] * grid.spacing.z;
  CHECK(glm::length(step - glm::vec3(kStep * kNormal + spec.shear)) < 1e-4f);
  check_region(seg, seg.regions[0], liver);
  check_region(seg, seg.regions[2], tumour);
}

TEST_CASE("DICOM SEG: a folder holding one SEG file opens it") {
  const fs::path path = write_seg("folder", seg_data_set(reference_scene()));
  CHECK(load(path.parent_path()).regions.size() == 4);
  CHECK_FALSE(is_dicom_seg(path.parent_path()));
}

TEST_CASE("DICOM SEG: what is not a SEG is told apart") {
  SegSpec spec = reference_scene();
  spec.sop = "1.2.840.10008.5.1.4.1.1.2";  // CT Image Storage
  const fs::path ct = write_seg("not_seg", seg_data_set(spec));
  CHECK_FALSE(is_dicom_seg(ct));
  CHECK(test::error_of([&] { load(ct); }).find("not a DICOM Segmentation") != std::string::npos);
  const fs::path text = test::write_file(ct.parent_path() / "notes.dcm", "not DICOM at all");
  CHECK_FALSE(is_dicom_seg(text));
  CHECK_FALSE(is_dicom_seg(ct.parent_path() / "missing.dcm"));
  const fs::path fifo = ct.parent_path() / "pipe.dcm";
  REQUIRE(mkfifo(fifo.c_str(), 0600) == 0);
  CHECK_FALSE(is_dicom_seg(fifo));  // without blocking
  CHECK(test::error_of([&] { load(fifo); }).find("pipe.dcm") != std::string::npos);
  CHECK(test::error_of([&] { load(text); }).find("notes.dcm: not a DICOM file") !=
        std::string::npos);
}

TEST_CASE("DICOM SEG: each fault of a file is an error naming the field") {
  const auto expect = [](const std::string& name, const SegSpec& spec, const std::string& part) {
    const std::string message = error_loading(spec, name);
    CAPTURE(message);
    CHECK(message.find("seg.dcm: ") != std::string::npos);
    CHECK(message.find(part) != std::string::npos);
  };
  SegSpec spec = reference_scene();
  spec.frames[2].segment = 9;
  expect("unknown_segment", spec, "ReferencedSegmentNumber = 9: SegmentSequence has no such");
  spec = reference_scene();
  spec.segments[2].number = 1;
  expect("duplicate", spec, "SegmentNumber 1 is given twice");
  spec = reference_scene();
  spec.bits = 8;
  expect("bits", spec, "BitsAllocated = 8: a BINARY segmentation has 1 bit a pixel");
  spec = reference_scene();
  spec.positions = false;
  expect("no_position", spec, "frame 1: ImagePositionPatient is missing");
  spec = reference_scene();
  spec.orientation = false;
  expect("no_orientation", spec, "frame 1: ImageOrientationPatient is missing");
  spec = reference_scene();
  spec.frames[0].slice = 3.4;  // steps of 2.5 mm, then 3.5 mm
  expect("uneven", spec, "uneven slice spacing");
  spec = reference_scene();
  spec.frames[4].offset = glm::dvec3(0.0, 1.0, 0.0);  // the tumour's slice 2, moved along a row
  expect("moved", spec, "frames 2 and 5 are on one slice but at different places in it");
  spec = reference_scene();
  spec.type = "FRACTIONAL";
  spec.bits = 8;
  expect("no_maximum", spec, "MaximumFractionalValue is missing");
}

TEST_CASE("DICOM SEG: overlapping segments' layers are held to the memory limit") {
  const fs::path path = write_seg("layers", seg_data_set(reference_scene()));
  VolumeReadOptions options;
  options.limits.memory_bytes = 500;  // one layer of 60 voxels and the mask, not two
  std::vector<std::string> warnings;
  const std::string message = test::error_of([&] { load_dicom_seg(path, options, warnings); });
  CHECK(message.find("the segments overlap so that they need 2 layers") != std::string::npos);
}

TEST_CASE("DICOM SEG: missing sequences and short pixel data are errors") {
  const auto expect = [](const std::string& name, const gdcm::DataSet& d, const std::string& part) {
    const std::string message = test::error_of([&] { load(write_seg(name, d)); });
    CAPTURE(message);
    CHECK(message.find(part) != std::string::npos);
  };
  gdcm::DataSet d = seg_data_set(reference_scene());
  d.Remove(gdcm::Tag(0x0062, 0x0002));
  expect("no_segments", d, "SegmentSequence is missing or empty");
  d = seg_data_set(reference_scene());
  d.Replace(text(0x0028, 0x0008, gdcm::VR::IS, "3"));
  expect("frame_count", d, "PerFrameFunctionalGroupsSequence has 6 items, NumberOfFrames is 3");
  d = seg_data_set(reference_scene());
  gdcm::DataElement pixels(gdcm::Tag(0x7fe0, 0x0010));
  pixels.SetVR(gdcm::VR::OB);
  pixels.SetByteValue("\1\2\3\4", 4);
  d.Replace(pixels);
  expect("short_pixels", d, "PixelData has 4 bytes");
  d = seg_data_set(reference_scene());
  d.Remove(gdcm::Tag(0x7fe0, 0x0010));
  expect("no_pixels", d, "PixelData is missing");
}

TEST_CASE("DICOM SEG: a truncated file is an error, never a crash") {
  const fs::path path = write_seg("truncated", seg_data_set(reference_scene()));
  const std::string bytes = test::read_file(path);
  for (size_t keep : {size_t(140), bytes.size() / 3, bytes.size() / 2, bytes.size() - 3}) {
    test::write_file(path, bytes.substr(0, keep));
    CAPTURE(keep);
    CHECK(test::error_of([&] { load(path); }).find("seg.dcm") != std::string::npos);
  }
}

TEST_CASE("DICOM SEG: a file pydicom writes by the standard opens with its names") {
  const fs::path folder = test::fresh_folder("dicom_seg", "pydicom");
  const fs::path script = fs::path(STRATA_TEST_DATA) / "dicom_seg_pydicom.py";
  std::string python;
  for (const char* candidate : {"python3", "/usr/bin/python3"})
    if (std::system((std::string(candidate) + " -c 'import pydicom' >/dev/null 2>&1").c_str()) ==
        0) {
      python = candidate;
      break;
    }
  if (python.empty()) {
    MESSAGE("skipped: python3 cannot import pydicom (scripts/setup.sh installs python3-pydicom)");
    return;
  }
  const fs::path path = folder / "pydicom_seg.dcm";
  REQUIRE(std::system((python + " " + script.string() + " " + path.string()).c_str()) == 0);
  CHECK(is_dicom_seg(path));
  const Segmentation seg = load(path);
  REQUIRE(seg.regions.size() == 2);
  CHECK(seg.regions[0].name == "Left kidney");
  CHECK(seg.regions[1].name == "Spleen");  // from the code meaning
  REQUIRE(seg.layers.size() == 1);
  CHECK(seg.layers[0].dims == glm::uvec3(4, 3, 2));
  CHECK(seg.layers[0].spacing.z == doctest::Approx(3.0));
  // The script's masks: the left kidney on pixels 0..4 of slice 0, the spleen on pixel 11 of
  // both slices.
  size_t kidney = 0, spleen = 0;
  for (size_t v = 0; v < 24; ++v) {
    uint16_t value;
    std::memcpy(&value, seg.layers[0].voxels.data() + 2 * v, 2);
    kidney += value == 1;
    spleen += value == 2;
  }
  CHECK(kidney == 5);
  CHECK(spleen == 2);
}
