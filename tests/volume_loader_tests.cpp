// The volume readers (engine/scene/io/volume_loader.h): real data from Debian's archive
// (scripts/fetch-data.sh), files written here at run time, and the bad inputs a user's file can
// hold: each must give one strata::Error naming the file and the reason.
#include <doctest/doctest.h>
#include <malloc.h>
#include <sys/stat.h>
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
#include <limits>
#include <new>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/core/error.h"
#include "engine/scene/io/scene_loader.h"
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
    CHECK_LOAD_ERROR(file("5d.nii", Header{good}.put<int16_t>(40, 5).put<int16_t>(50, 2).bytes),
                     "dim[5] = 2: images of more than 4 dimensions are not supported");
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
    CHECK_LOAD_ERROR(file("5d.nrrd", "NRRD0004\ntype: uchar\ndimension: 5\n\n"),
                     "dimension = 5: expected 2, 3 or 4");
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
    write_file(folder / "noise.bin", std::string(4096, '\x08'));
    CHECK(strata::load_volume(folder).dims == glm::uvec3(16, 16, 5));
  }

  // The default transfer syntax (implicit VR little endian) and zero padding after the last
  // element, which scanners and pydicom write: the structure check must let them through.
  TEST_CASE("dicom_implicit_vr_and_zero_padded_files_open_like_their_explicit_twins") {
    const fs::path explicit_file = cache / "dicom/MR_small.dcm";
    const fs::path implicit_file = cache / "dicom/MR_small_implicit.dcm";
    REQUIRE_MESSAGE(fs::exists(implicit_file), "run scripts/fetch-data.sh");
    std::vector<std::string> warnings;
    const Volume e = strata::load_volume(explicit_file, {}, warnings);
    const Volume i = strata::load_volume(implicit_file, {}, warnings);
    CHECK(i.dims == glm::uvec3(64, 64, 1));
    CHECK(i.dims == e.dims);
    CHECK(i.voxels == e.voxels);
    CHECK(i.index_to_patient() == e.index_to_patient());

    const fs::path padded = output_folder("dicom_padded") / "padded.dcm";
    write_file(padded, strata::test::read_file(explicit_file) + std::string(64, '\0'));
    CHECK(strata::load_volume(padded, {}, warnings).voxels == e.voxels);
    // Padding that is not all zero is still an error.
    write_file(padded, strata::test::read_file(explicit_file) + std::string(8, '\0') + "x");
    CHECK(strata::test::error_of([&] {
            strata::load_volume(padded, {}, warnings);
          }).find("DICOM file is") != std::string::npos);
  }

  TEST_CASE("dicom_bad_series_give_one_error_naming_the_folder_or_file") {
    const fs::path same = copy_ct5n("dicom_same_position", {"2062", "2392"});
    fs::copy_file(ct5n / "2062", same / "2062-copy");
    CHECK_LOAD_ERROR(same,
                     "2062 and 2062-copy are at the same position (8.7625 mm along the normal): "
                     "the same image twice (one SOPInstanceUID), a copied file; remove one");

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

  // A folder as an archive exports it: the five CT slices of one series and an MR slice of
  // another. Listed both; opened by default the largest 3-D one with a warning naming the other,
  // either by its SeriesNumber or UID, and the choice kept when the scene is saved.
  TEST_CASE("dicom_folder_with_two_series_lists_both_and_opens_either") {
    const fs::path folder = copy_ct5n("dicom_two_series", {"2062", "2392", "2693", "3023", "3353"});
    fs::copy_file(cache / "dicom/MR_small.dcm", folder / "MR_small.dcm");
    const std::vector<strata::DicomSeries> series = strata::list_dicom_series_isolated(folder);
    REQUIRE(series.size() == 2);
    CHECK(series[0].number == "5");
    CHECK(series[0].modality == "CT");
    CHECK(series[0].images == 5);
    CHECK(series[0].orientation == "axial");
    CHECK(series[0].description == "SmartScore - Gated 0.5 sec");
    CHECK(series[1].number == "1");
    CHECK(series[1].modality == "MR");
    CHECK(series[1].columns == 64);
    CHECK(series[1].images == 1);
    CHECK(series[0].uid != series[1].uid);

    std::vector<std::string> warnings;
    const Volume chosen = strata::load_volume(folder, {}, warnings);
    CHECK(chosen.dims == glm::uvec3(16, 16, 5));
    CHECK(chosen.voxels == strata::load_volume(ct5n).voxels);
    CHECK(chosen.series == series[0].uid);
    REQUIRE(!warnings.empty());
    CHECK(warnings[0] == folder.string() +
                             ": holds 2 series; opened series 5 'SmartScore - Gated 0.5 sec' "
                             "(CT, 16x16x5), the largest 3-D image; the others: series 1 (MR, "
                             "64x64x1). --series NUMBER or UID (or the scene's \"series\") opens "
                             "another; strata info " +
                             folder.string() + " lists them");
    const Volume mr = strata::load_volume(cache / "dicom/MR_small.dcm", {}, warnings);
    for (const std::string& wanted : {std::string("1"), series[1].uid}) {
      CAPTURE(wanted);
      warnings.clear();
      const Volume v = strata::load_volume(folder, {.series = wanted}, warnings);
      CHECK(v.voxels == mr.voxels);
      CHECK(v.index_to_patient() == mr.index_to_patient());
      CHECK(v.series == series[1].uid);
      for (const std::string& w : warnings) CHECK(w.find("holds 2 series") == std::string::npos);
    }
    const auto error_with = [](const fs::path& path, const std::string& wanted) {
      std::vector<std::string> ignored;
      return strata::test::error_of(
          [&] { strata::load_volume(path, {.series = wanted}, ignored); });
    };
    CHECK(error_with(folder, "9") ==
          folder.string() +
              ": no series '9' (SeriesNumber or SeriesInstanceUID); the folder holds: series 5 "
              "'SmartScore - Gated 0.5 sec' (CT, 16x16x5); series 1 (MR, 64x64x1)");
    CHECK(error_with(cache / "dicom/MR_small.dcm", "1").find("is chosen in a DICOM folder only") !=
          std::string::npos);

    // Saved, the scene of the folder opens the same series again.
    const strata::Scene scene = strata::load_scene(folder, {.series = "1"});
    const fs::path saved = output_folder("dicom_two_series_scene") / "scene.json";
    strata::save_scene_json(saved, scene);
    const strata::Scene back = strata::load_scene(saved);
    REQUIRE(back.volumes.size() == 1);
    CHECK(back.volumes[0].voxels == mr.voxels);
  }

  // A Siemens mosaic tiles its slices into one image: refused, never shown as one slice.
  TEST_CASE("dicom_siemens_mosaic_is_refused_with_the_way_out") {
    const fs::path mosaic = cache / "dicom/siemens_mosaic.dcm";
    REQUIRE_MESSAGE(fs::exists(mosaic), "run scripts/fetch-data.sh");
    std::vector<std::string> warnings;
    const std::string error =
        strata::test::error_of([&] { strata::load_volume(mosaic, {}, warnings); });
    CHECK(error.starts_with(mosaic.string() +
                            ": a Siemens mosaic (ImageType ORIGINAL\\PRIMARY\\"
                            "DIFFUSION\\NONE\\ND\\MOSAIC): its slices are tiles"));
    CHECK(error.find("dcm2niix") != std::string::npos);
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

  // ---- enhanced multi-frame DICOM

  namespace {

  // The volume and the warnings of the full load_volume.
  struct Loaded {
    Volume volume;
    std::vector<std::string> warnings;
  };

  Loaded load_with_warnings(const fs::path& path, std::optional<int> frame = std::nullopt) {
    Loaded loaded;
    loaded.volume = strata::load_volume(path, {.frame = frame}, loaded.warnings);
    return loaded;
  }

  std::string frame_error(const fs::path& path, int frame) {
    return strata::test::error_of([&] { load_with_warnings(path, frame); });
  }

  // DICOM written here: explicit VR little endian, every length defined.
  std::string dicom_element(uint16_t group, uint16_t element, const std::string& vr,
                            std::string value) {
    if (value.size() % 2 == 1) value += vr == "UI" || vr == "OB" || vr == "OW" ? '\0' : ' ';
    std::string bytes = element_bytes<uint16_t>({group, element}) + vr;
    if (vr == "SQ" || vr == "OB" || vr == "OW")
      return bytes + std::string(2, '\0') + element_bytes<uint32_t>({uint32_t(value.size())}) +
             value;
    return bytes + element_bytes<uint16_t>({uint16_t(value.size())}) + value;
  }

  std::string dicom_us(uint16_t group, uint16_t element, uint16_t value) {
    return dicom_element(group, element, "US", element_bytes<uint16_t>({value}));
  }

  // A sequence of items, each given as its elements.
  std::string dicom_sequence(uint16_t group, uint16_t element,
                             const std::vector<std::string>& items) {
    std::string value;
    for (const std::string& item : items)
      value += element_bytes<uint16_t>({0xfffe, 0xe000}) +
               element_bytes<uint32_t>({uint32_t(item.size())}) + item;
    return dicom_element(group, element, "SQ", value);
  }

  // A functional group macro: a sequence of one item.
  std::string macro(uint16_t group, uint16_t element, const std::string& attributes) {
    return dicom_sequence(group, element, {attributes});
  }

  std::string part10(const std::string& transfer_syntax, const std::string& data_set) {
    const std::string meta = dicom_element(0x0002, 0x0001, "OB", std::string("\0\1", 2)) +
                             dicom_element(0x0002, 0x0002, "UI", "1.2.840.10008.5.1.4.1.1.2.1") +
                             dicom_element(0x0002, 0x0003, "UI", "1.2.826.0.1.3680043.2.1") +
                             dicom_element(0x0002, 0x0010, "UI", transfer_syntax);
    return std::string(128, '\0') + "DICM" +
           dicom_element(0x0002, 0x0000, "UL", element_bytes<uint32_t>({uint32_t(meta.size())})) +
           meta + data_set;
  }

  // One frame of the enhanced CT built from CT5N: the slice file it takes its position and pixels
  // from, and what a test changes.
  struct CtFrame {
    std::string file;
    std::string slope = "1";
    std::string stack = "1";
    uint32_t time = 1;             // TemporalPositionIndex
    std::string orientation = "";  // per-frame ImageOrientationPatient instead of the shared one
  };

  // ImagePositionPatient of CT5N's slices (gdcmdump).
  std::string ct5n_position(const std::string& file) {
    if (file == "2062") return "-72.199997\\-143.000000\\8.762500";
    if (file == "2392") return "-72.199997\\-143.000000\\6.262500";
    if (file == "2693") return "-72.199997\\-143.000000\\3.762500";
    if (file == "3023") return "-72.199997\\-143.000000\\1.262500";
    return "-72.199997\\-143.000000\\-1.237500";  // 3353
  }

  struct EnhancedCt {
    std::vector<CtFrame> frames;
    std::string transfer_syntax = "1.2.840.10008.1.2.1";
    bool functional_groups = true;
  };

  // CT5N's slices as one Enhanced CT Image (what a scanner writes today): geometry and rescale in
  // the functional groups, the pixels of every frame in one PixelData.
  std::string enhanced_ct(const EnhancedCt& ct) {
    std::vector<std::string> per_frame;
    std::string pixels;
    for (const CtFrame& f : ct.frames) {
      std::string item =
          macro(0x0020, 0x9111,
                dicom_element(0x0020, 0x9056, "SH", f.stack) +
                    dicom_element(0x0020, 0x9128, "UL", element_bytes<uint32_t>({f.time})));
      item += macro(0x0020, 0x9113, dicom_element(0x0020, 0x0032, "DS", ct5n_position(f.file)));
      if (!f.orientation.empty())
        item += macro(0x0020, 0x9116, dicom_element(0x0020, 0x0037, "DS", f.orientation));
      item += macro(0x0028, 0x9145,
                    dicom_element(0x0028, 0x1052, "DS", "-1024") +
                        dicom_element(0x0028, 0x1053, "DS", f.slope));
      per_frame.push_back(item);
      const std::string bytes = read_file(ct5n / f.file);
      pixels += bytes.substr(bytes.size() - 512);  // CT5N's PixelData: the last 16x16x2 bytes
    }
    std::string shared;
    if (ct.frames.front().orientation.empty())
      shared += macro(0x0020, 0x9116, dicom_element(0x0020, 0x0037, "DS", "1\\0\\0\\0\\1\\0"));
    shared += macro(0x0028, 0x9110,
                    dicom_element(0x0018, 0x0050, "DS", "2.5") +
                        dicom_element(0x0028, 0x0030, "DS", "0.488281\\0.488281"));
    std::string top = dicom_element(0x0008, 0x0016, "UI", "1.2.840.10008.5.1.4.1.1.2.1") +
                      dicom_element(0x0008, 0x0060, "CS", "CT");
    if (!ct.functional_groups)
      top += dicom_element(0x0020, 0x0032, "DS", ct5n_position(ct.frames.front().file)) +
             dicom_element(0x0020, 0x0037, "DS", "1\\0\\0\\0\\1\\0");
    top += dicom_us(0x0028, 0x0002, 1) + dicom_element(0x0028, 0x0004, "CS", "MONOCHROME2") +
           dicom_element(0x0028, 0x0008, "IS", std::to_string(ct.frames.size())) +
           dicom_us(0x0028, 0x0010, 16) + dicom_us(0x0028, 0x0011, 16);
    if (!ct.functional_groups) top += dicom_element(0x0028, 0x0030, "DS", "0.488281\\0.488281");
    top += dicom_us(0x0028, 0x0100, 16) + dicom_us(0x0028, 0x0101, 16) +
           dicom_us(0x0028, 0x0102, 15) + dicom_us(0x0028, 0x0103, 1);
    if (ct.functional_groups)
      top += dicom_sequence(0x5200, 0x9229, {shared}) + dicom_sequence(0x5200, 0x9230, per_frame);
    if (ct.transfer_syntax == "1.2.840.10008.1.2.1")
      return part10(ct.transfer_syntax, top + dicom_element(0x7fe0, 0x0010, "OW", pixels));
    // Encapsulated: an empty offset table, then the "compressed" frames as one fragment.
    const std::string fragments =
        element_bytes<uint16_t>({0xfffe, 0xe000}) + element_bytes<uint32_t>({0}) +
        element_bytes<uint16_t>({0xfffe, 0xe000}) +
        element_bytes<uint32_t>({uint32_t(pixels.size())}) + pixels +
        element_bytes<uint16_t>({0xfffe, 0xe0dd}) + element_bytes<uint32_t>({0});
    const std::string undefined = element_bytes<uint16_t>({0x7fe0, 0x0010}) + "OB" +
                                  std::string(2, '\0') + element_bytes<uint32_t>({0xffffffff});
    return part10(ct.transfer_syntax, top + undefined + fragments);
  }

  // Frames in an order that is not the slices' order along the normal.
  std::vector<CtFrame> shuffled_ct5n() {
    return {{"2693"}, {"2062"}, {"3353"}, {"2392"}, {"3023"}};
  }

  }  // namespace

  TEST_CASE("dicom_enhanced_ct_matches_the_series_it_was_made_from_voxel_for_voxel") {
    const fs::path folder = output_folder("dicom_enhanced_ct");
    const fs::path file = write_file(folder / "ct5n.dcm", enhanced_ct({shuffled_ct5n()}));
    const Volume series = strata::load_volume(ct5n);
    const Loaded loaded = load_with_warnings(file);
    const Volume& v = loaded.volume;
    CHECK(loaded.warnings.empty());
    CHECK(v.dims == glm::uvec3(16, 16, 5));
    CHECK(v.name == "ct5n");
    CHECK(v.type == VoxelType::int16);  // stored int16, slope 1, intercept -1024 per frame
    CHECK(v.spacing == series.spacing);
    CHECK(v.origin == series.origin);  // 3353's position: the first along the normal
    CHECK(v.direction == glm::mat3(1.0f));
    CHECK(v.value_range == series.value_range);
    CHECK(v.voxels == series.voxels);  // frames put in order along the normal

    // A folder holding only the multi-frame file loads the same.
    const fs::path only = output_folder("dicom_enhanced_ct_folder");
    fs::copy_file(file, only / "IM0001");
    const Volume from_folder = strata::load_volume(only);
    CHECK(from_folder.voxels == series.voxels);
    CHECK(from_folder.name == "dicom_enhanced_ct_folder");
  }

  TEST_CASE("dicom_enhanced_ct_applies_each_frames_rescale") {
    std::vector<CtFrame> frames = shuffled_ct5n();
    frames[1].slope = "2";  // 2062, the last along the normal
    const fs::path file =
        write_file(output_folder("dicom_enhanced_slope") / "ct.dcm", enhanced_ct({frames}));
    const Volume v = strata::load_volume(file);
    CHECK(v.type == VoxelType::int16);
    CHECK(v.value(0, 0, 4) == 974.0f * 2.0f - 1024.0f);  // CT5N/2062 stores 974 first
    CHECK(v.value(0, 0, 0) == 991.0f - 1024.0f);         // 3353
    frames[1].slope = ".5";
    write_file(file, enhanced_ct({frames}));
    const Volume fractional = strata::load_volume(file);
    CHECK(fractional.type == VoxelType::float32);
    CHECK(fractional.value(0, 0, 4) == 974.0f * 0.5f - 1024.0f);
  }

  // nibabel's philips_mprage.dcm: a Philips Enhanced MR Image, 176 sagittal frames of 256x256,
  // every attribute per frame. Expected values read with pydicom: frame 1 at (92.7090416119899,
  // -125.12766968458, 136.495256863534), frame 176 at (-82.190830214181, -125.12766968458,
  // 142.421648465096), cosines (-0.0022011068649, 0.99788552522659, -0.0649590045213) and
  // (-0.0337935090065, -0.0649962872266, -0.9973131418228), PixelSpacing 1\1, RescaleSlope
  // 2.1079365079365; the anonymised pixels are all 0.
  TEST_CASE("dicom_enhanced_mr_from_philips_loads_176_frames_along_the_normal") {
    const fs::path path = cache / "dicom/philips_mprage.dcm";
    REQUIRE_MESSAGE(fs::exists(path), "run scripts/fetch-data.sh");
    const size_t before = heap_in_use.load();
    heap_peak.store(before);
    // In this process (load_volume reads DICOM in a child process, whose heap is not counted).
    Loaded loaded;
    loaded.volume = strata::load_dicom_file(path, {}, loaded.warnings);
    const size_t peak = heap_peak.load() - before;
    const Volume& v = loaded.volume;
    CHECK(loaded.warnings.empty());
    CHECK(v.dims == glm::uvec3(256, 256, 176));
    CHECK(v.name == "philips_mprage");
    CHECK(v.type == VoxelType::float32);  // a fractional slope
    CHECK(v.value_range == glm::vec2(0.0f));
    // GDCM's copy of the file (the stored uint16) and the float32 voxels: at most two copies.
    CHECK(peak < 2 * v.byte_size());
    const glm::vec3 row(-0.0022011068649f, 0.99788552522659f, -0.0649590045213f);
    const glm::vec3 column(-0.0337935090065f, -0.0649962872266f, -0.9973131418228f);
    for (int axis = 0; axis < 3; ++axis) {
      CHECK(v.direction[0][axis] == doctest::Approx(row[axis]).epsilon(1e-5));
      CHECK(v.direction[1][axis] == doctest::Approx(column[axis]).epsilon(1e-5));
    }
    CHECK(v.direction[2].x == doctest::Approx(-0.999426).epsilon(1e-5));  // row x column
    CHECK(v.spacing.x == 1.0f);
    CHECK(v.spacing.y == 1.0f);
    CHECK(v.spacing.z == doctest::Approx(1.0).epsilon(1e-5));
    const glm::vec4 first = v.index_to_patient() * glm::vec4(0, 0, 0, 1);
    const glm::vec4 last = v.index_to_patient() * glm::vec4(0, 0, 175, 1);
    CHECK(first.x == doctest::Approx(92.7090416));
    CHECK(first.z == doctest::Approx(136.4952569));
    CHECK(last.x == doctest::Approx(-82.1908302).epsilon(1e-4));
    CHECK(last.y == doctest::Approx(-125.1276697).epsilon(1e-4));
    CHECK(last.z == doctest::Approx(142.4216485).epsilon(1e-4));
    CHECK(frame_error(path, 1) ==
          path.string() + ": frame 1 is out of range: the image has one frame, 0");
  }

  TEST_CASE("dicom_multi_frame_files_strata_cannot_read_give_one_error_naming_the_file") {
    const fs::path folder = output_folder("dicom_enhanced_bad");
    const auto file = [&](const char* name, const EnhancedCt& ct) {
      return write_file(folder / name, enhanced_ct(ct));
    };
    std::vector<CtFrame> turned = shuffled_ct5n();
    for (CtFrame& f : turned) f.orientation = "1\\0\\0\\0\\1\\0";
    turned[3].orientation = "0\\1\\0\\1\\0\\0";
    CHECK_LOAD_ERROR(file("turned.dcm", {turned}),
                     "mixed ImageOrientationPatient: frame 1 and frame 4 differ");
    std::vector<CtFrame> stacks = shuffled_ct5n();
    stacks[2].stack = "2";
    CHECK_LOAD_ERROR(file("stacks.dcm", {stacks}),
                     "holds several stacks (frame 1 has StackID '1', frame 3 '2')");
    std::vector<CtFrame> times = shuffled_ct5n();
    times[2].time = 2;
    CHECK_LOAD_ERROR(file("times.dcm", {times}),
                     "holds several time points (frame 1 has TemporalPositionIndex 1, frame 3 2): "
                     "strata reads an enhanced file of one time point; dcm2niix converts it to a "
                     "4-D NIfTI, whose --frame picks one");
    std::vector<CtFrame> twice = shuffled_ct5n();
    twice[4].file = "2693";
    CHECK_LOAD_ERROR(file("twice.dcm", {twice}), "frame 1 and frame 5 are at the same position");
    CHECK_LOAD_ERROR(
        file("htj2k.dcm", {shuffled_ct5n(), "1.2.840.10008.1.2.4.201"}),
        "TransferSyntaxUID 1.2.840.10008.1.2.4.201 is not supported (GDCM does not know it");
    CHECK_LOAD_ERROR(file("mpeg2.dcm", {shuffled_ct5n(), "1.2.840.10008.1.2.4.100"}),
                     "cannot decode the pixel data (transfer syntax 1.2.840.10008.1.2.4.100");
    CHECK_LOAD_ERROR(file("legacy.dcm", {shuffled_ct5n(), "1.2.840.10008.1.2.1", false}),
                     "NumberOfFrames = 5 without a Per-frame Functional Groups Sequence");
    CHECK_LOAD_ERROR(folder / "missing.dcm", "no such file");
    write_file(folder / "notes.dcm", "not DICOM\n");
    CHECK_LOAD_ERROR(folder / "notes.dcm", "not a DICOM file");

    // (the made-up enhanced file has no SeriesInstanceUID: a series of its own beside 2062's)
    const fs::path mixed = copy_ct5n("dicom_enhanced_and_slices", {"2062"});
    write_file(mixed / "enhanced.dcm", enhanced_ct({shuffled_ct5n()}));
    std::vector<std::string> warnings;
    CHECK(strata::load_volume(mixed, {}, warnings).dims == glm::uvec3(16, 16, 5));
    REQUIRE(!warnings.empty());
    CHECK(warnings[0].find("holds 2 series") != std::string::npos);
    const fs::path two = output_folder("dicom_two_multi_frame_files");
    write_file(two / "enhanced.dcm", enhanced_ct({shuffled_ct5n()}));
    write_file(two / "other.dcm", enhanced_ct({shuffled_ct5n()}));
    CHECK_LOAD_ERROR(two, "holds the multi-frame file enhanced.dcm and other images of its series");
  }

  // ---- 2-D images: one voxel thick, with a warning

  // pydicom's CT_small.dcm: one 128x128 CT slice, PixelSpacing 0.661468, SliceThickness 5,
  // ImagePositionPatient (-158.135803, -179.035797, -75.699997), RescaleIntercept -1024; stored
  // 128..2191 (pydicom), the pixel at row 5, column 10 stores 187.
  TEST_CASE("dicom_single_slice_file_loads_one_voxel_thick_with_a_warning") {
    const fs::path path = cache / "dicom/CT_small.dcm";
    REQUIRE_MESSAGE(fs::exists(path), "run scripts/fetch-data.sh");
    const Loaded loaded = load_with_warnings(path);
    const Volume& v = loaded.volume;
    CHECK(v.dims == glm::uvec3(128, 128, 1));
    CHECK(v.name == "CT_small");
    CHECK(v.type == VoxelType::int16);
    CHECK(v.spacing.x == doctest::Approx(0.661468));
    CHECK(v.spacing.z == 5.0f);  // SliceThickness
    CHECK(v.origin == glm::vec3(-158.135803f, -179.035797f, -75.699997f));
    CHECK(v.value(10, 5, 0) == 187.0f - 1024.0f);
    CHECK(v.value_range == glm::vec2(128.0f - 1024.0f, 2191.0f - 1024.0f));
    REQUIRE(loaded.warnings.size() == 1);
    CHECK(loaded.warnings[0] == path.string() +
                                    ": 2-D image (one slice of 128x128); shown as a volume one "
                                    "voxel (5 mm) thick");
    // The same slice alone in a folder.
    const fs::path folder = output_folder("dicom_one_slice");
    fs::copy_file(path, folder / "CT_small");
    CHECK(load_with_warnings(folder).volume.voxels == v.voxels);
  }

  TEST_CASE("two_dimensional_nifti_nrrd_and_metaimage_load_one_voxel_thick") {
    const fs::path folder = output_folder("two_d");
    // NIfTI dim[0] = 2 with pixdim[3] 0: k is 1 mm.
    Header nifti = nifti1(false, 2, {3, 2, 0});
    nifti.put<int16_t>(40, 2).put<float>(88, 0.0f);
    write_file(folder / "flat.nii", nifti.bytes + "abcdef");
    const Loaded n = load_with_warnings(folder / "flat.nii");
    CHECK(n.volume.dims == glm::uvec3(3, 2, 1));
    CHECK(n.volume.spacing == glm::vec3(1.0f));
    CHECK(n.volume.value(2, 1, 0) == float('f'));
    REQUIRE(n.warnings.size() == 1);
    CHECK(n.warnings[0].find("flat.nii: 2-D image (one slice of 3x2)") != std::string::npos);

    write_file(folder / "flat.nrrd",
               "NRRD0004\ntype: uchar\ndimension: 2\nsizes: 2 3\nspace: left-posterior-superior\n"
               "space directions: (0,0.5,0) (0.25,0,0)\nspace origin: (1,2,3)\nencoding: raw\n\n"
               "abcdef");
    const Loaded r = load_with_warnings(folder / "flat.nrrd");
    CHECK(r.volume.dims == glm::uvec3(2, 3, 1));
    CHECK(r.volume.value(1, 2, 0) == float('f'));
    // k is the normal of the slice: (0,1,0) x (1,0,0).
    check_matrix(r.volume.index_to_patient(),
                 columns({0, 0.5f, 0}, {0.25f, 0, 0}, {0, 0, -1}, {1, 2, 3}));
    CHECK(r.warnings.size() == 1);

    write_file(folder / "flat.mha",
               "ObjectType = Image\nNDims = 2\nDimSize = 2 3\nElementSpacing = 0.5 0.25\n"
               "Offset = 1 2\nTransformMatrix = 0 1 1 0\nElementType = MET_UCHAR\n"
               "ElementDataFile = LOCAL\nabcdef");
    const Loaded m = load_with_warnings(folder / "flat.mha");
    CHECK(m.volume.dims == glm::uvec3(2, 3, 1));
    check_matrix(m.volume.index_to_patient(),
                 columns({0, 0.5f, 0}, {0.25f, 0, 0}, {0, 0, -1}, {1, 2, 0}));
    CHECK(m.warnings.size() == 1);
  }

  // ---- 4-D images: one frame

  // nibabel's example4d.nii.gz: 128x96x24 int16, 2 frames. Read with nibabel: frame 0 ranges 0 to
  // 1162 (at voxel 64,49,0; frame 1 there: 1056), frame 1 0 to 1140 (at 62,86,10; frame 0 there:
  // 1135); sform rows (-2 0 0 117.8551025) (0 1.9737115 -0.3555282 -35.7229424)
  // (0 0.3232076 2.1710818 -7.2487984).
  TEST_CASE("nifti_4d_loads_frame_0_by_default_and_the_frame_asked_for_with_a_warning") {
    const fs::path path = cache / "nibabel/example4d.nii.gz";
    REQUIRE_MESSAGE(fs::exists(path), "run scripts/fetch-data.sh");
    const Loaded first = load_with_warnings(path);
    CHECK(first.volume.dims == glm::uvec3(128, 96, 24));
    CHECK(first.volume.type == VoxelType::int16);
    CHECK(first.volume.value(64, 49, 0) == 1162.0f);
    CHECK(first.volume.value(62, 86, 10) == 1135.0f);
    CHECK(first.volume.value_range == glm::vec2(0.0f, 1162.0f));
    CHECK(first.warnings ==
          std::vector<std::string>{path.string() +
                                   ": 4-D image with 2 frames; showing frame 0 (choose with "
                                   "--frame)"});
    CHECK(first.volume.spacing.x == doctest::Approx(2.0));
    CHECK(first.volume.spacing.z == doctest::Approx(2.2).epsilon(1e-5));
    CHECK(first.volume.origin.x == doctest::Approx(-117.8551025));  // RAS x negated into LPS
    CHECK(first.volume.origin.y == doctest::Approx(35.7229424));

    const Loaded second = load_with_warnings(path, 1);
    CHECK(second.volume.value(64, 49, 0) == 1056.0f);
    CHECK(second.volume.value(62, 86, 10) == 1140.0f);
    CHECK(second.volume.value_range == glm::vec2(0.0f, 1140.0f));
    CHECK(second.volume.voxels != first.volume.voxels);
    CHECK(second.volume.index_to_patient() == first.volume.index_to_patient());
    CHECK(second.warnings[0].find("showing frame 1 (choose with --frame)") != std::string::npos);

    const std::string range = ": the image has 2 frames, 0 to 1";
    CHECK(frame_error(path, 2) == path.string() + ": frame 2 is out of range" + range);
    CHECK(frame_error(path, -1) == path.string() + ": frame -1 is out of range" + range);
    CHECK(frame_error(cache / "mricron/ch2.nii.gz", 1)
              .find("ch2.nii.gz: frame 1 is out of range: "
                    "the image has one frame, 0") != std::string::npos);
  }

  TEST_CASE("scene_volume_frame_key_picks_the_frame_and_the_warning_reaches_the_scene") {
    const fs::path path = cache / "nibabel/example4d.nii.gz";
    REQUIRE_MESSAGE(fs::exists(path), "run scripts/fetch-data.sh");
    const fs::path folder = output_folder("scene_frame");
    const auto scene = [&](const std::string& frame) {
      return write_file(folder / "s.json", R"({"strata_scene": 1, "volumes": [{"file": ")" +
                                               path.string() + R"(", "frame": )" + frame + "}]}");
    };
    const strata::Scene loaded = strata::load_scene(scene("1"));
    REQUIRE(loaded.volumes.size() == 1);
    CHECK(loaded.volumes[0].value(64, 49, 0) == 1056.0f);
    REQUIRE(loaded.warnings.size() == 2);  // the frame, then the preset for the bare volume
    CHECK(loaded.warnings[0].find("showing frame 1 (choose with --frame)") != std::string::npos);
    CHECK(loaded.warnings[1].find("has no transfer function; preset") != std::string::npos);
    const std::string prefix = (folder / "s.json").string() + ": volumes[0].";
    CHECK(strata::test::error_of([&] { strata::load_scene(scene("-1")); }) ==
          prefix + "frame: expected an integer >= 0");
    CHECK(strata::test::error_of([&] { strata::load_scene(scene("2.5")); }) ==
          prefix + "frame: expected an integer");
    CHECK(strata::test::error_of([&] {
            strata::load_scene(scene("2"));
          }).find("frame 2 is out of range: the image has 2 frames, 0 to 1") != std::string::npos);
  }

  TEST_CASE("nrrd_and_metaimage_4d_read_the_frame_asked_for") {
    const fs::path folder = output_folder("four_d");
    const std::string frames = "abcdefghijkl";  // 3 frames of 2x2x1
    write_file(folder / "time.nrrd",
               "NRRD0004\ntype: uchar\ndimension: 4\nsizes: 2 2 1 3\nkinds: space space space "
               "time\nspace: left-posterior-superior\nspace directions: (2,0,0) (0,2,0) (0,0,2) "
               "none\nencoding: raw\n\n" +
                   frames);
    const Loaded r = load_with_warnings(folder / "time.nrrd", 2);
    CHECK(r.volume.dims == glm::uvec3(2, 2, 1));
    CHECK(r.volume.value(0, 0, 0) == float('i'));
    CHECK(r.volume.value(1, 1, 0) == float('l'));
    CHECK(r.volume.spacing == glm::vec3(2.0f));
    CHECK(r.warnings.front() ==
          (folder / "time.nrrd").string() +
              ": 4-D image with 3 frames; showing frame 2 (choose with --frame)");

    write_gzip(folder / "frames.gz", frames);
    write_file(folder / "time_gzip.nrrd",
               "NRRD0004\ntype: uchar\ndimension: 4\nsizes: 2 2 1 3\nspacings: 1 1 1 nan\n"
               "encoding: gzip\n\n" +
                   read_file(folder / "frames.gz"));
    CHECK(load_with_warnings(folder / "time_gzip.nrrd", 1).volume.value(0, 0, 0) == float('e'));

    write_file(folder / "time.mha",
               "ObjectType = Image\nNDims = 4\nDimSize = 2 2 1 3\nElementSpacing = 1 1 3 0.5\n"
               "Offset = 1 2 3 0\nTransformMatrix = 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n"
               "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n" +
                   frames);
    const Loaded m = load_with_warnings(folder / "time.mha", 1);
    CHECK(m.volume.value(0, 0, 0) == float('e'));
    CHECK(m.volume.spacing == glm::vec3(1, 1, 3));
    CHECK(m.volume.origin == glm::vec3(1, 2, 3));
    CHECK(m.warnings.front().find("4-D image with 3 frames; showing frame 1") != std::string::npos);
    CHECK(frame_error(folder / "time.mha", 3)
              .find("frame 3 is out of range: the image has 3 "
                    "frames, 0 to 2") != std::string::npos);
  }

  TEST_CASE("4d_images_strata_cannot_read_give_one_error_naming_the_file") {
    const fs::path folder = output_folder("four_d_bad");
    const auto file = [&](const char* name, const std::string& bytes) {
      return write_file(folder / name, bytes);
    };
    // NIfTI: the data holds frame 0 only, frame 1 is asked for.
    Header nifti = nifti1(false, 2, {2, 2, 1});
    nifti.put<int16_t>(40, 4).put<int16_t>(48, 2);
    file("cut4d.nii", nifti.bytes + "abcd");
    CHECK(frame_error(folder / "cut4d.nii", 1) ==
          (folder / "cut4d.nii").string() + ": voxel data ends before frame 1 (4 bytes a frame)");
    CHECK_LOAD_ERROR(file("zero_frames.nii", Header{nifti}.put<int16_t>(48, 0).bytes),
                     "dim[4] = 0: the frame count must be positive");
    // Vectors first (a DWI or an RGB image): frames are not stored one after the other.
    CHECK_LOAD_ERROR(file("dwi.nrrd",
                          "NRRD0004\ntype: uchar\ndimension: 4\nsizes: 3 2 2 1\nkinds: list "
                          "domain domain domain\nencoding: raw\n\n" +
                              std::string(12, 'x')),
                     "kinds: axis 0 is 'list': strata reads 4-D images whose fourth axis is the "
                     "non-spatial one");
    CHECK_LOAD_ERROR(file("none_first.nrrd",
                          "NRRD0004\ntype: uchar\ndimension: 4\nsizes: 3 2 2 1\nspace: RAS\n"
                          "space directions: none (1,0,0) (0,1,0) (0,0,1)\nencoding: raw\n\n" +
                              std::string(12, 'x')),
                     "space directions: axis 0 is 'none'");
    CHECK_LOAD_ERROR(file("sizes.nrrd", "NRRD0004\ntype: uchar\ndimension: 4\nsizes: 2 2 2\n\n"),
                     "sizes: expected 4 numbers (dimension 4), got '2 2 2'");
    CHECK_LOAD_ERROR(file("5d.mha", "ObjectType = Image\nNDims = 5\nElementDataFile = LOCAL\n"),
                     "NDims = 5: expected 2, 3 or 4");
    CHECK_LOAD_ERROR(file("sizes.mha",
                          "ObjectType = Image\nNDims = 4\nDimSize = 2 2 2\nElementType = "
                          "MET_UCHAR\nElementDataFile = LOCAL\n"),
                     "DimSize: expected 4 numbers (NDims = 4), got '2 2 2'");
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

  // ---- numbers checked where they enter, limits checked before reading

  namespace {

  // Replaces a short-VR element's value with one of any even length (explicit VR little endian;
  // CT5N has no group lengths to fix).
  void patch_any_length(std::string& bytes, uint16_t group, uint16_t element, const char* vr,
                        std::string value) {
    if (value.size() % 2) value += ' ';
    const std::string tag = element_bytes<uint16_t>({group, element}) + vr;
    const size_t at = bytes.find(tag);
    REQUIRE(at != std::string::npos);
    uint16_t length = 0;
    std::memcpy(&length, bytes.data() + at + 6, 2);
    bytes.replace(at + 6, 2u + length, element_bytes<uint16_t>({uint16_t(value.size())}) + value);
  }

  // CT5N with one element of every file replaced.
  fs::path ct5n_with(const std::string& name, uint16_t group, uint16_t element,
                     const std::string& value) {
    const fs::path folder = output_folder(name);
    for (const char* file : {"2062", "2392", "2693"}) {
      std::string bytes = read_file(ct5n / file);
      patch_any_length(bytes, group, element, "DS", value);
      write_file(folder / file, bytes);
    }
    return folder;
  }

  }  // namespace

  TEST_CASE("non_finite_or_singular_geometry_is_an_error_naming_the_field") {
    const fs::path folder = output_folder("geometry");
    const std::string data(3 * 4 * 5, '\0');
    const auto nifti = [&](const char* name, const Header& h) {
      return write_file(folder / name, h.bytes + data);
    };
    const float inf = std::numeric_limits<float>::infinity();
    Header qform = nifti1(false, 2, {3, 4, 5});
    qform.put<int16_t>(252, 1).put<float>(268, inf);  // qform_code 1, qoffset_x inf
    CHECK_LOAD_ERROR(nifti("qoffset.nii", qform), "qoffset_x/y/z = ");
    CHECK(load_error(folder / "qoffset.nii").find("must be finite") != std::string::npos);
    Header sform = nifti1(false, 2, {3, 4, 5});
    sform.put<int16_t>(254, 1);  // sform_code 1; i and j both along x: no volume
    for (size_t col = 0; col < 2; ++col) sform.put<float>(280 + 4 * col, 1.0f);
    sform.put<float>(312 + 8, 1.0f);
    CHECK_LOAD_ERROR(nifti("singular.nii", sform),
                     "srow_x/y/z: the axes' directions lie in one plane");
    // NIfTI-2 keeps the sform in doubles: a column of length 1e100 is finite there, not in float.
    Header wide = nifti2(2, {3, 4, 5});
    wide.put<int32_t>(348, 1);  // sform_code
    wide.put<double>(400, 1e100).put<double>(432 + 8, 1.0).put<double>(464 + 16, 1.0);
    CHECK_LOAD_ERROR(nifti("wide.nii", wide),
                     "srow_x/y/z: spacing inf 1 1 must be positive and finite");
    wide.put<double>(400, 1e300);  // its square overflows the double too
    CHECK_LOAD_ERROR(nifti("wider.nii", wide),
                     "srow_x/y/z column 0: the column's length is not a finite");
    Header good_sform = sform;
    good_sform.put<float>(284, 0.0f).put<float>(296 + 4, 1.0f);
    CHECK(strata::load_volume(nifti("sform.nii", good_sform)).dims == glm::uvec3(3, 4, 5));

    const auto mha = [&](const char* name, const std::string& fields) {
      return write_file(folder / name,
                        "ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\n"
                        "ElementType = MET_UCHAR\n" +
                            fields + "ElementDataFile = LOCAL\n" + std::string(8, '\0'));
    };
    CHECK_LOAD_ERROR(mha("nan.mha", "Offset = nan 0 0\n"),
                     "Offset = nan 0 0: the origin must be finite");
    CHECK_LOAD_ERROR(mha("zero.mha", "TransformMatrix = 0 0 0 0 0 0 0 0 0\n"),
                     "TransformMatrix: the direction of axis 0 (0 0 0) is not a unit vector");
    CHECK_LOAD_ERROR(mha("flat.mha", "TransformMatrix = 1 0 0 1 0 0 0 0 1\n"),
                     "TransformMatrix: the axes' directions lie in one plane");
    CHECK(strata::load_volume(
              mha("fine.mha", "Offset = 1 2 3\nTransformMatrix = 0 1 0 1 0 0 0 0 1\n"))
              .origin == glm::vec3(1, 2, 3));

    const std::string nrrd =
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
        "space: left-posterior-superior\nspace directions: (1,0,0) (0,1,0) "
        "(0,0,1)\n";
    CHECK_LOAD_ERROR(write_file(folder / "inf.nrrd",
                                nrrd + "space origin: (inf,0,0)\n\n" + std::string(8, '\0')),
                     "space origin = inf 0 0: the origin must be finite");
    // Finite as a double, not as the float the volume keeps.
    CHECK_LOAD_ERROR(write_file(folder / "far.nrrd",
                                nrrd + "space origin: (1e39,0,0)\n\n" + std::string(8, '\0')),
                     "the origin must be finite");

    CHECK_LOAD_ERROR(ct5n_with("dicom_position_nan", 0x0020, 0x0032, "NaN\\-143\\8.7625"),
                     "ImagePositionPatient = nan -143 8.7625: the position must be finite");
  }

  TEST_CASE("rescales_that_are_not_numbers_or_overflow_are_errors") {
    CHECK_LOAD_ERROR(ct5n_with("dicom_slope_zero", 0x0028, 0x1053, "0"),
                     "RescaleSlope = 0: expected a finite, non-zero number");
    CHECK_LOAD_ERROR(ct5n_with("dicom_slope_nan", 0x0028, 0x1053, "NaN"),
                     "RescaleSlope = nan: expected a finite, non-zero number");
    CHECK_LOAD_ERROR(ct5n_with("dicom_intercept_inf", 0x0028, 0x1052, "inf"),
                     "RescaleIntercept = inf: expected a finite number");
    const fs::path huge = ct5n_with("dicom_slope_huge", 0x0028, 0x1053, "1e300");
    CHECK_LOAD_ERROR(huge, "RescaleSlope, RescaleIntercept = 1e+300, -1024: the stored value");
    CHECK_LOAD_ERROR(huge, "outside the range of a 32-bit float");
    // NIfTI: scl_slope 0 means "no scaling" by the standard (nibabel writes NaN for the same);
    // a slope that takes the values past float is an error.
    const fs::path folder = output_folder("nifti_slope");
    const std::string values = element_bytes<int16_t>({100, -3});
    Header h = nifti1(false, 4, {2, 1, 1});
    write_file(folder / "none.nii", Header{h}.put<float>(112, 0.0f).bytes + values);
    CHECK(strata::load_volume(folder / "none.nii").value(0, 0, 0) == 100.0f);
    write_file(folder / "huge.nii", Header{h}.put<float>(112, 1e38f).bytes + values);
    CHECK_LOAD_ERROR(folder / "huge.nii", "scl_slope, scl_inter = ");
    CHECK_LOAD_ERROR(folder / "huge.nii", "the stored value 100 becomes 1e+40");
  }

  TEST_CASE("volumes_too_big_for_the_memory_or_the_device_are_refused_from_the_header") {
    // Headers only: the limits are checked before any voxel is read (the data is not there).
    const fs::path folder = output_folder("limits");
    write_file(folder / "big.nii", nifti1(false, 4, {1024, 1024, 512}).bytes);  // 1 GiB
    std::vector<std::string> warnings;
    const auto message = [&](const strata::VolumeLimits& limits) {
      return strata::test::error_of(
          [&] { strata::load_volume(folder / "big.nii", {.limits = limits}, warnings); });
    };
    CHECK(message({.memory_bytes = uint64_t{1} << 30})
              .find("dim[1..3] = 1024x1024x512: the voxels need 1.0 GiB twice while loading; this "
                    "machine has 1.0 GiB of memory") != std::string::npos);
    CHECK(message({.max_side = 800, .device = "Test GPU"})
              .find("1024x1024x512: the device (Test GPU) renders at most 800 voxels per side") !=
          std::string::npos);
    CHECK(message({.max_device_voxels = 1000000, .device_voxel_bytes = 8, .device = "Test GPU"})
              .find("536870912 voxels; the device (Test GPU) holds at most 1000000") !=
          std::string::npos);
    // Within every limit: the reader goes on and finds the data missing.
    CHECK(message({}).find("voxel data has 0 bytes") != std::string::npos);
    // The DICOM reader checks them too, after reading the headers, before the pixels.
    std::vector<std::string> w;
    CHECK(strata::test::error_of([&] {
            strata::load_volume(ct5n, {.limits = {.max_side = 8, .device = "Test GPU"}}, w);
          }).find("Columns x Rows x files = 16x16x5: the device (Test GPU) renders at most 8") !=
          std::string::npos);
  }

  TEST_CASE("fifos_and_folders_are_refused_where_a_file_is_read") {
    const fs::path folder = output_folder("fifo");
    const fs::path fifo = folder / "pipe.nii";
    REQUIRE(mkfifo(fifo.c_str(), 0600) == 0);
    // Opening a FIFO for reading blocks until a writer comes: these must return at once.
    CHECK_LOAD_ERROR(fifo, "is not a regular file (a FIFO, device or socket)");
    const fs::path mhd = write_file(folder / "a.mhd",
                                    "ObjectType = Image\nNDims = 3\nDimSize = 1 1 1\n"
                                    "ElementType = MET_UCHAR\nElementDataFile = pipe.raw\n");
    REQUIRE(mkfifo((folder / "pipe.raw").c_str(), 0600) == 0);
    CHECK_LOAD_ERROR(mhd, "pipe.raw: is not a regular file");
    const fs::path scene_fifo = folder / "scene.json";
    REQUIRE(mkfifo(scene_fifo.c_str(), 0600) == 0);
    CHECK(strata::test::error_of([&] { strata::load_scene(scene_fifo); }) ==
          scene_fifo.string() +
              ": is not a regular file (a FIFO, device or socket); strata reads only files");
    CHECK(strata::test::error_of([&] {
            strata::load_scene("/dev/zero.json");
          }).find("no such file") != std::string::npos);
    fs::create_directories(folder / "dir.json");
    CHECK(strata::test::error_of([&] { strata::load_scene(folder / "dir.json"); }) ==
          (folder / "dir.json").string() + ": is a folder, not a file");
  }

  TEST_CASE("text_files_have_a_size_limit_and_no_nul_bytes") {
    const fs::path folder = output_folder("text_limits");
    // 65 MiB, sparse: a valid scene's start and then zeros, as a broken copy would leave it.
    const fs::path big = write_file(folder / "big.json", "{\"strata_scene\": 1, \"volumes\": []");
    fs::resize_file(big, (uint64_t{65} << 20));
    CHECK(strata::test::error_of([&] { strata::load_scene(big); }) ==
          big.string() + ": is 65 MiB; files of this kind may have at most 64 MiB");
    const fs::path nul = write_file(folder / "nul.json",
                                    std::string("{\"strata_scene\": 1}\n\0{\"volumes\": 3}", 34));
    CHECK(strata::test::error_of([&] { strata::load_scene(nul); }) ==
          nul.string() + ": a NUL byte at line 2, column 1 (offset 20): not a text file");
  }

}  // TEST_SUITE("loaders")
