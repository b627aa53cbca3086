// 3D Slicer's .seg.nrrd and folders of one mask per structure (engine/scene/io/
// slicer_segmentation.cpp), on files written here: every region's voxels, names, colours and
// geometry, and one error naming the file and the field for each bad input.
#include <doctest/doctest.h>
#include <zlib.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "engine/scene/segmentation.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using strata::Segmentation;
using strata::SegmentRegion;
using strata::test::error_of;
using strata::test::write_file;

// The grid of every file here: 8 x 8 x 4 voxels.
constexpr int nx = 8, ny = 8, nz = 4;
using Shape = std::function<bool(int, int, int)>;

bool sphere(int i, int j, int k) {
  return k <= 2 && (i - 3) * (i - 3) + (j - 3) * (j - 3) + (k - 1) * (k - 1) <= 4;
}
// A square ring in the top slice, open on one side.
bool c_shape(int i, int j, int k) {
  const int ring = std::max(std::abs(2 * i - 9), std::abs(2 * j - 9));
  return k == 3 && ring >= 3 && ring <= 5 && !(i >= 6 && (j == 4 || j == 5));
}
bool box(int i, int j, int k) {
  return i >= 2 && i <= 5 && j >= 2 && j <= 5 && k >= 1 && k <= 2;
}
bool cube(int i, int j, int k) {
  return i >= 6 && j >= 6 && k <= 1;
}

fs::path folder(const std::string& name) {
  return strata::test::fresh_folder("slicer_segmentation", name);
}

