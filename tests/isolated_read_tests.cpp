// Assimp and GDCM read in a child process (engine/scene/io/isolated_read.h): what takes a parser
// down (a crash, an assertion, an endless loop, a runaway allocation) is one Error naming the file,
// and what loads, loads as it did in this process.
#include <doctest/doctest.h>

#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "engine/core/error.h"
#include "engine/scene/io/isolated_read.h"
#include "engine/scene/io/mesh_loader.h"
#include "engine/scene/io/volume_loader.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using strata::test::error_of;

const fs::path cache = STRATA_DATA_CACHE;
constexpr uint64_t kMiB = uint64_t{1} << 20;

fs::path output(const std::string& name) {
  return fs::path(STRATA_TEST_OUTPUT) / "isolated_read_tests" / name;
}

fs::path write_file(const std::string& name, const std::string& bytes) {
  return strata::test::write_file(output(name), bytes);
}

bool starts_with(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string u16(uint16_t v) {
  return std::string{char(v & 0xff), char(v >> 8)};
}
std::string u32(uint32_t v) {
  return u16(uint16_t(v & 0xffff)) + u16(uint16_t(v >> 16));
}

// Replaces the value of an explicit-VR element with a short length (VR then a 2-byte length).
void replace_value(std::string& bytes, uint16_t group, uint16_t element, const std::string& vr,
                   const std::string& value) {
  const size_t at = bytes.find(u16(group) + u16(element) + vr);
  REQUIRE(at != std::string::npos);
  const size_t old_length = uint8_t(bytes[at + 6]) | size_t(uint8_t(bytes[at + 7])) << 8;
  bytes.replace(at + 6, 2 + old_length, u16(uint16_t(value.size())) + value);
}

// pydicom's MR_small.dcm (64x64 int16, explicit VR little endian) re-encoded as RLE Lossless, so
// that GDCM's image reader decodes it (strata copies native pixels itself); `palette`: with
// PhotometricInterpretation PALETTE COLOR and no palette, on which that reader asserts.
std::string rle_mr_small(bool palette) {
  std::string bytes = strata::test::read_file(cache / "dicom/MR_small.dcm");
  // The transfer syntax UIDs have the same padded length: the meta group's length holds.
  replace_value(bytes, 0x0002, 0x0010, "UI", std::string("1.2.840.10008.1.2.5\0", 20));
  if (palette) replace_value(bytes, 0x0028, 0x0004, "CS", "PALETTE COLOR ");
  const size_t at = bytes.rfind(u16(0x7fe0) + u16(0x0010) + "OW");
  REQUIRE(at != std::string::npos);
  const std::string pixels = bytes.substr(at + 12, 64 * 64 * 2);
  REQUIRE(pixels.size() == 64 * 64 * 2);
  // One segment of high bytes, one of low bytes; each row one literal run of 64 bytes.
  std::string high, low;
  for (size_t row = 0; row < 64; ++row) {
    high += char(63);
    low += char(63);
    for (size_t column = 0; column < 64; ++column) {
      low += pixels[(row * 64 + column) * 2];
      high += pixels[(row * 64 + column) * 2 + 1];
    }
  }
  std::string fragment = u32(2) + u32(64) + u32(uint32_t(64 + high.size()));
  fragment += std::string(64 - fragment.size(), '\0') + high + low;
  const std::string item = u16(0xfffe) + u16(0xe000);
  bytes.resize(at);  // the pixel data was the last element but for trailing padding
  bytes += u16(0x7fe0) + u16(0x0010) + "OB" + u16(0) + u32(0xffffffff);
  bytes += item + u32(0) + item + u32(uint32_t(fragment.size())) + fragment;
  bytes += u16(0xfffe) + u16(0xe0dd) + u32(0);
  return bytes;
}

const std::string ply_header =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
    "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n";

void check_same_meshes(const std::vector<strata::Mesh>& a, const std::vector<strata::Mesh>& b) {
  REQUIRE(a.size() == b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    CHECK(a[i].name == b[i].name);
    CHECK(a[i].source == b[i].source);
    CHECK(a[i].positions == b[i].positions);
    CHECK(a[i].normals == b[i].normals);
    CHECK(a[i].indices == b[i].indices);
    CHECK(a[i].color == b[i].color);
    CHECK(a[i].transform == b[i].transform);
  }
}

void check_same_volume(const strata::Volume& a, const strata::Volume& b) {
  CHECK(a.name == b.name);
  CHECK(a.source == b.source);
  CHECK(a.type == b.type);
  CHECK(a.dims == b.dims);
  CHECK(a.spacing == b.spacing);
  CHECK(a.origin == b.origin);
  CHECK(a.direction == b.direction);
  CHECK(a.transform == b.transform);
  CHECK(a.voxels == b.voxels);
  CHECK(a.value_range == b.value_range);
  CHECK(a.transfer_function == b.transfer_function);
}

}  // namespace

