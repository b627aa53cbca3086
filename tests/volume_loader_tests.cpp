// The volume readers (engine/scene/io/volume_loader.h): real data from Debian's archive
// (scripts/fetch-data.sh), files written here at run time, and the bad inputs a user's file can
// hold: each must give one strata::Error naming the file and the reason.
#include <doctest/doctest.h>
#include <malloc.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <new>
#include <set>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/core/error.h"
#include "engine/scene/io/volume_loader.h"

// ---- heap accounting
// Global operator new/delete are replaced (for the whole strata_scene_tests binary) to count the
// bytes in use and their peak; they only count, allocation itself is malloc's. Sizes come from
// malloc_usable_size, so unsized deletes are counted exactly too (under ASan it reports the
// requested size).
namespace {
std::atomic<size_t> heap_in_use{0};
std::atomic<size_t> heap_peak{0};

void* counted_alloc(size_t size) noexcept {
  void* p = std::malloc(size == 0 ? 1 : size);
  if (p == nullptr) return nullptr;
  const size_t now = heap_in_use += malloc_usable_size(p);
  size_t peak = heap_peak.load();
  while (now > peak && !heap_peak.compare_exchange_weak(peak, now)) {
  }
  return p;
}
void counted_free(void* p) noexcept {
  if (p == nullptr) return;
  heap_in_use -= malloc_usable_size(p);
  std::free(p);
}
void* counted_alloc_or_throw(size_t size) {
  if (void* p = counted_alloc(size)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(size_t size) {
  return counted_alloc_or_throw(size);
}
void* operator new[](size_t size) {
  return counted_alloc_or_throw(size);
}
void* operator new(size_t size, const std::nothrow_t&) noexcept {
  return counted_alloc(size);
}
void* operator new[](size_t size, const std::nothrow_t&) noexcept {
  return counted_alloc(size);
}
void operator delete(void* p) noexcept {
  counted_free(p);
}
void operator delete[](void* p) noexcept {
  counted_free(p);
}
void operator delete(void* p, size_t) noexcept {
  counted_free(p);
}
void operator delete[](void* p, size_t) noexcept {
  counted_free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  counted_free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  counted_free(p);
}
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using strata::Volume;
using strata::VoxelType;

const fs::path cache = STRATA_DATA_CACHE;

fs::path output_folder(const std::string& name) {
  return strata::test::fresh_folder("volume_loader", name);
}

using strata::test::read_file;
using strata::test::write_file;

void write_gzip(const fs::path& path, const std::string& bytes) {
  gzFile file = gzopen(path.c_str(), "wb");
  REQUIRE(file != nullptr);
  CHECK(gzwrite(file, bytes.data(), static_cast<unsigned>(bytes.size())) == int(bytes.size()));
  CHECK(gzclose(file) == Z_OK);
}

// The values as bytes in the given order.
template <class T>
std::string element_bytes(const std::vector<T>& values, bool big_endian = false) {
  std::string bytes;
  for (T v : values) {
    char raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));
    if (big_endian != (std::endian::native == std::endian::big)) std::reverse(raw, raw + sizeof(T));
    bytes.append(raw, sizeof(T));
  }
  return bytes;
}

std::string load_error(const fs::path& path) {
  return strata::test::error_of([&] { strata::load_volume(path); });
}

// One error whose message names the file and says the reason.
#define CHECK_LOAD_ERROR(file, reason)                        \
  do {                                                        \
    const fs::path where = (file);                            \
    const std::string message = load_error(where);            \
    INFO("message: ", message);                               \
    CHECK(message.find(where.string()) != std::string::npos); \
    CHECK(message.find(reason) != std::string::npos);         \
  } while (false)

void check_matrix(const glm::mat4& actual, const glm::mat4& expected, float tolerance = 1e-5f) {
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) {
      INFO("column ", col, " row ", row);
      CHECK(actual[col][row] == doctest::Approx(expected[col][row]).epsilon(tolerance));
    }
}

glm::mat4 columns(glm::vec3 i, glm::vec3 j, glm::vec3 k, glm::vec3 origin) {
  return glm::mat4(glm::vec4(i, 0.0f), glm::vec4(j, 0.0f), glm::vec4(k, 0.0f),
                   glm::vec4(origin, 1.0f));
}

// ---- NIfTI files built field by field (offsets from nifti1.h and nifti2.h)

struct Header {
  std::string bytes;
  bool big_endian = false;

  template <class T>
  Header& put(size_t offset, T value) {
    const std::string raw = element_bytes(std::vector<T>{value}, big_endian);
    bytes.replace(offset, raw.size(), raw);
    return *this;
  }
  Header& text(size_t offset, std::string_view s) {
    bytes.replace(offset, s.size(), s);
    return *this;
  }
};