std::string gzip(const std::string& data) {
  z_stream z{};
  REQUIRE(deflateInit2(&z, Z_BEST_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) == Z_OK);
  std::string out(deflateBound(&z, uLong(data.size())) + 32, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  z.avail_in = uInt(data.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = uInt(out.size());
  REQUIRE(deflate(&z, Z_FINISH) == Z_STREAM_END);
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

// One layer's bytes (x fastest) of the given element type, or several interleaved (the layer
// fastest): value(layer, i, j, k).
template <class T>
std::string voxels(int layers, const std::function<int(int, int, int, int)>& value) {
  std::string bytes;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (int layer = 0; layer < layers; ++layer) {
          const T v = T(value(layer, i, j, k));
          bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
        }
  return bytes;
}

// The sphere (value 1) and the C (value 3) in one layer.
int sphere_and_c(int, int i, int j, int k) {
  return sphere(i, j, k) ? 1 : c_shape(i, j, k) ? 3 : 0;
}

// Fields of a 3-D file in RAS (strata's world is LPS: x and y change sign).
std::string fields_3d(const std::string& type = "uchar", const std::string& encoding = "raw") {
  return "NRRD0004\ntype: " + type +
         "\ndimension: 3\nspace: right-anterior-superior\nsizes: 8 8 4\n"
         "space directions: (0.5,0,0) (0,0.75,0) (0,0,2)\nkinds: domain domain domain\n"
         "endian: little\nencoding: " +
         encoding + "\nspace origin: (10,20,30)\n";
}

std::string segment(int n, const std::string& id, const std::string& name,
                    const std::string& colour, const std::string& more = "") {
  const std::string prefix = "Segment" + std::to_string(n) + "_";
  std::string text = prefix + "ID:=" + id + "\n";
  if (!name.empty()) text += prefix + "Name:=" + name + "\n";
  if (!colour.empty()) text += prefix + "Color:=" + colour + "\n";
  // "more": further fields without the prefix, one a line ("LabelValue:=3\nLayer:=0").
  for (size_t start = 0; start < more.size();) {
    const size_t end = more.find('\n', start);
    text += prefix + more.substr(start, end - start) + "\n";
    start = end == std::string::npos ? more.size() : end + 1;
  }
  return text;
}

const std::string two_segments =
    segment(0, "Segment_1", "tumour sphere", "0.9 0.1 0.2", "LabelValue:=1\nLayer:=0") +
    segment(1, "Segment_2", "C shaped vessel", "0.25 0.5 1", "LabelValue:=3\nLayer:=0");

fs::path write_3d(const fs::path& path, const std::string& key_values,
                  const std::string& encoding = "raw") {
  const std::string data = voxels<uint8_t>(1, sphere_and_c);
  return write_file(path, fields_3d("uchar", encoding) + key_values + "\n" +
                              (encoding == "gzip" ? gzip(data) : data));
}

Segmentation load(const fs::path& path, std::vector<std::string>& warnings) {
  return strata::load_slicer_segmentation(path, {}, warnings);
}
Segmentation load(const fs::path& path) {
  std::vector<std::string> warnings;
  Segmentation s = load(path, warnings);
  CHECK(warnings.empty());
  return s;
}

// Whether the region holds exactly the voxels of `shape`.
void check_voxels(const Segmentation& s, const SegmentRegion& region, const Shape& shape) {
  INFO("region ", region.name);
  REQUIRE(region.layer >= 0);
  REQUIRE(size_t(region.layer) < s.layers.size());
  const strata::Volume& layer = s.layers[size_t(region.layer)];
  REQUIRE(layer.type == strata::VoxelType::uint16);
  REQUIRE(layer.dims == glm::uvec3(nx, ny, nz));
  int wrong = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        wrong += (layer.value(uint32_t(i), uint32_t(j), uint32_t(k)) == float(region.value)) !=
                 shape(i, j, k);
  CHECK(wrong == 0);
}

void check_colour(const SegmentRegion& region, glm::vec3 colour) {
  REQUIRE(region.colour);
  for (int c = 0; c < 3; ++c) CHECK((*region.colour)[c] == doctest::Approx(colour[c]));
}

// Voxel (2, 3, 1) of the RAS grid above, in LPS.
void check_geometry(const strata::Volume& layer) {
  const glm::vec4 world = layer.index_to_world() * glm::vec4(2, 3, 1, 1);
  CHECK(world.x == doctest::Approx(-11.0f));
  CHECK(world.y == doctest::Approx(-22.25f));
  CHECK(world.z == doctest::Approx(32.0f));
}

void check_two_segments(const Segmentation& s) {
  CHECK(s.format == "3D Slicer segmentation");
  REQUIRE(s.layers.size() == 1);
  REQUIRE(s.regions.size() == 2);
  CHECK(s.regions[0].name == "tumour sphere");
  CHECK(s.regions[0].number == 1);
  CHECK(s.regions[1].name == "C shaped vessel");
  CHECK(s.regions[1].number == 3);
  CHECK(s.regions[1].value == 3);
  check_colour(s.regions[0], {0.9f, 0.1f, 0.2f});
  check_colour(s.regions[1], {0.25f, 0.5f, 1.0f});
  check_voxels(s, s.regions[0], sphere);
  check_voxels(s, s.regions[1], c_shape);
  check_geometry(s.layers[0]);
  // Each anchor lies in its region; the C's centroid (the ring's middle) does not.
  const std::vector<strata::RegionSummary> summaries = strata::summarise_regions(s);
  for (size_t r = 0; r < 2; ++r)
    CHECK(strata::region_contains(s, s.regions[r], summaries[r].anchor));
  const glm::vec4 centroid = s.layers[0].index_to_world() * glm::vec4(4.5f, 4.5f, 3.0f, 1.0f);
  CHECK_FALSE(strata::region_contains(s, s.regions[1], glm::vec3(centroid)));
}

// One error naming the file and saying the reason.
#define CHECK_SEG_ERROR(file, reason)                                     \
  do {                                                                    \
    const fs::path where = (file);                                        \
    std::vector<std::string> warnings;                                    \
    const std::string message = error_of([&] { load(where, warnings); }); \
    INFO("message: ", message);                                           \
    CHECK(message.find(where.string()) != std::string::npos);             \
    CHECK(message.find(reason) != std::string::npos);                     \
  } while (false)

}  // namespace

TEST_CASE("Slicer 3-D seg.nrrd, raw and gzip, gives each segment's name, colour and voxels") {
  const fs::path dir = folder("three_d");
  check_two_segments(load(write_3d(dir / "raw.seg.nrrd", two_segments)));
  check_two_segments(load(write_3d(dir / "gzip.seg.nrrd", two_segments, "gzip")));
}

TEST_CASE("Slicer 4-D seg.nrrd keeps overlapping segments in their own layers") {
  const fs::path dir = folder("four_d");
  // Layer 0: the sphere (1) and a cube (5); layer 1: a box over the sphere (1); layer 2: the C (2).
  const auto value = [](int layer, int i, int j, int k) {
    if (layer == 0) return sphere(i, j, k) ? 1 : cube(i, j, k) ? 5 : 0;
    if (layer == 1) return box(i, j, k) ? 1 : 0;
    return c_shape(i, j, k) ? 2 : 0;
  };
  const std::string header =
      "NRRD0004\ntype: short\ndimension: 4\nspace: right-anterior-superior\nsizes: 3 8 8 4\n"
      "space directions: none (0.5,0,0) (0,0.75,0) (0,0,2)\nkinds: list domain domain domain\n"
      "endian: little\nencoding: raw\nspace origin: (10,20,30)\n" +
      segment(0, "s", "sphere", "1 0 0", "LabelValue:=1\nLayer:=0") +
      segment(1, "b", "box", "0 1 0", "LabelValue:=1\nLayer:=1") +
      segment(2, "c", "C", "0 0 1", "LabelValue:=2\nLayer:=2") +
      segment(3, "q", "cube", "1 1 0", "LabelValue:=5\nLayer:=0") + "\n";
  const Segmentation s =
      load(write_file(dir / "layers.seg.nrrd", header + voxels<int16_t>(3, value)));
  REQUIRE(s.layers.size() == 3);
  REQUIRE(s.regions.size() == 4);
  const int layers[] = {0, 1, 2, 0}, values[] = {1, 1, 2, 5};
  for (size_t r = 0; r < 4; ++r) {
    CHECK(s.regions[r].layer == layers[r]);
    CHECK(s.regions[r].value == values[r]);
    CHECK(s.regions[r].number == values[r]);
  }
  check_voxels(s, s.regions[0], sphere);
  check_voxels(s, s.regions[1], box);
  check_voxels(s, s.regions[2], c_shape);
  check_voxels(s, s.regions[3], cube);
  for (const strata::Volume& layer : s.layers) check_geometry(layer);
}

TEST_CASE("Slicer 4-D seg.nrrd without LabelValue and Layer has each segment in its own layer") {
  const fs::path dir = folder("old_style");
  const auto value = [](int layer, int i, int j, int k) {
    return layer == 0 ? sphere(i, j, k) : box(i, j, k);
  };
  const std::string header =
      "NRRD0004\ntype: unsigned char\ndimension: 4\nspace: left-posterior-superior\n"
      "sizes: 2 8 8 4\nspace directions: none (1,0,0) (0,1,0) (0,0,1)\n"
      "kinds: list domain domain domain\nencoding: gzip\nspace origin: (0,0,0)\n" +
      segment(0, "Segment_1", "sphere", "0.5 0.5 0.5", "Extent:=1 5 1 5 0 2") +
      segment(1, "Segment_2", "box", "", "Extent:=2 5 2 5 1 2") + "\n";
  const Segmentation s =
      load(write_file(dir / "old.seg.nrrd", header + gzip(voxels<uint8_t>(2, value))));
  REQUIRE(s.layers.size() == 2);
  REQUIRE(s.regions.size() == 2);
  CHECK(s.regions[0].layer == 0);
  CHECK(s.regions[1].layer == 1);
  CHECK(s.regions[0].value == 1);
  CHECK(s.regions[1].value == 1);
  CHECK_FALSE(s.regions[1].colour);
  check_voxels(s, s.regions[0], sphere);
  check_voxels(s, s.regions[1], box);
}

TEST_CASE("Slicer seg.nhdr reads its detached data file") {
  const fs::path dir = folder("detached");
  write_file(dir / "labels.raw", voxels<uint16_t>(1, sphere_and_c));
  const std::string header = fields_3d("ushort") + "data file: labels.raw\n" + two_segments;
  check_two_segments(load(write_file(dir / "detached.seg.nhdr", header)));
}

TEST_CASE("Slicer extents: an empty one lists a segment without voxels, voxels outside are cut") {
  const fs::path dir = folder("extents");
  // The sphere spans i 1..5, j 1..5, k 0..2: an extent ending at k = 1 leaves its top out.
  const std::string fields =
      segment(0, "a", "cut sphere", "", "LabelValue:=1\nExtent:=1 5 1 5 0 1") +
      segment(1, "b", "vessel", "", "LabelValue:=3\nExtent:=0 7 0 7 3 3") +
      segment(2, "c", "nothing yet", "", "LabelValue:=4\nExtent:=0 -1 0 -1 0 -1");
  std::vector<std::string> warnings;
  const Segmentation s = load(write_3d(dir / "extents.seg.nrrd", fields), warnings);
  REQUIRE(s.regions.size() == 3);
  check_voxels(s, s.regions[0], [](int i, int j, int k) { return k <= 1 && sphere(i, j, k); });
  check_voxels(s, s.regions[1], c_shape);
  check_voxels(s, s.regions[2], [](int, int, int) { return false; });
  CHECK(s.regions[2].name == "nothing yet");
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0].find("9 voxels of segment 'cut sphere' lie outside its Segment0_Extent") !=
        std::string::npos);
}