TEST_SUITE("isolated_read") {
  // GDCM asserts (SIGABRT, caught by the child process) on PALETTE COLOR without a lookup table;
  // the reader now refuses such a file before GDCM decodes it, in a folder too.
  TEST_CASE("isolated_dicom_read_refuses_a_palette_gdcm_would_assert_on") {
    const fs::path path = write_file("palette.dcm", rle_mr_small(true));
    std::vector<std::string> warnings;
    const std::string refused =
        ": PhotometricInterpretation = PALETTE COLOR without a lookup table";
    const std::string message = error_of([&] { strata::load_volume(path, {}, warnings); });
    CHECK(starts_with(message, path.string() + refused));
    const fs::path folder = strata::test::fresh_folder("isolated_read_tests", "palette_series");
    fs::copy_file(path, folder / "slice");
    CHECK(starts_with(error_of([&] { strata::load_volume(folder, {}, warnings); }),
                      (folder / "slice").string() + refused));
  }

  TEST_CASE("isolated_dicom_read_gives_what_the_in_process_read_gives") {
    std::vector<std::string> isolated_warnings, warnings;
    const fs::path ct5n = cache / "dicom/CT5N";
    check_same_volume(strata::load_volume(ct5n, {}, isolated_warnings),
                      strata::load_dicom_series(ct5n, {}, warnings));
    // GDCM's decoder in the child: the RLE copy has MR_small's voxels, and its warning comes back.
    const fs::path rle = write_file("mr_small_rle.dcm", rle_mr_small(false));
    isolated_warnings.clear();
    warnings.clear();
    const strata::Volume from_child = strata::load_volume(rle, {}, isolated_warnings);
    check_same_volume(from_child, strata::load_dicom_file(rle, {}, warnings));
    const strata::Volume native =
        strata::load_dicom_file(cache / "dicom/MR_small.dcm", {}, warnings);
    CHECK(from_child.voxels == native.voxels);
    CHECK(from_child.value_range == native.value_range);
    REQUIRE(isolated_warnings.size() == 1);  // a 2-D image, added by load_volume itself
    CHECK(isolated_warnings[0].find("2-D image") != std::string::npos);
  }

  TEST_CASE("isolated_mesh_read_turns_assimp_crashes_into_errors") {
    // An ASCII PLY cut after its first vertex: an assertion in Assimp's triangulation.
    const fs::path cut = write_file("cut_after_a_vertex.ply", ply_header + "0 0 0");
    CHECK(starts_with(error_of([&] { strata::load_meshes(cut); }),
                      cut.string() + ": the mesh reader (Assimp) crashed (SIGABRT"));
    // A binary PLY whose face list counts in ushort and indexes in float, found by mutating a
    // valid tetrahedron: a bus error.
    const std::string header =
        "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n"
        "property float y\nproperty float z\nelement face 5\n"
        "property list ushort float vertex_indices\nproperty uchar red\nend_header\n";
    const std::string body = std::string(48, '\0') + std::string("\x03\x00", 2) +
                             std::string(16, '\0') + std::string("\x01\x00", 2);
    const fs::path bus = write_file("bus_error.ply", header + body);
    CHECK(error_of([&] { strata::load_meshes(bus); }) ==
          bus.string() + ": the mesh reader (Assimp) crashed (SIGBUS)");
  }

  TEST_CASE("isolated_mesh_read_refuses_a_ply_cut_inside_its_header_at_once") {
    const fs::path path = write_file("cut_in_header.ply", ply_header.substr(0, 70));
    const auto start = std::chrono::steady_clock::now();
    CHECK(error_of([&] { strata::load_meshes(path, {.seconds = 3}); }) ==
          path.string() + ": PLY header: no 'end_header' line (the file is cut short or damaged)");
    CHECK(seconds_since(start) < 1.0);
    // "end_header" run into the line before it: Assimp loops on it too.
    std::string glued = ply_header + "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n";
    glued.replace(glued.find("\nend_header"), 1, ")");
    const fs::path glued_path = write_file("glued_end_header.ply", glued);
    CHECK(starts_with(error_of([&] { strata::load_meshes(glued_path, {.seconds = 3}); }),
                      glued_path.string() + ": PLY header: no 'end_header' line"));
  }

  TEST_CASE("isolated_mesh_read_refuses_a_glb_chunk_longer_than_the_file_at_once") {
    const std::string json = R"({"asset":{"version":"2.0"}})";
    const std::string glb =
        "glTF" + u32(2) + u32(uint32_t(20 + json.size())) + u32(0xfffffff0u) + "JSON" + json;
    const fs::path path = write_file("huge_chunk.glb", glb);
    const auto start = std::chrono::steady_clock::now();
    CHECK(error_of([&] { strata::load_meshes(path); }) ==
          path.string() + ": GLB chunk 0 (JSON): length 4294967280 bytes, the file has " +
              std::to_string(json.size()) + " after the chunk header");
    CHECK(seconds_since(start) < 1.0);
  }

  TEST_CASE("isolated_mesh_read_stops_assimps_out_of_memory_model_at_the_limits") {
    // Assimp's own invalid/OutOfMemory.off (Debian's assimp-testmodels): 309 bytes claiming
    // 3.5 million vertices; unlimited, it runs for minutes and takes gigabytes.
    const fs::path path = cache / "assimp/OutOfMemory.off";
    REQUIRE(fs::exists(path));
    auto start = std::chrono::steady_clock::now();
    CHECK(error_of([&] { strata::load_meshes(path, {.memory_bytes = 256 * kMiB}); }) ==
          path.string() +
              ": the mesh reader (Assimp) needed more than 256 MiB of memory (stopped)");
    CHECK(seconds_since(start) < 5.0);
    start = std::chrono::steady_clock::now();
    CHECK(error_of([&] {
            strata::load_meshes(path, {.seconds = 1, .memory_bytes = 64 * 1024 * kMiB});
          }) == path.string() + ": the mesh reader (Assimp) took more than 1 s (stopped)");
    CHECK(seconds_since(start) < 3.0);
  }

  TEST_CASE("isolated_read_limits_hold_for_any_reader") {
    const fs::path file = write_file("any", "x");
    const auto start = std::chrono::steady_clock::now();
    CHECK(error_of([&] {
            strata::read_meshes_isolated(file, "a spinning reader", {.seconds = 0.5}, [] {
              volatile bool spin = true;
              while (spin) {
              }
              return std::vector<strata::Mesh>{};
            });
          }) == file.string() + ": a spinning reader took more than 0.5 s (stopped)");
    CHECK(seconds_since(start) < 2.0);
    // Memory that is touched as it grows, in steps: the limit stops it whatever the build.
    CHECK(error_of([&] {
            strata::read_meshes_isolated(file, "a greedy reader", {.memory_bytes = 128 * kMiB}, [] {
              std::vector<std::vector<char>> held;
              for (;;) held.emplace_back(16 * kMiB, 'x');
              return std::vector<strata::Mesh>{};
            });
          }) == file.string() + ": a greedy reader needed more than 128 MiB of memory (stopped)");
    CHECK(starts_with(error_of([&] {
                        strata::read_meshes_isolated(file, "a crashing reader", {}, [] {
                          std::raise(SIGSEGV);
                          return std::vector<strata::Mesh>{};
                        });
                      }),
                      file.string() + ": a crashing reader crashed (SIGSEGV"));
    // The reader's own Error comes back as it is.
    CHECK(error_of([&] {
            strata::read_meshes_isolated(file, "a failing reader", {},
                                         [&]() -> std::vector<strata::Mesh> {
                                           throw strata::Error(file.string() + ": field: reason");
                                         });
          }) == file.string() + ": field: reason");
  }

  TEST_CASE("isolated_mesh_read_gives_what_the_in_process_read_gives") {
    const fs::path ply =
        write_file("tetrahedron.ply", ply_header +
                                          "0 0 0\n2 0 0\n0 2 0\n0 0 2\n3 0 2 1\n3 0 1 3\n3 0 3 2\n"
                                          "3 1 2 3\n");
    check_same_meshes(strata::load_meshes(ply), strata::load_meshes_in_process(ply));
    // Two meshes under transformed nodes, with a material.
    const fs::path obj =
        write_file("two.obj",
                   "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\no first\nf 1 3 2\nf 1 2 4\no second\n"
                   "f 1 4 3\nf 2 3 4\n");
    const auto meshes = strata::load_meshes(obj);
    CHECK(meshes.size() == 2);
    check_same_meshes(meshes, strata::load_meshes_in_process(obj));
    // A valid GLB passes the chunk check: a JSON chunk and a BIN chunk of positions and indices.
    const float positions[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const uint16_t indices[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    std::string bin(sizeof positions + sizeof indices, '\0');
    std::memcpy(bin.data(), positions, sizeof positions);
    std::memcpy(bin.data() + sizeof positions, indices, sizeof indices);
    std::string json = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
      "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0},
      "indices": 1}]}], "buffers": [{"byteLength": 72}],
      "bufferViews": [{"buffer": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48,
      "byteLength": 24}], "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4,
      "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]}, {"bufferView": 1,
      "componentType": 5123, "count": 12, "type": "SCALAR"}]})";
    json.resize((json.size() + 3) / 4 * 4, ' ');
    const std::string chunks = u32(uint32_t(json.size())) + "JSON" + json +
                               u32(uint32_t(bin.size())) + std::string("BIN\0", 4) + bin;
    const fs::path glb =
        write_file("tetrahedron.glb", "glTF" + u32(2) + u32(uint32_t(12 + chunks.size())) + chunks);
    const auto from_glb = strata::load_meshes(glb);
    REQUIRE(from_glb.size() == 1);
    CHECK(from_glb[0].triangle_count() == 4);
    check_same_meshes(from_glb, strata::load_meshes_in_process(glb));
  }
}
