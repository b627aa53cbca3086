// DICOM that loads right or not at all: sheared stacks keep each slice where its
// ImagePositionPatient puts it, a damaged slice anywhere in a folder is an error naming it, pixel
// formats strata cannot show as grey values are refused, and a lone image without a position opens
// as a 2-D image. Every file is written here (explicit VR little endian, tiny images).
#include <doctest/doctest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "engine/core/error.h"
#include "engine/scene/io/volume_loader.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using strata::Volume;
using strata::test::write_file;

fs::path output_folder(const std::string& name) {
  return strata::test::fresh_folder("dicom_geometry", name);
}

template <class T>
std::string bytes_of(const std::vector<T>& values) {
  std::string bytes;
  for (T v : values) {
    char raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) std::reverse(raw, raw + sizeof(T));
    bytes.append(raw, sizeof(T));
  }
  return bytes;
}

std::string element(uint16_t group, uint16_t number, const std::string& vr, std::string value) {
  if (value.size() % 2 == 1) value += vr == "UI" || vr == "OB" || vr == "OW" ? '\0' : ' ';
  std::string bytes = bytes_of<uint16_t>({group, number}) + vr;
  if (vr == "SQ" || vr == "OB" || vr == "OW")
    return bytes + std::string(2, '\0') + bytes_of<uint32_t>({uint32_t(value.size())}) + value;
  return bytes + bytes_of<uint16_t>({uint16_t(value.size())}) + value;
}

std::string sequence(uint16_t group, uint16_t number, const std::vector<std::string>& items) {
  std::string value;
  for (const std::string& item : items)
    value +=
        bytes_of<uint16_t>({0xfffe, 0xe000}) + bytes_of<uint32_t>({uint32_t(item.size())}) + item;
  return element(group, number, "SQ", value);
}

// A data set: elements by tag, written in ascending tag order as DICOM requires.
struct DataSet {
  std::map<uint32_t, std::string> elements;
  DataSet& set(uint16_t group, uint16_t number, const std::string& vr, const std::string& value) {
    elements[uint32_t(group) << 16 | number] = element(group, number, vr, value);
    return *this;
  }
  DataSet& us(uint16_t group, uint16_t number, uint16_t value) {
    return set(group, number, "US", bytes_of<uint16_t>({value}));
  }
  DataSet& sq(uint16_t group, uint16_t number, const std::vector<std::string>& items) {
    elements[uint32_t(group) << 16 | number] = sequence(group, number, items);
    return *this;
  }
  DataSet& erase(uint16_t group, uint16_t number) {
    elements.erase(uint32_t(group) << 16 | number);
    return *this;
  }
  std::string bytes() const {
    std::string all;
    for (const auto& [tag, encoded] : elements) all += encoded;
    return all;
  }
};

std::string part10(const DataSet& data_set) {
  const std::string meta = element(0x0002, 0x0001, "OB", std::string("\0\1", 2)) +
                           element(0x0002, 0x0002, "UI", "1.2.840.10008.5.1.4.1.1.2") +
                           element(0x0002, 0x0003, "UI", "1.2.826.0.1.3680043.2.1") +
                           element(0x0002, 0x0010, "UI", "1.2.840.10008.1.2.1");
  return std::string(128, '\0') + "DICM" +
         element(0x0002, 0x0000, "UL", bytes_of<uint32_t>({uint32_t(meta.size())})) + meta +
         data_set.bytes();
}

constexpr uint16_t kColumns = 4, kRows = 3;

std::string ds(glm::dvec3 p) {
  char text[96];
  std::snprintf(text, sizeof text, "%.6f\\%.6f\\%.6f", p.x, p.y, p.z);
  return text;
}

// Pixel n of the slice that is k-th along the normal stores 100 k + n.
std::string pixels(int k) {
  std::vector<uint16_t> values;
  for (int n = 0; n < kColumns * kRows; ++n) values.push_back(uint16_t(100 * k + n));
  return bytes_of(values);
}