// A NIfTI-1 header (348 bytes plus the 4-byte extension flag), datatype and dims set, pixdim 1,
// no qform or sform, no scaling.
Header nifti1(bool big_endian, int16_t datatype, std::array<int16_t, 3> dims) {
  Header h{std::string(352, '\0'), big_endian};
  h.put<int32_t>(0, 348).put<int16_t>(40, 3).put<int16_t>(70, datatype).put<float>(108, 352.0f);
  for (size_t axis = 0; axis < 3; ++axis) h.put<int16_t>(42 + 2 * axis, dims[axis]);
  for (size_t axis = 0; axis < 4; ++axis) h.put<float>(76 + 4 * axis, 1.0f);
  return h.text(344, std::string_view("n+1\0", 4));
}

// A NIfTI-2 header (540 bytes plus the extension flag).
Header nifti2(int16_t datatype, std::array<int64_t, 3> dims) {
  Header h{std::string(544, '\0'), false};
  h.put<int32_t>(0, 540).text(4, std::string_view("n+2\0\r\n\032\n", 8)).put<int16_t>(12, datatype);
  h.put<int64_t>(16, 3).put<int64_t>(168, 544);
  for (size_t axis = 0; axis < 3; ++axis) h.put<int64_t>(24 + 8 * axis, dims[axis]);
  for (size_t axis = 0; axis < 4; ++axis) h.put<double>(104 + 8 * axis, 1.0);
  return h;
}

}  // namespace