TEST_CASE("Slicer segment without a name takes its ID; values no segment has are left out") {
  const fs::path dir = folder("fallbacks");
  std::vector<std::string> warnings;
  const Segmentation s =
      load(write_3d(dir / "unnamed.seg.nrrd", segment(0, "Segment_7", "", "")), warnings);
  REQUIRE(s.regions.size() == 1);
  CHECK(s.regions[0].name == "Segment_7");
  CHECK(s.regions[0].value == 1);
  check_voxels(s, s.regions[0], sphere);
  REQUIRE(warnings.size() == 2);
  CHECK(warnings[0].find("Segment0_Name is missing") != std::string::npos);
  CHECK(warnings[1].find("value(s) 3 that no segment has") != std::string::npos);
  // The C's value is cleared from the layer, not kept under no name.
  CHECK(s.layers[0].value(2, 4, 3) == 0.0f);
}

// As 3D Slicer 5 writes a TotalSegmentator result: its header lines in its order (the teem
// writer's fields, then the key/values sorted, so Segment10 comes before Segment2), an extent
// offset that the geometry already holds, and an empty segment.
TEST_CASE("Slicer real file: a seg.nrrd as 3D Slicer writes it reads back") {
  const fs::path dir = folder("real_file");
  const char* names[] = {"spleen",
                         "kidney_right",
                         "kidney_left",
                         "gallbladder",
                         "liver",
                         "stomach",
                         "pancreas",
                         "adrenal_gland_right",
                         "adrenal_gland_left",
                         "lung_upper_lobe_left",
                         "lung_lower_lobe_left",
                         "esophagus"};
  std::vector<std::string> order;
  for (int n = 0; n < 12; ++n) order.push_back(std::to_string(n));
  std::sort(order.begin(), order.end());
  std::string key_values;
  const std::string tags =
      "TerminologyEntry:Segmentation category and type - 3D Slicer General Anatomy list"
      "~SCT^85756007^Tissue~SCT^85756007^Tissue~^^~Anatomic codes - DICOM master list~^^~^^|";
  for (const std::string& n : order) {
    const int index = std::stoi(n);
    const std::string p = "Segment" + n + "_";
    key_values += p + "Color:=0.517647 0.87451 0.392157\n" + p + "ColorAutoGenerated:=1\n" + p +
                  "Extent:=" + (index == 11 ? "0 -1 0 -1 0 -1" : "0 7 0 7 0 3") + "\n" + p +
                  "ID:=" + names[index] + "\n" + p + "LabelValue:=" + std::to_string(index + 1) +
                  "\n" + p + "Layer:=0\n" + p + "Name:=" + names[index] + "\n" + p +
                  "NameAutoGenerated:=1\n" + p + "Tags:=" + tags + "\n";
  }
  key_values +=
      "Segmentation_ContainedRepresentationNames:=Binary labelmap|Closed surface|\n"
      "Segmentation_ConversionParameters:=Collapse labelmaps|1|Merge the labelmaps into as few "
      "shared labelmaps as possible 1 = created labelmaps will be shared if possible without "
      "overwriting each other.&Compute surface normals|1|Compute surface normals. 1 (default) = "
      "surface normals are computed.&End capping|1|Create end cap to close surface inside "
      "contours on the top and bottom of the structure.\\n0 = leave contours open on surface "
      "exterior.&Smoothing factor|0.5|Smoothing factor. Range: 0.0 (no smoothing) to 1.0 "
      "(strong smoothing).&Threshold fraction|0.5|Determines the threshold that the closed "
      "surface is created at as a fractional value between 0 and 1.&\n"
      "Segmentation_MasterRepresentation:=Binary labelmap\n"
      "Segmentation_ReferenceImageExtentOffset:=35 86 -1\n";
  const std::string header =
      "NRRD0004\n# Complete NRRD file format specification at:\n"
      "# http://teem.sourceforge.net/nrrd/format.html\ntype: unsigned char\ndimension: 3\n"
      "space: left-posterior-superior\nsizes: 8 8 4\n"
      "space directions: (0.78200000524520874,0,0) (0,-0.78200000524520874,0) (0,0,5)\n"
      "kinds: domain domain domain\nencoding: gzip\n"
      "space origin: (-137.63340008258817,106.73968309164046,1243)\n" +
      key_values + "\n";
  const auto label = [](int, int i, int j, int k) { return (i + 8 * j + 64 * k) % 12; };
  const Segmentation s =
      load(write_file(dir / "Segmentation.seg.nrrd", header + gzip(voxels<uint8_t>(1, label))));
  REQUIRE(s.regions.size() == 12);
  for (int n = 0; n < 12; ++n) {
    const SegmentRegion& region = s.regions[size_t(n)];
    CHECK(region.name == names[n]);
    CHECK(region.number == n + 1);
    check_colour(region, {0.517647f, 0.87451f, 0.392157f});
    check_voxels(s, region, [&](int i, int j, int k) { return label(0, i, j, k) == n + 1; });
  }
  const glm::vec4 world = s.layers[0].index_to_world() * glm::vec4(1, 2, 3, 1);
  CHECK(world.x == doctest::Approx(-137.63340008258817 + 0.782));
  CHECK(world.y == doctest::Approx(106.73968309164046 - 2 * 0.782));
  CHECK(world.z == doctest::Approx(1243 + 15));
}