// A 4x3 CT slice, 0.5 x 0.7 mm pixels, rows along x and columns along y (normal +z).
DataSet ct_slice(glm::dvec3 position, int k) {
  DataSet d;
  d.set(0x0008, 0x0016, "UI", "1.2.840.10008.5.1.4.1.1.2").set(0x0008, 0x0060, "CS", "CT");
  d.set(0x0018, 0x0050, "DS", "2.5");
  d.set(0x0020, 0x000e, "UI", "1.2.826.0.1.3680043.2.1.7");
  d.set(0x0020, 0x0032, "DS", ds(position)).set(0x0020, 0x0037, "DS", "1\\0\\0\\0\\1\\0");
  d.us(0x0028, 0x0002, 1).set(0x0028, 0x0004, "CS", "MONOCHROME2");
  d.us(0x0028, 0x0010, kRows).us(0x0028, 0x0011, kColumns);
  d.set(0x0028, 0x0030, "DS", "0.7\\0.5");  // between rows, between columns
  d.us(0x0028, 0x0100, 16).us(0x0028, 0x0101, 16).us(0x0028, 0x0102, 15).us(0x0028, 0x0103, 0);
  d.set(0x7fe0, 0x0010, "OW", pixels(k));
  return d;
}

// Positions of a stack 2.5 mm apart along +z whose slices also move `sideways` each.
std::vector<glm::dvec3> stack(glm::dvec3 sideways, int count = 5) {
  std::vector<glm::dvec3> positions;
  for (int k = 0; k < count; ++k)
    positions.push_back(glm::dvec3(10.0, 20.0, 30.0 + 2.5 * k) + double(k) * sideways);
  return positions;
}

// One file per position, named so that the names' order is not the slices' order.
fs::path write_series(const std::string& name, const std::vector<glm::dvec3>& positions) {
  const fs::path folder = output_folder(name);
  for (size_t k = 0; k < positions.size(); ++k)
    write_file(folder / ("IM" + std::to_string((k * 3) % positions.size())),
               part10(ct_slice(positions[k], int(k))));
  return folder;
}

struct Loaded {
  Volume volume;
  std::vector<std::string> warnings;
};

Loaded load(const fs::path& path) {
  Loaded loaded;
  loaded.volume = strata::load_volume(path, {}, loaded.warnings);
  return loaded;
}

std::string load_error(const fs::path& path) {
  return strata::test::error_of([&] { load(path); });
}

#define CHECK_ERROR(file, reason)                        \
  do {                                                   \
    const fs::path where = (file);                       \
    const std::string message = load_error(where);       \
    INFO("message: ", message);                          \
    CHECK(message.rfind(where.string() + ": ", 0) == 0); \
    CHECK(message.find(reason) != std::string::npos);    \
  } while (false)

// Every voxel where its slice's ImagePositionPatient and PixelSpacing put it, and the stored
// values of the k-th slice along the normal at k.
void check_voxels_at_their_positions(const Volume& v, const std::vector<glm::dvec3>& positions) {
  REQUIRE(v.dims == glm::uvec3(kColumns, kRows, positions.size()));
  const glm::mat4 m = v.index_to_patient();
  for (uint32_t k = 0; k < v.dims.z; ++k)
    for (uint32_t j = 0; j < kRows; ++j)
      for (uint32_t i = 0; i < kColumns; ++i) {
        const glm::vec4 p = m * glm::vec4(float(i), float(j), float(k), 1.0f);
        const glm::dvec3 expected = positions[k] + glm::dvec3(0.5 * i, 0.7 * j, 0.0);
        INFO("voxel ", i, " ", j, " ", k);
        CHECK(p.x == doctest::Approx(expected.x).epsilon(1e-5));
        CHECK(p.y == doctest::Approx(expected.y).epsilon(1e-5));
        CHECK(p.z == doctest::Approx(expected.z).epsilon(1e-5));
        CHECK(v.value(i, j, k) == float(100 * k + j * kColumns + i));
      }
}

std::string joined(const std::vector<std::string>& warnings) {
  std::string all;
  for (const std::string& w : warnings) all += w + "\n";
  return all;
}