TEST_SUITE("loaders") {
  // ---- real data: Colin27 (ch2) and the AAL atlas from Debian's mricron-data

  TEST_CASE("ch2_is_181x217x181_uint8_with_1mm_spacing") {
    const fs::path path = cache / "mricron/ch2.nii.gz";
    REQUIRE_MESSAGE(fs::exists(path), "run scripts/fetch-data.sh");
    const Volume ch2 = strata::load_volume(path);
    CHECK(ch2.dims == glm::uvec3(181, 217, 181));
    CHECK(ch2.type == VoxelType::uint8);
    CHECK(ch2.byte_size() == size_t{181} * 217 * 181);
    CHECK(ch2.spacing == glm::vec3(1.0f));
    CHECK(ch2.name == "ch2");
    CHECK(ch2.source == path);
    CHECK(ch2.value_range.x >= 0.0f);
    CHECK(ch2.value_range.y > 100.0f);
  }

  TEST_CASE("ch2_sform_puts_the_mni_origin_at_voxel_90_125_71_and_spans_181x217x181_mm") {
    const Volume ch2 = strata::load_volume(cache / "mricron/ch2.nii.gz");
    // sform: x = i - 90, y = j - 125, z = k - 71 in RAS; strata's patient space is LPS.
    check_matrix(ch2.index_to_patient(),
                 columns({-1, 0, 0}, {0, -1, 0}, {0, 0, 1}, {90.0f, 125.0f, -71.0f}));
    const glm::vec4 mni_origin = ch2.index_to_patient() * glm::vec4(90, 125, 71, 1);
    CHECK(glm::length(glm::vec3(mni_origin)) < 1e-4f);
    const auto [lo, hi] = ch2.world_bounds();
    CHECK(hi - lo == glm::vec3(180.0f, 216.0f, 180.0f));  // between the outer voxel centres
  }

  TEST_CASE("ch2_loads_with_at_most_two_copies_of_its_voxels") {
    const fs::path path = cache / "mricron/ch2.nii.gz";
    const size_t voxel_bytes = size_t{181} * 217 * 181;
    const size_t before = heap_in_use.load();
    heap_peak.store(before);
    const Volume ch2 = strata::load_volume(path);
    const size_t peak = heap_peak.load() - before;
    INFO("peak heap while loading: ", peak, " bytes");
    CHECK(peak >= voxel_bytes);  // the counter does see the voxels
    CHECK(peak <= 2 * voxel_bytes + (size_t{1} << 20));
  }

  TEST_CASE("aal_matches_ch2_dims_and_holds_116_regions") {
    // aal.nii.gz: 181x217x181 uint8, 0 outside the brain and region numbers 1..116 (aal.nii.txt).
    const Volume aal = strata::load_volume(cache / "mricron/aal.nii.gz");
    CHECK(aal.dims == glm::uvec3(181, 217, 181));
    CHECK(aal.type == VoxelType::uint8);
    CHECK(aal.value_range == glm::vec2(0.0f, 116.0f));
    std::set<std::byte> regions(aal.voxels.begin(), aal.voxels.end());
    regions.erase(std::byte{0});
    CHECK(regions.size() == 116);
  }

  // ---- NIfTI built here

  TEST_CASE("nifti_big_endian_int16_reads_values_and_pixdim_spacing") {
    const fs::path path = output_folder("nifti_be") / "be.nii";
    std::vector<int16_t> values;
    for (int k = 0; k < 5; ++k)
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 3; ++i) values.push_back(int16_t(i + 10 * j + 100 * k - 250));
    Header h = nifti1(true, 4, {3, 4, 5});
    h.put<float>(80, 0.5f).put<float>(84, 0.75f).put<float>(88, 2.5f);
    write_file(path, h.bytes + element_bytes(values, true));

    const Volume v = strata::load_volume(path);
    CHECK(v.dims == glm::uvec3(3, 4, 5));
    CHECK(v.type == VoxelType::int16);
    CHECK(v.value(0, 0, 0) == -250.0f);
    CHECK(v.value(2, 3, 4) == 182.0f);
    CHECK(v.value(1, 2, 3) == 71.0f);
    CHECK(v.value_range == glm::vec2(-250.0f, 182.0f));
    CHECK(v.name == "be");
    // No qform or sform: pixdim scales RAS axes, which LPS flips in x and y.
    check_matrix(v.index_to_patient(), columns({-0.5f, 0, 0}, {0, -0.75f, 0}, {0, 0, 2.5f}, {}));
  }

  TEST_CASE("nifti2_gzip_with_sform_and_scaling_reads_as_float32") {
    const fs::path path = output_folder("nifti2") / "scaled.nii.gz";
    Header h = nifti2(512, {4, 3, 2});                                    // uint16
    h.put<double>(176, 2.0).put<double>(184, -5.0).put<int32_t>(348, 2);  // slope, inter, sform
    const double srow[3][4] = {{0, 0, 1.5, 10}, {-2, 0, 0, 20}, {0, 3, 0, -30}};
    for (size_t row = 0; row < 3; ++row)
      for (size_t col = 0; col < 4; ++col) h.put<double>(400 + 32 * row + 8 * col, srow[row][col]);
    std::vector<uint16_t> values(24);
    for (size_t n = 0; n < values.size(); ++n) values[n] = uint16_t(1000 * n);
    write_gzip(path, h.bytes + element_bytes(values));

    const Volume v = strata::load_volume(path);
    CHECK(v.dims == glm::uvec3(4, 3, 2));
    CHECK(v.type == VoxelType::float32);
    CHECK(v.value(0, 0, 0) == -5.0f);
    CHECK(v.value(3, 2, 1) == 2.0f * 23000.0f - 5.0f);
    CHECK(v.value_range == glm::vec2(-5.0f, 45995.0f));
    CHECK(v.name == "scaled");
    CHECK(v.spacing == glm::vec3(2.0f, 3.0f, 1.5f));
    // The sform with x and y negated (RAS to LPS).
    check_matrix(v.index_to_patient(),
                 columns({0, 2, 0}, {0, 0, 3}, {-1.5f, 0, 0}, {-10, -20, -30}));
  }

  TEST_CASE("nifti_qform_quaternion_gives_the_expected_rotation") {
    const fs::path path = output_folder("nifti_qform") / "qform.nii";
    Header h = nifti1(false, 2, {2, 2, 2});
    // 90 degrees about z (b = c = 0, d = sin 45°), qfac = -1, pixdim 2, 3, 4, offset (10, 20, 30).
    h.put<float>(76, -1.0f).put<float>(80, 2.0f).put<float>(84, 3.0f).put<float>(88, 4.0f);
    h.put<int16_t>(252, 1).put<float>(264, std::sqrt(0.5f));
    h.put<float>(268, 10.0f).put<float>(272, 20.0f).put<float>(276, 30.0f);
    h.put<float>(280, 99.0f);  // an srow that must be ignored: sform_code is 0
    write_file(path, h.bytes + std::string("\1\2\3\4\5\6\7\10", 8));

    const Volume v = strata::load_volume(path);
    CHECK(v.value(1, 1, 1) == 8.0f);
    // RAS: i -> (0, 2, 0), j -> (-3, 0, 0), k -> (0, 0, -4) (qfac); then LPS negates x and y.
    check_matrix(v.index_to_patient(), columns({0, -2, 0}, {3, 0, 0}, {0, 0, -4}, {-10, -20, 30}),
                 1e-4f);
  }

  TEST_CASE("nifti_float64_is_converted_to_float32") {
    const fs::path path = output_folder("nifti_f64") / "f64.nii";
    write_file(path, nifti1(false, 64, {2, 1, 1}).bytes + element_bytes<double>({-1.5, 1e10}));
    const Volume v = strata::load_volume(path);
    CHECK(v.type == VoxelType::float32);
    CHECK(v.value(0, 0, 0) == -1.5f);
    CHECK(v.value(1, 0, 0) == 1e10f);
  }

  TEST_CASE("nifti_bad_inputs_give_one_error_naming_the_file_and_the_reason") {
    const fs::path folder = output_folder("nifti_bad");
    const std::string good = nifti1(false, 4, {3, 4, 5}).bytes;
    const std::string data(120, '\0');
    const auto file = [&](const char* name, const std::string& bytes) {
      write_file(folder / name, bytes);
      return folder / name;
    };
    CHECK_LOAD_ERROR(file("cut.nii", good.substr(0, 200)), "header is truncated: 200 of 348 bytes");
    CHECK_LOAD_ERROR(file("magic.nii", Header{good}.text(344, "xyz").bytes + data), "wrong magic");
    CHECK_LOAD_ERROR(file("notnifti.nii", Header{good}.put<int32_t>(0, 1234).bytes + data),
                     "not a NIfTI file");
    CHECK_LOAD_ERROR(file("short.nii", good + data.substr(0, 50)),
                     "voxel data has 50 bytes, the header needs 120");
    CHECK_LOAD_ERROR(file("rgb.nii", Header{good}.put<int16_t>(70, 128).bytes + data),
                     "datatype 128 is not supported");
    CHECK_LOAD_ERROR(file("zero.nii", Header{good}.put<float>(84, 0.0f).bytes + data),
                     "pixdim[1..3] = 1 0 1: spacing must be positive");
    CHECK_LOAD_ERROR(file("negative.nii", Header{good}.put<float>(88, -2.0f).bytes + data),
                     "spacing must be positive");
    CHECK_LOAD_ERROR(file("4d.nii", Header{good}.put<int16_t>(40, 4).put<int16_t>(48, 2).bytes),
                     "dim[4] = 2: only 3D volumes");
    CHECK_LOAD_ERROR(file("huge.nii", nifti1(false, 2, {32767, 32767, 32767}).bytes),
                     "dim[1..3] = 32767x32767x32767: 35181150961663 bytes of voxels, more than the "
                     "16 GiB");
    const int64_t big = int64_t{1} << 40;
    CHECK_LOAD_ERROR(
        file("overflow.nii", nifti2(2, {big, big, big}).bytes),
        "dim[1..3] = 1099511627776x1099511627776x1099511627776: voxel count overflows");

    write_gzip(folder / "cut.nii.gz", good + data.substr(0, 50));
    CHECK_LOAD_ERROR(folder / "cut.nii.gz", "voxel data ends after 50 of the 120 bytes");
    // A tiny gzip file cannot inflate to a gigabyte: refused before anything is allocated.
    write_gzip(folder / "claims.nii.gz", nifti1(false, 2, {1024, 1024, 1024}).bytes);
    CHECK_LOAD_ERROR(folder / "claims.nii.gz", "the header needs 1073741824");
  }

  // ---- MetaImage

  namespace {

  Volume test_volume(VoxelType type) {
    Volume v;
    v.type = type;
    v.dims = glm::uvec3(5, 4, 3);
    v.spacing = glm::vec3(0.488281f, 1.1f / 3.0f, 2.5f);
    v.origin = glm::vec3(-72.199997f, -143.0f, 1e-7f / 3.0f);
    v.direction = glm::mat3(glm::rotate(glm::mat4(1.0f), 0.3f, glm::normalize(glm::vec3(1, 2, 3))));
    v.voxels.resize(v.voxel_count() * strata::voxel_size(type));
    for (size_t n = 0; n < v.voxels.size(); ++n) v.voxels[n] = std::byte((n * 131 + 7) % 251);
    if (type == VoxelType::float32)  // keep every float finite
      for (size_t n = 3; n < v.voxels.size(); n += 4) v.voxels[n] = std::byte(0x41);
    return v;
  }

  }  // namespace

  TEST_CASE("metaimage_written_by_write_metaimage_reads_back_bit_exact") {
    const fs::path folder = output_folder("metaimage_round_trip");
    for (VoxelType type :
         {VoxelType::uint8, VoxelType::int16, VoxelType::uint16, VoxelType::float32}) {
      const Volume written = test_volume(type);
      for (const char* extension : {".mha", ".mhd"}) {
        for (bool compress : {false, true}) {
          const fs::path path =
              folder / (std::string(strata::to_string(type)) + (compress ? "_z" : "") + extension);
          CAPTURE(path);
          strata::write_metaimage(path, written, compress);
          const Volume read = strata::load_volume(path);
          CHECK(read.type == type);
          CHECK(read.dims == written.dims);
          CHECK(read.voxels == written.voxels);
          CHECK(read.spacing == written.spacing);
          CHECK(read.origin == written.origin);
          CHECK(read.direction == written.direction);
          CHECK(read.name == path.stem().string());
          CHECK(read.value_range.x <= read.value_range.y);
        }
      }
    }
    CHECK(fs::exists(folder / "uint8.raw"));
    CHECK(fs::exists(folder / "uint8_z.zraw"));
  }

  TEST_CASE("metaimage_reads_big_endian_data_and_itk_synonyms") {
    const fs::path path = output_folder("metaimage_synonyms") / "be.mha";
    write_file(path,
               "ObjectType = Image\nNDims = 3\nDimSize = 2 1 1\nElementType = MET_SHORT\n"
               "ElementSize = 2 3 4\nPosition = 1 2 3\nOrientation = 0 1 0 -1 0 0 0 0 1\n"
               "ElementByteOrderMSB = True\nElementDataFile = LOCAL\n" +
                   element_bytes<int16_t>({-300, 513}, true));
    const Volume v = strata::load_volume(path);
    CHECK(v.value(0, 0, 0) == -300.0f);
    CHECK(v.value(1, 0, 0) == 513.0f);
    check_matrix(v.index_to_patient(), columns({0, 2, 0}, {-3, 0, 0}, {0, 0, 4}, {1, 2, 3}));
  }

  TEST_CASE("metaimage_bad_inputs_give_one_error_naming_the_file_and_the_reason") {
    const fs::path folder = output_folder("metaimage_bad");
    const auto header = [](const std::string& dims, const std::string& type,
                           const std::string& more = "") {
      return "ObjectType = Image\nNDims = 3\nDimSize = " + dims + "\nElementType = " + type + "\n" +
             more;
    };
    const auto file = [&](const char* name, const std::string& bytes) {
      write_file(folder / name, bytes);
      return folder / name;
    };
    CHECK_LOAD_ERROR(file("cut.mha", header("2 2 2", "MET_UCHAR").substr(0, 40)),
                     "header is truncated: no ElementDataFile line");
    CHECK_LOAD_ERROR(file("binary.mha", std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16)),
                     "not a MetaImage header");
    CHECK_LOAD_ERROR(file("overflow.mha", header("4294967295 4294967295 4294967295", "MET_UCHAR",
                                                 "ElementDataFile = LOCAL\n")),
                     "DimSize = 4294967295x4294967295x4294967295: voxel count overflows");
    CHECK_LOAD_ERROR(
        file("huge.mha", header("4096 4096 4096", "MET_FLOAT", "ElementDataFile = LOCAL\n")),
        "more than the 16 GiB");
    CHECK_LOAD_ERROR(file("zero.mha", header("2 2 2", "MET_UCHAR",
                                             "ElementSpacing = 1 0 1\nElementDataFile = LOCAL\n") +
                                          std::string(8, 'x')),
                     "ElementSpacing = 1 0 1: spacing must be positive");
    CHECK_LOAD_ERROR(
        file("negative.mha",
             header("2 2 2", "MET_UCHAR", "ElementSpacing = 1 1 -2\nElementDataFile = LOCAL\n") +
                 std::string(8, 'x')),
        "spacing must be positive");
    CHECK_LOAD_ERROR(file("double.mha", header("2 2 2", "MET_DOUBLE", "ElementDataFile = LOCAL\n")),
                     "ElementType = MET_DOUBLE is not supported");
    write_file(folder / "short.raw", std::string(1000, 'x'));
    CHECK_LOAD_ERROR(
        file("short.mhd", header("10 10 10", "MET_FLOAT", "ElementDataFile = short.raw\n")),
        "ElementDataFile 'short.raw' has 1000 bytes, the header needs 4000");
    CHECK_LOAD_ERROR(
        file("missing.mhd", header("2 2 2", "MET_UCHAR", "ElementDataFile = missing.raw\n")),
        "ElementDataFile 'missing.raw': no such file");
    CHECK_LOAD_ERROR(
        file("local_short.mha", header("2 2 2", "MET_SHORT", "ElementDataFile = LOCAL\n") + "abc"),
        "the LOCAL data after the header has 3 bytes, the header needs 16");

    // A compressed stream cut short, and one that is not deflate data at all.
    const fs::path full = folder / "full.mha";
    strata::write_metaimage(full, test_volume(VoxelType::float32), true);
    const std::string bytes = read_file(full);
    CHECK_LOAD_ERROR(file("cut_z.mha", bytes.substr(0, bytes.size() - 100)), "ends after");
    CHECK_LOAD_ERROR(
        file("corrupt_z.mha",
             header("2 2 2", "MET_UCHAR", "CompressedData = True\nElementDataFile = LOCAL\n") +
                 std::string(64, '\x55')),
        "compressed data is corrupt");
  }

  // ---- NRRD

  TEST_CASE("nrrd_attached_raw_reads_values_spacing_from_space_directions_and_origin") {
    const fs::path path = output_folder("nrrd_raw") / "ras.nrrd";
    write_file(path,
               "NRRD0004\n# a comment\ntype: short\ndimension: 3\nspace: right-anterior-superior\n"
               "sizes: 2 2 1\nspace directions: (0,1.5,0) (2,0,0) (0,0,3)\nkinds: domain domain "
               "domain\nendian: big\nencoding: raw\nspace origin: (10,20,30)\nmodality:=CT\n\n" +
                   element_bytes<int16_t>({-7, 1, 2, 32000}, true));
    const Volume v = strata::load_volume(path);
    CHECK(v.dims == glm::uvec3(2, 2, 1));
    CHECK(v.type == VoxelType::int16);
    CHECK(v.value(0, 0, 0) == -7.0f);
    CHECK(v.value(1, 1, 0) == 32000.0f);
    CHECK(v.spacing == glm::vec3(1.5f, 2.0f, 3.0f));
    CHECK(v.name == "ras");
    // RAS space: x and y negated into LPS.
    check_matrix(v.index_to_patient(),
                 columns({0, -1.5f, 0}, {-2, 0, 0}, {0, 0, 3}, {-10, -20, 30}));
  }

  TEST_CASE("nrrd_attached_gzip_reads_back") {
    const fs::path path = output_folder("nrrd_gzip") / "float.nrrd";
    const std::vector<float> values{0.5f, -1.25f, 3.0f, 1e-3f, 7.0f, 8.0f};
    const fs::path packed = path.parent_path() / "packed.gz";
    write_gzip(packed, element_bytes(values));
    write_file(path,
               "NRRD0005\ntype: float\ndimension: 3\nsizes: 3 2 1\nspacings: 0.5 0.25 4\n"
               "endian: little\nencoding: gzip\n\n" +
                   read_file(packed));
    const Volume v = strata::load_volume(path);
    CHECK(v.type == VoxelType::float32);
    CHECK(v.value(1, 0, 0) == -1.25f);
    CHECK(v.value(2, 1, 0) == 8.0f);
    CHECK(v.spacing == glm::vec3(0.5f, 0.25f, 4.0f));
    CHECK(v.value_range == glm::vec2(-1.25f, 8.0f));
  }

  TEST_CASE("nrrd_detached_nhdr_reads_its_data_file") {
    const fs::path folder = output_folder("nrrd_detached");
    write_file(folder / "data.raw", "skipme" + element_bytes<uint16_t>({1, 65535, 3, 4}));
    write_file(folder / "detached.nhdr",
               "NRRD0004\ntype: unsigned short\ndimension: 3\nsizes: 1 2 2\nencoding: raw\n"
               "byte skip: 6\nspace: left-posterior-superior\nspace origin: (1,2,3)\n"
               "space directions: (1,0,0) (0,1,0) (0,0,1)\ndata file: data.raw");  // no newline
    const Volume v = strata::load_volume(folder / "detached.nhdr");
    CHECK(v.type == VoxelType::uint16);
    CHECK(v.value(0, 1, 0) == 65535.0f);
    CHECK(v.value(0, 1, 1) == 4.0f);
    CHECK(v.origin == glm::vec3(1, 2, 3));
    CHECK(v.name == "detached");
  }

  TEST_CASE("nrrd_bad_inputs_give_one_error_naming_the_file_and_the_reason") {
    const fs::path folder = output_folder("nrrd_bad");
    const auto header = [](const std::string& type, const std::string& sizes,
                           const std::string& more = "") {
      return "NRRD0004\ntype: " + type + "\ndimension: 3\nsizes: " + sizes + "\nencoding: raw\n" +
             more + "\n";
    };
    const auto file = [&](const char* name, const std::string& bytes) {
      write_file(folder / name, bytes);
      return folder / name;
    };
    CHECK_LOAD_ERROR(file("magic.nrrd", "NRRX0004\ntype: short\n\n"), "wrong magic 'NRRX0004'");
    CHECK_LOAD_ERROR(file("cut.nrrd", header("short", "2 2 2").substr(0, 30)),
                     "header is truncated");
    CHECK_LOAD_ERROR(file("overflow.nrrd", header("uchar", "4294967295 4294967295 4294967295")),
                     "sizes = 4294967295x4294967295x4294967295: voxel count overflows");
    CHECK_LOAD_ERROR(file("huge.nrrd", header("float", "4096 4096 4096")), "more than the 16 GiB");
    CHECK_LOAD_ERROR(file("zero.nrrd", header("uchar", "1 1 1", "spacings: 1 0 1\n") + "x"),
                     "spacings = 1 0 1: spacing must be positive");
    CHECK_LOAD_ERROR(file("negative.nrrd", header("uchar", "1 1 1", "spacings: 1 1 -1\n") + "x"),
                     "spacing must be positive");
    CHECK_LOAD_ERROR(
        file("flat.nrrd",
             header("uchar", "1 1 1", "space directions: (1,0,0) (0,0,0) (0,0,1)\n") + "x"),
        "space directions: axis 1 has zero length: spacing must be positive");
    CHECK_LOAD_ERROR(file("short.nrrd", header("short", "2 3 4") + std::string(10, 'x')),
                     "the data after the header has 10 bytes, the header needs 48");
    CHECK_LOAD_ERROR(file("double.nrrd", header("double", "1 1 1") + std::string(8, 'x')),
                     "type 'double' is not supported");
    CHECK_LOAD_ERROR(file("bzip.nrrd",
                          "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\n"
                          "encoding: bzip2\n\nx"),
                     "encoding 'bzip2' is not supported");
    CHECK_LOAD_ERROR(file("4d.nrrd", "NRRD0004\ntype: uchar\ndimension: 4\n\n"),
                     "dimension = 4: only 3D volumes");
    CHECK_LOAD_ERROR(file("nodata.nhdr", header("uchar", "1 1 1", "data file: gone.raw\n")),
                     "data file 'gone.raw': no such file");
    const std::string gzip_header =
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 9 9 9\nencoding: gzip\n\n";
    CHECK_LOAD_ERROR(file("gzip_corrupt.nrrd", gzip_header + header("uchar", "1 1 1")),
                     "compressed data is corrupt");
    std::string values(729, '\0');
    for (size_t n = 0; n < values.size(); ++n) values[n] = char(n * n % 251);
    write_gzip(folder / "values.gz", values);
    const std::string packed = read_file(folder / "values.gz");
    CHECK_LOAD_ERROR(file("gzip_cut.nrrd", gzip_header + packed.substr(0, packed.size() / 2)),
                     "the data after the header ends after");
  }

  // ---- DICOM: the CT5N series from Debian's python3-pydicom
  // (pydicom/data/test_files/dicomdirtests/98892001/CT5N: five 16x16 CT slices, 2.5 mm apart).

  namespace {

  const fs::path ct5n = cache / "dicom/CT5N";

  fs::path copy_ct5n(const std::string& name, std::initializer_list<const char*> files) {
    const fs::path folder = output_folder(name);
    for (const char* file : files) fs::copy_file(ct5n / file, folder / file);
    return folder;
  }

  // Replaces the value of a short-VR element with one of the same length (explicit VR little
  // endian, as in CT5N).
  void patch(std::string& bytes, uint16_t group, uint16_t element, const char* vr,
             const std::string& value) {
    const std::string tag = element_bytes<uint16_t>({group, element}) + vr;
    const size_t at = bytes.find(tag);
    REQUIRE(at != std::string::npos);
    REQUIRE(bytes.substr(at + 6, 2) == element_bytes<uint16_t>({uint16_t(value.size())}));
    bytes.replace(at + 8, value.size(), value);
  }
  void patch_us(std::string& bytes, uint16_t group, uint16_t element, uint16_t value) {
    patch(bytes, group, element, "US", element_bytes<uint16_t>({value}));
  }

  }  // namespace

  TEST_CASE("dicom_ct5n_assembles_into_16x16x5_sorted_along_the_normal") {
    const Volume v = strata::load_volume(ct5n);
    CHECK(v.dims == glm::uvec3(16, 16, 5));
    CHECK(v.name == "CT5N");
    CHECK(v.spacing.x == doctest::Approx(0.488281));
    CHECK(v.spacing.y == doctest::Approx(0.488281));
    CHECK(v.spacing.z == doctest::Approx(2.5));  // the step between ImagePositionPatient z values
    CHECK(v.direction == glm::mat3(1.0f));
    // ImagePositionPatient z of files 3353, 3023, 2693, 2392, 2062 (gdcmdump): strictly increasing.
    const float z[5] = {-1.2375f, 1.2625f, 3.7625f, 6.2625f, 8.7625f};
    for (uint32_t k = 0; k < 5; ++k) {
      const glm::vec4 p = v.index_to_patient() * glm::vec4(0, 0, float(k), 1);
      CHECK(p.x == doctest::Approx(-72.199997));
      CHECK(p.y == doctest::Approx(-143.0));
      CHECK(p.z == doctest::Approx(z[k]));
    }
  }

  TEST_CASE("dicom_ct5n_rescale_gives_int16_hounsfield_units_in_place") {
    const Volume v = strata::load_volume(ct5n);
    // Stored int16, RescaleSlope 1, RescaleIntercept -1024: int16 results.
    CHECK(v.type == VoxelType::int16);
    // File 2062 (z = 8.7625, sorted last) stores 974 first: 974 - 1024.
    CHECK(v.value(0, 0, 4) == -50.0f);
    // The first stored pixel of each other file, in sorted order (3353, 3023, 2693, 2392).
    CHECK(v.value(0, 0, 0) == 991.0f - 1024.0f);
    CHECK(v.value(0, 0, 1) == 1034.0f - 1024.0f);
    CHECK(v.value(0, 0, 2) == 975.0f - 1024.0f);
    CHECK(v.value(0, 0, 3) == 998.0f - 1024.0f);
    CHECK(v.value(1, 1, 4) == 994.0f - 1024.0f);
    CHECK(v.value_range == glm::vec2(136.0f - 1024.0f, 1109.0f - 1024.0f));
  }

  TEST_CASE("dicom_series_skips_files_that_are_not_dicom") {
    const fs::path folder = copy_ct5n("dicom_extra", {"2062", "2392", "2693", "3023", "3353"});
    write_file(folder / "README.txt", "five CT slices\n");
    write_file(folder / "empty", "");
    write_file(folder / "noise.bin", std::string(4096, '\x08'));
    CHECK(strata::load_volume(folder).dims == glm::uvec3(16, 16, 5));
  }

  TEST_CASE("dicom_bad_series_give_one_error_naming_the_folder_or_file") {
    const fs::path same = copy_ct5n("dicom_same_position", {"2062", "2392"});
    fs::copy_file(ct5n / "2062", same / "2062-copy");
    CHECK_LOAD_ERROR(same, "2062 and 2062-copy are at the same position");

    const fs::path none = output_folder("dicom_none");
    write_file(none / "notes.txt", "no images here\n");
    CHECK_LOAD_ERROR(none, "no DICOM files");
    CHECK_LOAD_ERROR(output_folder("dicom_empty"), "no DICOM files");

    const fs::path mixed = copy_ct5n("dicom_mixed_size", {"2062", "2392", "2693"});
    std::string bytes = read_file(ct5n / "3023");
    patch_us(bytes, 0x0028, 0x0010, 8);   // Rows
    patch_us(bytes, 0x0028, 0x0011, 32);  // Columns: the pixel data still fits
    write_file(mixed / "3023", bytes);
    CHECK_LOAD_ERROR(mixed, "mixed Rows/Columns: 2062 is 16x16, 3023 is 32x8");

    const fs::path gap = copy_ct5n("dicom_gap", {"2062", "2392", "3023", "3353"});
    CHECK_LOAD_ERROR(gap, "slice spacing is not uniform");

    // Cut inside the pixel data and inside the header: errors, never crashes (Debian's GDCM
    // asserts on the second one, so the loader checks the file's structure before GDCM reads it).
    const fs::path cut = copy_ct5n("dicom_cut_pixels", {"2062", "2392"});
    write_file(cut / "2693", read_file(ct5n / "2693").substr(0, 3700));
    CHECK_LOAD_ERROR(cut, "2693: DICOM file is truncated: element (7fe0,0010) needs 512 bytes");
    const fs::path cut_header = copy_ct5n("dicom_cut_header", {"2062", "2392"});
    write_file(cut_header / "2693", read_file(ct5n / "2693").substr(0, 600));
    CHECK_LOAD_ERROR(cut_header, "2693: DICOM file is truncated");

    const fs::path flat = copy_ct5n("dicom_zero_spacing", {"2062"});
    bytes = read_file(ct5n / "2392");
    patch(bytes, 0x0028, 0x0030, "DS", "0.000000\\0.488281 ");
    write_file(flat / "2392", bytes);
    CHECK_LOAD_ERROR(flat, "2392: PixelSpacing = 0 0.488281: spacing must be positive");

    const fs::path wide = copy_ct5n("dicom_32_bits", {"2062"});
    bytes = read_file(ct5n / "2392");
    patch_us(bytes, 0x0028, 0x0100, 32);  // BitsAllocated
    write_file(wide / "2392", bytes);
    CHECK_LOAD_ERROR(wide, "2392: BitsAllocated = 32: only 8 and 16 are supported");
  }

  TEST_CASE("dicom_rescale_gives_float32_when_fractional_and_applies_per_slice") {
    const fs::path half = output_folder("dicom_half_slope");
    const fs::path per_slice = output_folder("dicom_per_slice_slope");
    for (const char* file : {"2062", "2392", "2693", "3023", "3353"}) {
      std::string bytes = read_file(ct5n / file);
      if (std::string(file) == "2062") patch(bytes, 0x0028, 0x1053, "DS", "2 ");  // RescaleSlope
      write_file(per_slice / file, bytes);
      patch(bytes, 0x0028, 0x1053, "DS", ".5");
      write_file(half / file, bytes);
    }
    const Volume fractional = strata::load_volume(half);
    CHECK(fractional.type == VoxelType::float32);
    CHECK(fractional.value(0, 0, 4) == 974.0f * 0.5f - 1024.0f);
    CHECK(fractional.value(0, 0, 0) == 991.0f * 0.5f - 1024.0f);
    // Only file 2062 (k = 4) has slope 2; integer results that fit stay int16.
    const Volume mixed = strata::load_volume(per_slice);
    CHECK(mixed.type == VoxelType::int16);
    CHECK(mixed.value(0, 0, 4) == 974.0f * 2.0f - 1024.0f);
    CHECK(mixed.value(0, 0, 0) == 991.0f - 1024.0f);
  }

  // ---- load_volume

  TEST_CASE("load_volume_dispatches_by_extension_not_by_content") {
    const fs::path folder = output_folder("dispatch");
    const std::string nifti = nifti1(false, 2, {1, 1, 1}).bytes + "x";
    write_file(folder / "a.nii", nifti);
    CHECK(strata::load_volume(folder / "a.nii").value(0, 0, 0) == float('x'));
    write_file(folder / "a.mha", nifti);
    CHECK_LOAD_ERROR(folder / "a.mha", "not a MetaImage header");
    write_file(folder / "a.nrrd", nifti);
    CHECK_LOAD_ERROR(folder / "a.nrrd", "not a NRRD file");
    write_file(folder / "b.nii", "NRRD0004\n");
    CHECK_LOAD_ERROR(folder / "b.nii", "not a NIfTI file");
    CHECK(strata::load_volume(ct5n).dims.z == 5);  // a folder is a DICOM series
  }

  TEST_CASE("load_volume_refuses_unknown_extensions_and_missing_files") {
    const fs::path folder = output_folder("unknown");
    write_file(folder / "volume.vtk", "# vtk DataFile Version 3.0\n");
    CHECK_LOAD_ERROR(folder / "volume.vtk", "unknown volume extension '.vtk'");
    const fs::path missing = folder / "missing.nii.gz";
    CHECK(load_error(missing) == missing.string() + ": no such file");
    CHECK(load_error(folder / "missing_folder/") ==
          (folder / "missing_folder/").string() + ": no such file");
  }

}  // TEST_SUITE("loaders")