TEST_CASE("Slicer seg.nrrd errors name the file and the field") {
  const fs::path dir = folder("errors");
  const auto with = [&](const std::string& name, const std::string& key_values) {
    return write_3d(dir / (name + ".seg.nrrd"), key_values);
  };
  const std::string s0 = segment(0, "a", "A", "");
  CHECK_SEG_ERROR(with("no_segments", "Segmentation_MasterRepresentation:=Binary labelmap\n"),
                  "no SegmentN_ fields: not a 3D Slicer segmentation; give a names table");
  CHECK_SEG_ERROR(with("bad_number", segment(0, "a", "A", "", "LabelValue:=one")),
                  "Segment0_LabelValue: 'one' is not a list of numbers");
  CHECK_SEG_ERROR(with("fraction", segment(0, "a", "A", "", "Layer:=0.5")), "Segment0_Layer");
  CHECK_SEG_ERROR(with("bad_colour", segment(0, "a", "A", "1.5 0 0")),
                  "Segment0_Color: '1.5 0 0': red, green and blue must be within 0..1");
  CHECK_SEG_ERROR(with("short_extent", segment(0, "a", "A", "", "Extent:=0 1 0 1")),
                  "Segment0_Extent: expected 6 numbers");
  CHECK_SEG_ERROR(with("layer", s0 + segment(1, "b", "B", "", "LabelValue:=3\nLayer:=1")),
                  "Segment1_Layer: 1 is outside the file's layers 0..0");
  CHECK_SEG_ERROR(with("zero", segment(0, "a", "A", "", "LabelValue:=0")),
                  "Segment0_LabelValue: 0 is outside 1..65535");
  CHECK_SEG_ERROR(with("large", segment(0, "a", "A", "", "LabelValue:=65536")),
                  "Segment0_LabelValue: 65536 is outside 1..65535");
  CHECK_SEG_ERROR(with("same", s0 + segment(1, "b", "B", "")),
                  "Segment1_LabelValue: segments 0 and 1 are both value 1 of layer 0");
  CHECK_SEG_ERROR(with("gap", s0 + segment(2, "c", "C", "", "LabelValue:=3")),
                  "Segment2_ID: no Segment1_ID");
  CHECK_SEG_ERROR(with("no_id", s0 + "Segment1_Name:=B\n"), "Segment1_Name: no Segment1_ID");
  CHECK_SEG_ERROR(with("twice", s0 + "Segment0_Name:=again\n"), "Segment0_Name: given twice");
  CHECK_SEG_ERROR(with("fractional", s0 + "Segmentation_MasterRepresentation:=Fractional "
                                          "labelmap\n"),
                  "Segmentation_MasterRepresentation: 'Fractional labelmap'");
  CHECK_SEG_ERROR(with("legacy", s0 + "Segmentation_Extent:=0 7 0 7 0 3\n"),
                  "Segmentation_Extent: the legacy .seg.nrrd layout");

  const std::string data = voxels<uint8_t>(1, sphere_and_c);
  CHECK_SEG_ERROR(write_file(dir / "float.seg.nrrd", fields_3d("float") + s0 + "\n" + data),
                  "type 'float': not an integer type");
  CHECK_SEG_ERROR(write_file(dir / "cut.seg.nrrd", fields_3d() + s0 + "\n" + data.substr(0, 99)),
                  "the data after the header has 99 bytes, the header needs 256");
  const auto negative = [](int, int i, int, int) { return i == 7 ? -1 : 0; };
  CHECK_SEG_ERROR(write_file(dir / "negative.seg.nrrd",
                             fields_3d("int") + s0 + "\n" + voxels<int32_t>(1, negative)),
                  "voxel 7 of layer 0 holds -1: label values are 0..65535");

  // A 4-D file with its layers last (as an image's frames are) is not Slicer's layout.
  const std::string frames_last =
      "NRRD0004\ntype: uchar\ndimension: 4\nsizes: 8 8 4 2\n"
      "space directions: (1,0,0) (0,1,0) (0,0,1) none\nkinds: domain domain domain list\n"
      "encoding: raw\n" +
      s0 + "\n" + voxels<uint8_t>(2, sphere_and_c);
  CHECK_SEG_ERROR(write_file(dir / "last.seg.nrrd", frames_last),
                  "kinds: axis 0 is 'domain': strata reads 4-D segmentations whose first axis is "
                  "the list of layers");
  std::string no_kinds = frames_last;
  no_kinds.erase(no_kinds.find("kinds:"), no_kinds.find("encoding:") - no_kinds.find("kinds:"));
  CHECK_SEG_ERROR(write_file(dir / "last_no_kinds.seg.nrrd", no_kinds),
                  "space directions: axis 3 is 'none': strata reads 4-D segmentations whose first "
                  "axis is the list of layers");
  // Without _Layer a 4-D file's segment N is layer N.
  const std::string missing_layer =
      "NRRD0004\ntype: uchar\ndimension: 4\nsizes: 1 8 8 4\n"
      "space directions: none (1,0,0) (0,1,0) (0,0,1)\nkinds: list domain domain domain\n"
      "encoding: raw\n" +
      s0 + segment(1, "b", "B", "", "LabelValue:=3") + "\n" + voxels<uint8_t>(1, sphere_and_c);
  CHECK_SEG_ERROR(write_file(dir / "missing_layer.seg.nrrd", missing_layer),
                  "Segment1_Layer: missing, so segment 1 is layer 1");
}