// An Enhanced CT Image of the positions' slices, frames stored in the order `frame_order` gives
// (the k-th along the normal stores frame_order[k]).
std::string enhanced_ct(const std::vector<glm::dvec3>& positions) {
  std::vector<std::string> per_frame;
  std::string all_pixels;
  for (size_t f = 0; f < positions.size(); ++f) {
    const size_t k = (f * 2 + 1) % positions.size();  // frames out of order along the normal
    per_frame.push_back(
        sequence(0x0020, 0x9113, {element(0x0020, 0x0032, "DS", ds(positions[k]))}));
    all_pixels += pixels(int(k));
  }
  const std::string shared =
      sequence(0x0020, 0x9116, {element(0x0020, 0x0037, "DS", "1\\0\\0\\0\\1\\0")}) +
      sequence(0x0028, 0x9110,
               {element(0x0018, 0x0050, "DS", "2.5") + element(0x0028, 0x0030, "DS", "0.7\\0.5")});
  DataSet d = ct_slice(positions[0], 0);
  d.set(0x0008, 0x0016, "UI", "1.2.840.10008.5.1.4.1.1.2.1").erase(0x0020, 0x0032);
  d.erase(0x0020, 0x0037).erase(0x0028, 0x0030).erase(0x0018, 0x0050);
  d.set(0x0028, 0x0008, "IS", std::to_string(positions.size()));
  d.sq(0x5200, 0x9229, {shared}).sq(0x5200, 0x9230, per_frame);
  d.set(0x7fe0, 0x0010, "OW", all_pixels);
  return part10(d);
}

}  // namespace

