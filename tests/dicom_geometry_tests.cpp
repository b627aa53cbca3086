// DICOM that loads right or not at all: sheared stacks keep each slice where its
// ImagePositionPatient puts it, positions rounded in the header still make an evenly spaced stack
// while a missing slice does not, a damaged slice anywhere in a folder is an error naming it and a
// skipped file is named in a warning, a series of several time points opens the one --frame
// chooses, pixel formats strata cannot show as grey values are refused, and a lone image without a
// position opens as a 2-D image. Every file is written here (explicit VR little endian, tiny
// images).
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

// One file per data set, IM0, IM1, ... in the order given.
fs::path write_slices(const std::string& name, const std::vector<DataSet>& slices) {
  const fs::path folder = output_folder(name);
  for (size_t k = 0; k < slices.size(); ++k)
    write_file(folder / ("IM" + std::to_string(k)), part10(slices[k]));
  return folder;
}

struct Loaded {
  Volume volume;
  std::vector<std::string> warnings;
};

Loaded load(const fs::path& path, const strata::VolumeReadOptions& options = {}) {
  Loaded loaded;
  loaded.volume = strata::load_volume(path, options, loaded.warnings);
  return loaded;
}

std::string load_error(const fs::path& path, const strata::VolumeReadOptions& options = {}) {
  return strata::test::error_of([&] { load(path, options); });
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

  // ---- positions rounded in the header

  // As a GE scanner writes an oblique MR series: 20 slices 7 mm apart, rows and columns turned by
  // 20° about z and 30° about x, positions printed to 0.1 mm, so steps of 6.90 to 7.04 mm.
  TEST_CASE("dicom_oblique_positions_rounded_to_a_tenth_of_a_millimetre_load_with_a_warning") {
    const glm::dvec3 row(0.9396926207859084, 0.3420201433256687, 0.0);
    const glm::dvec3 column(-0.29619813272602386, 0.8137976813493738, 0.5);
    const glm::dvec3 normal = glm::cross(row, column);
    const auto series = [&](const std::string& name, std::vector<double> along) {
      std::vector<DataSet> slices;
      for (size_t k = 0; k < along.size(); ++k) {
        const glm::dvec3 p = glm::dvec3(-101.37, 42.81, -18.53) + along[k] * normal;
        char position[64];
        std::snprintf(position, sizeof position, "%.1f\\%.1f\\%.1f", p.x, p.y, p.z);
        slices.push_back(ct_slice({}, int(k))
                             .set(0x0020, 0x0032, "DS", position)
                             .set(0x0020, 0x0037, "DS", ds(row) + "\\" + ds(column)));
      }
      return write_slices(name, slices);
    };
    std::vector<double> along;
    for (int k = 0; k < 20; ++k) along.push_back(7.0 * k);
    const fs::path folder = series("rounded", along);
    const Loaded loaded = load(folder);
    const Volume& v = loaded.volume;
    CHECK(v.dims == glm::uvec3(kColumns, kRows, 20));
    CHECK(v.spacing.z == doctest::Approx(7.0).epsilon(0.001));
    CHECK(glm::length(glm::dvec3(v.direction[2]) - normal) < 1e-5);  // not sheared
    CHECK(v.value(0, 0, 19) == 1900.0f);
    REQUIRE(loaded.warnings.size() == 1);
    INFO(loaded.warnings[0]);
    CHECK(loaded.warnings[0].starts_with(folder.string() +
                                         ": ImagePositionPatient: slice steps of 6.9 mm to 7.04 "
                                         "mm; the largest deviation from even spacing is 0.0977 "
                                         "mm (IM"));
    CHECK(loaded.warnings[0].find("within what rounding of the positions (printed to 0.1 mm) "
                                  "explains up to 0.151 mm: read as evenly spaced 7.0016") !=
          std::string::npos);

    // A missing slice, or one 0.4 mm out of place, is more than rounding explains.
    std::vector<double> gap = along;
    gap.erase(gap.begin() + 8);
    CHECK_ERROR(series("rounded_gap", gap), "slice spacing is not uniform: ");
    std::vector<double> moved = along;
    moved[10] += 0.4;
    const fs::path uneven = series("rounded_uneven", moved);
    CHECK_ERROR(uneven, "IM10 lies 0.");
    CHECK_ERROR(uneven,
                "from even spacing, more than rounding of the positions (printed to 0.1 mm) "
                "explains up to 0.151 mm (a missing slice, or slices at uneven distances)");
  }

  // ---- files that are not slices

  // Random bytes in place of the last slice: the rest loads, and the warning names the file.
  TEST_CASE("dicom_folder_names_every_skipped_file_in_one_warning") {
    const fs::path folder = write_series("skipped", stack({0.0, 0.0, 0.0}));
    std::string noise;
    for (int n = 0; n < 600; ++n) noise += char(n * 37 % 251 + 1);
    write_file(folder / "IM2", noise);  // the last along the normal
    write_file(folder / "README.txt", "five CT slices\n");
    write_file(folder / ".DS_Store", noise);  // hidden files are left out of the warning
    const Loaded loaded = load(folder);
    CHECK(loaded.volume.dims == glm::uvec3(kColumns, kRows, 4));
    CHECK(loaded.warnings ==
          std::vector<std::string>{folder.string() +
                                   ": skipped 2 files that are not DICOM images: IM2, README.txt"});
    // Many files: the first eight named on the one line.
    for (int n = 0; n < 20; ++n) write_file(folder / ("notes" + std::to_string(n + 10)), "x\n");
    const Loaded many = load(folder);
    REQUIRE(many.warnings.size() == 1);
    CHECK(many.warnings[0] == folder.string() +
                                  ": skipped 22 files that are not DICOM images: IM2, README.txt, "
                                  "notes10, notes11, notes12, notes13, notes14, notes15 and 14 "
                                  "more");
  }

  TEST_CASE("dicom_folder_whose_series_lies_in_subfolders_names_them") {
    const fs::path folder = output_folder("nested");
    const std::vector<glm::dvec3> positions = stack({0.0, 0.0, 0.0});
    for (size_t k = 0; k < positions.size(); ++k)
      write_file(folder / "DICOM" / "SE1" / ("IM" + std::to_string(k)),
                 part10(ct_slice(positions[k], int(k))));
    CHECK(load_error(folder) ==
          folder.string() +
              ": no DICOM files in the folder itself (it holds only subfolders); its subfolder "
              "DICOM/SE1 holds DICOM files: open " +
              (folder / "DICOM" / "SE1").string() +
              " (strata reads one folder's files as a series)");
    CHECK(load(folder / "DICOM" / "SE1").volume.dims.z == 5);
    fs::copy(folder / "DICOM" / "SE1", folder / "DICOM" / "SE2", fs::copy_options::recursive);
    write_file(folder / "README.txt", "two series\n");
    CHECK(load_error(folder) ==
          folder.string() +
              ": no DICOM files in the folder itself (none of its 1 files is a DICOM image); its "
              "subfolders DICOM/SE1, DICOM/SE2 hold DICOM files: open one of them (strata reads "
              "one folder's files as a series)");
  }

  // ---- several volumes in one series

  // Two time points of five slices each, told apart by TemporalPositionIdentifier or, without it,
  // by AcquisitionNumber; time point 1 stores 100 k + n + 1000.
  TEST_CASE("dicom_series_of_two_time_points_opens_the_one_frame_chooses") {
    for (const bool by_acquisition : {false, true}) {
      CAPTURE(by_acquisition);
      std::vector<DataSet> slices;
      const std::vector<glm::dvec3> positions = stack({0.0, 0.0, 0.0});
      for (int t : {1, 0})  // the files of the later time point first
        for (size_t k = 0; k < positions.size(); ++k) {
          DataSet d = ct_slice(positions[k], int(k) + 10 * t);
          d.set(0x0020, by_acquisition ? 0x0012 : 0x0100, "IS", std::to_string(t + 1));
          slices.push_back(d);
        }
      const fs::path folder = write_slices("time_points", slices);
      const char* element = by_acquisition ? "AcquisitionNumber" : "TemporalPositionIdentifier";
      const Loaded first = load(folder);
      check_voxels_at_their_positions(first.volume, positions);
      CHECK(first.warnings ==
            std::vector<std::string>{folder.string() +
                                     ": the series holds 2 time points (its slices repeat their "
                                     "positions, " +
                                     element + " tells them apart); showing time point 0 (" +
                                     element + " 1; choose with --frame 0 to 1)"});
      const Loaded second = load(folder, {.frame = 1});
      CHECK(second.volume.dims == glm::uvec3(kColumns, kRows, 5));
      CHECK(second.volume.value(1, 0, 4) == 1401.0f);
      CHECK(second.warnings[0].find("showing time point 1 (" + std::string(element) + " 2;") !=
            std::string::npos);
      CHECK(load_error(folder, {.frame = 2}) ==
            folder.string() + ": frame 2 is out of range: the series holds 2 time points, 0 to 1");
      CHECK(strata::list_dicom_series_isolated(folder).at(0).time_points == 2);
    }
    CHECK(load_error(write_series("one_time_point", stack({0.0, 0.0, 0.0})), {.frame = 1})
              .ends_with(": frame 1 is out of range: the image has one frame, 0"));
  }

  TEST_CASE("dicom_slices_at_one_position_say_what_tells_them_apart") {
    const std::vector<glm::dvec3> positions = stack({0.0, 0.0, 0.0}, 3);
    std::vector<DataSet> slices;
    for (int echo : {1, 2})
      for (size_t k = 0; k < positions.size(); ++k)
        slices.push_back(
            ct_slice(positions[k], int(k)).set(0x0018, 0x0086, "IS", std::to_string(echo)));
    CHECK_ERROR(write_slices("echoes", slices),
                " are at the same position (30 mm along the normal) and differ in EchoNumbers "
                "(1, 2): the series holds several volumes; split it into one folder a volume "
                "(dcm2niix does) and open one");
    // A copy of a slice, and a slice repeated under another SOPInstanceUID.
    slices.resize(3);
    slices.push_back(slices[1]);
    for (size_t k = 0; k < slices.size(); ++k) slices[k].set(0x0008, 0x0018, "UI", "1.2.3");
    CHECK_ERROR(write_slices("copied", slices),
                "IM1 and IM3 are at the same position (32.5 mm along the normal): the same image "
                "twice (one SOPInstanceUID), a copied file; remove one");
    slices[3].set(0x0008, 0x0018, "UI", "1.2.4");
    CHECK_ERROR(write_slices("repeated", slices),
                "IM1 and IM3 are at the same position (32.5 mm along the normal): a repeated "
                "slice (no TemporalPositionIdentifier");
  }
}