// ---- a folder of masks

namespace {

// A NIfTI-1 file (.nii, or gzip-compressed for .nii.gz) of the 8 x 8 x 4 grid: uint8 (datatype 2)
// or float32 (16), its sform placing voxel (0,0,0) at `origin` (RAS) with 1.5 mm voxels.
void write_mask(const fs::path& path, const std::function<float(int, int, int)>& value,
                bool float32 = false, glm::ivec3 dims = {nx, ny, nz},
                glm::vec3 origin = {-20, 10, 5}) {
  std::string h(352, '\0');
  const auto put = [&](size_t offset, auto v) { std::memcpy(h.data() + offset, &v, sizeof v); };
  put(0, int32_t{348});
  put(40, int16_t{3});
  for (int axis = 0; axis < 3; ++axis) put(42 + 2 * size_t(axis), int16_t(dims[axis]));
  put(70, int16_t(float32 ? 16 : 2));
  put(72, int16_t(float32 ? 32 : 8));
  for (int axis = 0; axis < 4; ++axis) put(76 + 4 * size_t(axis), 1.5f);
  put(108, 352.0f);
  put(254, int16_t{1});  // sform_code
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col)
      put(280 + 16 * size_t(row) + 4 * size_t(col), row == col ? 1.5f : 0.0f);
    put(280 + 16 * size_t(row) + 12, origin[row]);
  }
  std::memcpy(h.data() + 344, "n+1", 4);
  std::string data;
  for (int k = 0; k < dims.z; ++k)
    for (int j = 0; j < dims.y; ++j)
      for (int i = 0; i < dims.x; ++i) {
        const float v = value(i, j, k);
        if (float32) {
          data.append(reinterpret_cast<const char*>(&v), 4);
        } else {
          data.push_back(char(uint8_t(v)));
        }
      }
  const bool compressed = path.extension() == ".gz";
  write_file(path, compressed ? gzip(h + data) : h + data);
}