TEST_SUITE("loaders") {
  // ---- sheared stacks

  // A gantry tilt of 12.3°: each slice 2.5 mm further along the normal and 2.5 tan(12.3°) mm
  // further along y.
  TEST_CASE("dicom_tilted_series_keeps_every_slice_at_its_position_with_a_warning") {
    const double tilt = glm::radians(12.3);
    const std::vector<glm::dvec3> positions = stack({0.0, 2.5 * std::tan(tilt), 0.0});
    const fs::path folder = write_series("tilted", positions);
    const Loaded loaded = load(folder);
    check_voxels_at_their_positions(loaded.volume, positions);
    CHECK(loaded.volume.spacing.z == doctest::Approx(2.5 / std::cos(tilt)).epsilon(1e-5));
    REQUIRE(loaded.warnings.size() == 1);
    CHECK(loaded.warnings[0].rfind(folder.string() +
                                       ": ImagePositionPatient: the slices are sheared by 12.3° "
                                       "(gantry tilt)",
                                   0) == 0);
    CHECK(loaded.warnings[0].find("not resampled") != std::string::npos);
  }

  TEST_CASE("dicom_series_sheared_along_both_axes_keeps_every_slice_at_its_position") {
    const std::vector<glm::dvec3> positions = stack({-0.4, 0.3, 0.0});
    const Loaded loaded = load(write_series("sheared", positions));
    check_voxels_at_their_positions(loaded.volume, positions);
    // atan(0.5 / 2.5) = 11.3°
    CHECK(joined(loaded.warnings).find("sheared by 11.3°") != std::string::npos);
  }

  TEST_CASE("dicom_series_with_rounding_noise_sideways_stays_orthogonal_without_a_warning") {
    std::vector<glm::dvec3> positions = stack({0.0, 0.0, 0.0});
    positions[1].x += 0.004;
    positions[3].y -= 0.005;
    const Loaded loaded = load(write_series("rounding", positions));
    CHECK(loaded.warnings.empty());
    CHECK(loaded.volume.direction == glm::mat3(1.0f));
    CHECK(loaded.volume.spacing.z == doctest::Approx(2.5));
  }

  TEST_CASE("dicom_series_whose_slices_are_not_on_one_line_is_an_error_naming_the_slice") {
    std::vector<glm::dvec3> positions = stack({0.0, 0.5, 0.0});
    positions[2].x += 1.0;  // IM1 (2 * 3 % 5)
    const fs::path folder = write_series("off_line", positions);
    CHECK_ERROR(folder, "ImagePositionPatient: the slices do not lie on one line: IM1 is 1 mm");
    CHECK_ERROR(write_series("tilted_too_far", stack({0.0, 3.0, 0.0})), "sheared by 50.2°");
  }

  TEST_CASE("dicom_enhanced_ct_with_sheared_frame_positions_keeps_every_frame_at_its_position") {
    const std::vector<glm::dvec3> positions =
        stack({0.0, -2.5 * std::tan(glm::radians(20.0)), 0.0});
    const fs::path file =
        write_file(output_folder("enhanced_sheared") / "ct.dcm", enhanced_ct(positions));
    const Loaded loaded = load(file);
    check_voxels_at_their_positions(loaded.volume, positions);
    REQUIRE(loaded.warnings.size() == 1);
    CHECK(loaded.warnings[0].rfind(file.string() + ": ImagePositionPatient: the slices are "
                                                   "sheared by 20.0° (gantry tilt)",
                                   0) == 0);
    // The same frames without shear: an orthogonal grid, no warning.
    const std::vector<glm::dvec3> straight = stack({0.0, 0.0, 0.0});
    write_file(file, enhanced_ct(straight));
    const Loaded orthogonal = load(file);
    check_voxels_at_their_positions(orthogonal.volume, straight);
    CHECK(orthogonal.warnings.empty());
  }

  // ---- a damaged slice, wherever it is, is an error naming it

  TEST_CASE("dicom_damaged_first_middle_or_last_slice_is_an_error_naming_the_file") {
    const std::vector<glm::dvec3> positions = stack({0.0, 0.0, 0.0});
    const std::string slice_bytes = part10(ct_slice(positions[0], 0));
    struct Damage {
      const char* name;
      std::string bytes;
      const char* reason;
    };
    const std::vector<Damage> damages = {
        {"empty", "", "empty file in a DICOM folder"},
        {"zeros", std::string(slice_bytes.size(), '\0'), "no 'DICM' after the 128-byte preamble"},
        {"cut_in_preamble", slice_bytes.substr(0, 100), "only zero bytes"},
        {"cut_in_header", slice_bytes.substr(0, 300), "DICOM file is truncated"},
    };
    // IM0 is the first along the normal, IM1 the third, IM2 the last (file k is IM(3k % 5)).
    for (const char* file : {"IM0", "IM1", "IM2"})
      for (const Damage& damage : damages) {
        INFO(file, " ", damage.name);
        const fs::path folder = write_series(std::string("damaged_") + file, positions);
        write_file(folder / "README.txt", "five slices\n");  // not DICOM: skipped
        write_file(folder / file, damage.bytes);
        const std::string message = load_error(folder);
        INFO("message: ", message);
        CHECK(message.rfind((folder / file).string() + ": ", 0) == 0);
        CHECK(message.find(damage.reason) != std::string::npos);
      }
    const fs::path linked = write_series("missing_link", positions);
    fs::remove(linked / "IM2");
    fs::create_symlink(linked / "gone", linked / "IM2");
    CHECK(load_error(linked).rfind((linked / "IM2").string() + ": cannot read", 0) == 0);
    // The undamaged series loads whole.
    const Loaded whole = load(write_series("undamaged", positions));
    check_voxels_at_their_positions(whole.volume, positions);
  }

  // ---- pixel formats

  TEST_CASE("dicom_palette_color_and_impossible_bit_layouts_are_errors_naming_the_field") {
    const fs::path folder = output_folder("pixel_formats");
    const auto file = [&](const char* name, const DataSet& d) {
      return write_file(folder / name, part10(d));
    };
    DataSet palette = ct_slice({0, 0, 0}, 0);
    palette.set(0x0028, 0x0004, "CS", "PALETTE COLOR");
    CHECK_ERROR(file("palette_no_table.dcm", palette),
                "PhotometricInterpretation = PALETTE COLOR without a lookup table");
    for (int tag : {0x1101, 0x1102, 0x1103})
      palette.set(0x0028, uint16_t(tag), "US", bytes_of<uint16_t>({256, 0, 16}));
    for (int tag : {0x1201, 0x1202, 0x1203})
      palette.set(0x0028, uint16_t(tag), "OW", std::string(512, '\x10'));
    CHECK_ERROR(file("palette.dcm", palette),
                "PhotometricInterpretation = PALETTE COLOR: the pixel values are indices");
    DataSet rgb = ct_slice({0, 0, 0}, 0);
    rgb.set(0x0028, 0x0004, "CS", "RGB");
    CHECK_ERROR(file("rgb_one_sample.dcm", rgb), "PhotometricInterpretation = RGB");

    DataSet wide = ct_slice({0, 0, 0}, 0);
    wide.us(0x0028, 0x0101, 17);
    CHECK_ERROR(file("bits_stored_17.dcm", wide), "BitsStored = 17: must be 1 to BitsAllocated");
    DataSet high = ct_slice({0, 0, 0}, 0);
    high.us(0x0028, 0x0102, 40);
    CHECK_ERROR(file("high_bit_40.dcm", high), "HighBit = 40: must be BitsStored - 1 (15)");
    DataSet low = ct_slice({0, 0, 0}, 0);
    low.us(0x0028, 0x0101, 12).us(0x0028, 0x0102, 4);
    CHECK_ERROR(file("high_bit_4.dcm", low), "HighBit = 4: must be BitsStored - 1 (11)");

    DataSet short_pixels = ct_slice({0, 0, 0}, 0);
    short_pixels.set(0x7fe0, 0x0010, "OW", pixels(0).substr(0, 10));
    CHECK_ERROR(file("short.dcm", short_pixels), "PixelData has 10 bytes, Rows x Columns needs 24");
  }

  // 12 bits stored in bits 4 to 15 (HighBit 15), an overlay bit below them: the 12 bits are the
  // value.
  TEST_CASE("dicom_bits_stored_below_a_high_bit_at_the_top_are_moved_down") {
    DataSet d = ct_slice({0, 0, 0}, 0);
    d.us(0x0028, 0x0101, 12).us(0x0028, 0x0102, 15);
    std::vector<uint16_t> values;
    for (int n = 0; n < kColumns * kRows; ++n) values.push_back(uint16_t((n * 300) << 4 | 0x8));
    d.set(0x7fe0, 0x0010, "OW", bytes_of(values));
    const fs::path path = write_file(output_folder("high_bit_15") / "ct.dcm", part10(d));
    const Loaded loaded = load(path);
    for (int n = 0; n < kColumns * kRows; ++n)
      CHECK(loaded.volume.value(uint32_t(n % kColumns), uint32_t(n / kColumns), 0) ==
            float(n * 300));
  }

  // ---- a lone image without a position

  TEST_CASE("dicom_secondary_capture_without_position_opens_as_a_2d_image_with_a_warning") {
    DataSet d = ct_slice({0, 0, 0}, 3);
    d.set(0x0008, 0x0016, "UI", "1.2.840.10008.5.1.4.1.1.7").set(0x0008, 0x0060, "CS", "OT");
    d.erase(0x0020, 0x0032).erase(0x0020, 0x0037).erase(0x0028, 0x0030).erase(0x0018, 0x0050);
    const fs::path folder = output_folder("secondary_capture");
    const fs::path path = write_file(folder / "sc.dcm", part10(d));
    const Loaded loaded = load(path);
    const Volume& v = loaded.volume;
    CHECK(v.dims == glm::uvec3(kColumns, kRows, 1));
    CHECK(v.origin == glm::vec3(0.0f));
    CHECK(v.direction == glm::mat3(1.0f));
    CHECK(v.spacing == glm::vec3(1.0f));
    CHECK(v.value(3, 2, 0) == 311.0f);
    REQUIRE(loaded.warnings.size() == 2);
    CHECK(loaded.warnings[0].rfind(path.string() + ": ImagePositionPatient is missing", 0) == 0);
    CHECK(loaded.warnings[1].rfind(path.string() + ": 2-D image (one slice of 4x3)", 0) == 0);

    // ImagerPixelSpacing (a scanned film, a radiograph) gives the pixel size.
    d.set(0x0018, 0x1164, "DS", "0.2\\0.3");
    write_file(path, part10(d));
    CHECK(load(path).volume.spacing == glm::vec3(0.3f, 0.2f, 1.0f));

    // Two images without positions cannot be stacked.
    write_file(folder / "sc2.dcm", part10(d));
    CHECK(load_error(folder).find("ImagePositionPatient is missing: a slice of a series") !=
          std::string::npos);
  }
}