Segmentation load_masks(const fs::path& dir) {
  std::vector<std::string> warnings;
  Segmentation s = strata::load_mask_folder(dir, {}, warnings);
  CHECK(warnings.empty());
  return s;
}

#define CHECK_MASK_ERROR(dir, named, reason)                                                    \
  do {                                                                                          \
    std::vector<std::string> warnings;                                                          \
    const std::string message = error_of([&] { strata::load_mask_folder(dir, {}, warnings); }); \
    INFO("message: ", message);                                                                 \
    CHECK(message.find(fs::path(named).string()) != std::string::npos);                         \
    CHECK(message.find(reason) != std::string::npos);                                           \
  } while (false)

}  // namespace

TEST_CASE("mask folder: each mask is a region named after its file, numbered in name order") {
  const fs::path dir = folder("masks");
  const auto as_value = [](bool (*shape)(int, int, int)) {
    return [shape](int i, int j, int k) { return shape(i, j, k) ? 1.0f : 0.0f; };
  };
  write_mask(dir / "spleen.nii.gz", as_value(sphere));
  write_mask(dir / "kidney_right.nii.gz", as_value(c_shape));
  write_mask(dir / "liver.nii", as_value(box), true);  // overlaps the spleen
  write_file(dir / "statistics.json", "{}");
  const Segmentation s = load_masks(dir);
  REQUIRE(s.regions.size() == 3);
  CHECK(s.regions[0].name == "kidney_right");
  CHECK(s.regions[1].name == "liver");
  CHECK(s.regions[2].name == "spleen");
  for (int n = 0; n < 3; ++n) CHECK(s.regions[size_t(n)].number == n + 1);
  CHECK_FALSE(s.regions[0].colour);
  CHECK(s.layers.size() == 2);
  CHECK(s.regions[1].layer != s.regions[2].layer);
  check_voxels(s, s.regions[0], c_shape);
  check_voxels(s, s.regions[1], box);
  check_voxels(s, s.regions[2], sphere);
  const std::vector<strata::RegionSummary> summaries = strata::summarise_regions(s);
  for (size_t r = 0; r < 3; ++r)
    CHECK(strata::region_contains(s, s.regions[r], summaries[r].anchor));
  // Voxel (2, 3, 1): RAS (-17, 14.5, 6.5) is LPS (17, -14.5, 6.5).
  const glm::vec4 world = s.layers[0].index_to_world() * glm::vec4(2, 3, 1, 1);
  CHECK(world.x == doctest::Approx(17.0f));
  CHECK(world.y == doctest::Approx(-14.5f));
  CHECK(world.z == doctest::Approx(6.5f));
}

TEST_CASE("mask folder: an empty mask is listed without voxels; any one nonzero value is inside") {
  const fs::path dir = folder("mask_values");
  write_mask(dir / "absent.nii.gz", [](int, int, int) { return 0.0f; });
  write_mask(dir / "two_fifty_five.nii.gz",
             [](int i, int j, int k) { return sphere(i, j, k) ? 255.0f : 0.0f; });
  const Segmentation s = load_masks(dir);
  REQUIRE(s.regions.size() == 2);
  check_voxels(s, s.regions[0], [](int, int, int) { return false; });
  check_voxels(s, s.regions[1], sphere);
}

TEST_CASE("mask folder errors name the files") {
  const fs::path root = folder("mask_errors");
  const auto one = [](int i, int j, int k) { return sphere(i, j, k) ? 1.0f : 0.0f; };

  fs::create_directories(root / "empty");
  write_file(root / "empty" / "statistics.json", "{}");
  CHECK_MASK_ERROR(root / "empty", root / "empty", "no .nii or .nii.gz masks in the folder");

  write_mask(root / "grid" / "a.nii.gz", one);
  write_mask(root / "grid" / "b.nii.gz", one, false, {nx, ny, nz + 1});
  CHECK_MASK_ERROR(root / "grid", root / "grid" / "b.nii.gz", "not on the grid of");
  CHECK_MASK_ERROR(root / "grid", root / "grid" / "a.nii.gz", "dims 8x8x5, not 8x8x4");
  write_mask(root / "origin" / "a.nii.gz", one);
  write_mask(root / "origin" / "b.nii.gz", one, false, {nx, ny, nz}, {-20, 10, 6});
  CHECK_MASK_ERROR(root / "origin", root / "origin" / "a.nii.gz", "origin 6 along axis 2, not 5");

  write_mask(
      root / "fraction" / "p.nii", [](int i, int, int) { return i == 3 ? 0.5f : 0.0f; }, true);
  CHECK_MASK_ERROR(root / "fraction", root / "fraction" / "p.nii",
                   "voxel 3 holds 0.5: not a binary mask");
  write_mask(root / "labels" / "l.nii.gz", [](int i, int, int) { return float(i % 3); });
  CHECK_MASK_ERROR(root / "labels", root / "labels" / "l.nii.gz",
                   "holds 1 and 2: not a binary mask");
}
