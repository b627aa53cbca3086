// Names tables (parse_names_table: every form from text written here, and its errors), the label
// table in a NIfTI header extension (files with extension chains built here), and FreeSurfer's
// MGH volumes (a .mgz written here with a known geometry, and nibabel's test.mgz).
#include <doctest/doctest.h>
#include <zlib.h>

#include <array>
#include <bit>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "engine/scene/io/volume_loader.h"
#include "engine/scene/segmentation.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using strata::NamesTable;
using strata::test::error_of;
using strata::test::write_file;

NamesTable parse(std::string_view text, const fs::path& file = "table.txt") {
  return strata::parse_names_table(text, file);
}

std::string parse_error(std::string_view text, const fs::path& file = "table.txt") {
  return error_of([&] { parse(text, file); });
}

void check_colour(const strata::NamedValue& entry, int r, int g, int b) {
  REQUIRE(entry.colour.has_value());
  CHECK(entry.colour->r == doctest::Approx(r / 255.0));
  CHECK(entry.colour->g == doctest::Approx(g / 255.0));
  CHECK(entry.colour->b == doctest::Approx(b / 255.0));
}

fs::path output_folder(const std::string& name) {
  return strata::test::fresh_folder("names_table", name);
}

void write_gzip(const fs::path& path, const std::string& bytes) {
  gzFile file = gzopen(path.c_str(), "wb");
  REQUIRE(file != nullptr);
  CHECK(gzwrite(file, bytes.data(), unsigned(bytes.size())) == int(bytes.size()));
  CHECK(gzclose(file) == Z_OK);
}

// Bytes of a value in the given byte order.
template <class T>
std::string bytes_of(T value, bool big_endian) {
  std::array<char, sizeof(T)> raw;
  std::memcpy(raw.data(), &value, sizeof(T));
  if (big_endian != (std::endian::native == std::endian::big)) std::reverse(raw.begin(), raw.end());
  return std::string(raw.data(), raw.size());
}

template <class T>
void put(std::string& bytes, size_t offset, T value, bool big_endian) {
  bytes.replace(offset, sizeof(T), bytes_of(value, big_endian));
}

// ---- NIfTI files with extensions

struct Extension {
  int32_t code = 0;
  std::string data;   // padded with NULs to esize
  int32_t esize = 0;  // 0: the padded size + 8
};

std::string extension_chain(const std::vector<Extension>& extensions, bool big_endian) {
  std::string chain;
  for (const Extension& e : extensions) {
    std::string data = e.data;
    data.resize((data.size() + 8 + 15) / 16 * 16 - 8, '\0');
    const int32_t esize = e.esize ? e.esize : int32_t(data.size() + 8);
    chain += bytes_of(esize, big_endian) + bytes_of(e.code, big_endian) + data;
  }
  return chain;
}

// A 2x2x2 uint8 NIfTI-1 (or -2) image whose extensions are `chain`; vox_offset right after them
// unless given.
std::string nifti_with_extensions(const std::string& chain, int version = 1,
                                  bool big_endian = false, double vox_offset = -1) {
  const size_t header_bytes = version == 1 ? 348 : 540;
  std::string bytes(header_bytes, '\0');
  const double offset = vox_offset >= 0 ? vox_offset : double(header_bytes + 4 + chain.size());
  put(bytes, 0, int32_t(header_bytes), big_endian);
  if (version == 1) {
    for (size_t i = 0; i < 4; ++i) put(bytes, 40 + 2 * i, int16_t(i == 0 ? 3 : 2), big_endian);
    put(bytes, 70, int16_t(2), big_endian);  // uint8
    put(bytes, 72, int16_t(8), big_endian);
    for (size_t i = 0; i < 4; ++i) put(bytes, 76 + 4 * i, 1.0f, big_endian);
    put(bytes, 108, float(offset), big_endian);
    bytes.replace(344, 4, std::string("n+1\0", 4));
  } else {
    bytes.replace(4, 8, std::string("n+2\0\r\n\032\n", 8));
    put(bytes, 12, int16_t(2), big_endian);
    put(bytes, 14, int16_t(8), big_endian);
    for (size_t i = 0; i < 4; ++i) put(bytes, 16 + 8 * i, int64_t(i == 0 ? 3 : 2), big_endian);
    for (size_t i = 0; i < 4; ++i) put(bytes, 104 + 8 * i, 1.0, big_endian);
    put(bytes, 168, int64_t(offset), big_endian);
  }
  bytes += std::string(4, '\0');
  if (!chain.empty()) bytes[header_bytes] = 1;
  bytes += chain;
  bytes += std::string(8, '\x07');  // the voxels
  return bytes;
}

// TotalSegmentator's form: an XML declaration, CDATA names, colours as fractions of 255.
const std::string kTotalSegmentatorXml =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?> <CaretExtension>  <Date><![CDATA[2013-07-14T05:"
    "45:09]]></Date>   <VolumeInformation Index=\"0\">   <LabelTable>\n"
    "<Label Key=\"1\" Red=\"0.0\" Green=\"1.0\" Blue=\"0.0\" Alpha=\"1\"><![CDATA[spleen]]>"
    "</Label>\n"
    "<Label Key=\"2\" Red=\"0.0\" Green=\"0.0\" Blue=\"1.0\" Alpha=\"1\"><![CDATA[kidney_right]]>"
    "</Label>\n"
    "<Label Key=\"117\" Red=\"0.7254901960784313\" Green=\"0.6666666666666666\" "
    "Blue=\"0.6078431372549019\" Alpha=\"1\"><![CDATA[costal cartilages]]></Label>\n"
    "  </LabelTable>  <StudyMetaDataLinkSet>  </StudyMetaDataLinkSet>  <VolumeType><![CDATA["
    "Label]]></VolumeType>   </VolumeInformation></CaretExtension>\n              ";

void check_total_segmentator_table(const std::optional<NamesTable>& table) {
  REQUIRE(table.has_value());
  CHECK(table->format == "NIfTI label table (TotalSegmentator)");
  REQUIRE(table->entries.size() == 3);
  CHECK(table->entries[0].value == 1);
  CHECK(table->entries[0].name == "spleen");
  check_colour(table->entries[0], 0, 255, 0);
  CHECK(table->entries[1].name == "kidney_right");
  CHECK(table->entries[2].value == 117);
  CHECK(table->entries[2].name == "costal cartilages");
  check_colour(table->entries[2], 185, 170, 155);
}

// ---- MGH files

struct Mgh {
  std::array<int32_t, 4> dims{};  // width, height, depth, nframes
  int32_t type = 0;
  int16_t good_ras = 1;
  std::array<float, 3> size{1, 1, 1};
  std::array<float, 9> mdc{-1, 0, 0, 0, 0, -1, 0, 1, 0};  // x_r x_a x_s y_r y_a y_s z_r z_a z_s
  std::array<float, 3> c_ras{};
  int32_t version = 1;

  std::string header() const {
    std::string bytes(284, '\0');
    put(bytes, 0, version, true);
    for (size_t i = 0; i < 4; ++i) put(bytes, 4 + 4 * i, dims[i], true);
    put(bytes, 20, type, true);
    put(bytes, 28, good_ras, true);
    for (size_t i = 0; i < 3; ++i) put(bytes, 30 + 4 * i, size[i], true);
    for (size_t i = 0; i < 9; ++i) put(bytes, 42 + 4 * i, mdc[i], true);
    for (size_t i = 0; i < 3; ++i) put(bytes, 78 + 4 * i, c_ras[i], true);
    return bytes;
  }
};

glm::vec3 world_of(const strata::Volume& v, glm::vec3 index) {
  return glm::vec3(v.index_to_world() * glm::vec4(index, 1.0f));
}

void check_position(glm::vec3 actual, glm::vec3 expected) {
  CHECK(actual.x == doctest::Approx(expected.x).epsilon(1e-5));
  CHECK(actual.y == doctest::Approx(expected.y).epsilon(1e-5));
  CHECK(actual.z == doctest::Approx(expected.z).epsilon(1e-5));
}

}  // namespace

TEST_SUITE("segmentation") {
  // ---- names tables, each form

  TEST_CASE("names table: ITK-SNAP label descriptions keep names with spaces, quotes, UTF-8") {
    const NamesTable t = parse(
        "################################################\n"
        "# ITK-SnAP Label Description File\n"
        "# IDX   -R-  -G-  -B-  -A--  VIS MSH  LABEL\n"
        "################################################\n"
        "    0     0    0    0        0  0  0    \"Clear Label\"\n"
        "    1   255    0    0        1  1  1    \"Liver\"\n"
        "    2     0  128  255     0.75  1  0    \"Vena cava \"inferior\"\"\r\n"
        "   17    12   34   56        1  1  1    \"Lebergef\xC3\xA4\xC3\x9F "
        "\xE8\x82\x9D\xE8\x87\x93\"\n");
    CHECK(t.format == "ITK-SNAP label descriptions");
    REQUIRE(t.entries.size() == 4);
    CHECK(t.entries[0].value == 0);
    CHECK(t.entries[0].name == "Clear Label");
    CHECK(t.entries[1].name == "Liver");
    check_colour(t.entries[1], 255, 0, 0);
    CHECK(t.entries[2].name == "Vena cava \"inferior\"");
    check_colour(t.entries[2], 0, 128, 255);
    CHECK(t.entries[3].value == 17);
    CHECK(t.entries[3].name == "Lebergef\xC3\xA4\xC3\x9F \xE8\x82\x9D\xE8\x87\x93");
  }

  TEST_CASE("names table: 3D Slicer colour table keeps underscores and reads 0..255 colours") {
    const NamesTable t = parse(
        "# Color table file C:/Users/someone/Segmentation-label_ColorTable.ctbl\n"
        "# 4 values\n"
        "0 Background 0 0 0 0\n"
        "1 artery 216 101 79 255\n"
        "2 connective_tissue 111 184 210 255\n");
    CHECK(t.format == "3D Slicer colour table");
    REQUIRE(t.entries.size() == 3);
    CHECK(t.entries[1].name == "artery");
    check_colour(t.entries[1], 216, 101, 79);
    CHECK(t.entries[2].name == "connective_tissue");
    // Without a header, the extension tells a .ctbl; a .txt stays a generic colour table.
    const std::string body = "1 artery 216 101 79 255\n";
    CHECK(parse(body, "labels.ctbl").format == "3D Slicer colour table");
    CHECK(parse(body, "labels.txt").format == "colour table (value name R G B A)");
  }

  TEST_CASE("names table: FreeSurferColorLUT is told from its comment header") {
    const NamesTable t = parse(
        "#$Id: FreeSurferColorLUT.txt,v 1.70 2012/08/27 17:20:08 nicks Exp $\n"
        "\n"
        "#No. Label Name:                            R   G   B   A\n"
        "\n"
        "0   Unknown                                 0   0   0   0\n"
        "2   Left-Cerebral-White-Matter              245 245 245 0\n"
        "14175 wm_rh_S_temporal_transverse          221 60  60  0\n");
    CHECK(t.format == "FreeSurfer colour table");
    REQUIRE(t.entries.size() == 3);
    CHECK(t.entries[1].name == "Left-Cerebral-White-Matter");
    check_colour(t.entries[1], 245, 245, 245);
    CHECK(t.entries[2].value == 14175);
  }

  TEST_CASE("names table: 3D Slicer CSV follows CSV quoting and ignores terminology columns") {
    const NamesTable t = parse(
        "LabelValue,Name,Color_R,Color_G,Color_B,Color_A,Category,Type\n"
        "1,liver,221,130,101,255,\"SCT,123037004,Anatomical Structure\",x\n"
        "2,\"kidney, left\",185,102,83,255,,\n"
        "\n"
        "3,\"the \"\"big\"\" one\",0,0,255,255,,\n"
        "4,\"two\nlines\",1,2,3,255,,\n"
        "5,\xC3\xB6sophagus,4,5,6,255,,\n",
        "colours.csv");
    CHECK(t.format == "3D Slicer colour table (CSV)");
    REQUIRE(t.entries.size() == 5);
    CHECK(t.entries[0].name == "liver");
    check_colour(t.entries[0], 221, 130, 101);
    CHECK(t.entries[1].name == "kidney, left");
    CHECK(t.entries[2].name == "the \"big\" one");
    CHECK(t.entries[3].name == "two\nlines");
    CHECK(t.entries[4].name == "\xC3\xB6sophagus");
    // A record after a quoted line break is counted from the line it starts on.
    CHECK(parse_error("LabelValue,Name,Color_R,Color_G,Color_B\n1,\"a\nb\",1,2,3\n2,c,1,2,x\n",
                      "t.csv") == "t.csv: line 4: blue 'x' is not an integer 0..255");
  }

  TEST_CASE("names table: AAL's index name colour has no RGB colour") {
    const NamesTable t = parse("1 Precentral_L 2001\r\n2 Precentral_R 2002\r\n");
    CHECK(t.format == "AAL names (index name colour)");
    REQUIRE(t.entries.size() == 2);
    CHECK(t.entries[0].value == 1);
    CHECK(t.entries[0].name == "Precentral_L");
    CHECK_FALSE(t.entries[0].colour.has_value());
    const fs::path aal = fs::path(STRATA_DATA_CACHE) / "mricron/aal.nii.txt";
    REQUIRE_MESSAGE(fs::exists(aal), "run scripts/fetch-data.sh");
    const NamesTable real = strata::load_names_table(aal);
    CHECK(real.entries.size() == 116);
    CHECK(real.entries.back().value == 116);
    CHECK(real.entries.back().name == "Vermis_10");
  }

  TEST_CASE("names table: nnU-Net dataset.json v2 and v1, region lists left out") {
    const NamesTable v2 = parse(R"({"channel_names": {"0": "CT"},
        "labels": {"background": 0, "liver": 1, "tumour core": [1, 2], "Milz \u00e4": 2},
        "numTraining": 3, "file_ending": ".nii.gz"})",
                                "dataset.json");
    CHECK(v2.format == "nnU-Net dataset.json");
    REQUIRE(v2.entries.size() == 3);
    CHECK(v2.entries[1].value == 1);
    CHECK(v2.entries[1].name == "liver");
    CHECK(v2.entries[2].value == 2);
    CHECK(v2.entries[2].name == "Milz \xC3\xA4");
    CHECK_FALSE(v2.entries[2].colour.has_value());
    const NamesTable v1 = parse(R"({"modality": {"0": "CT"},
        "labels": {"0": "background", "1": "liver", "2": "liver tumour"}})");
    CHECK(v1.format == "nnU-Net dataset.json (v1)");
    REQUIRE(v1.entries.size() == 3);
    CHECK(v1.entries[2].value == 2);
    CHECK(v1.entries[2].name == "liver tumour");
  }

  TEST_CASE("names table: MONAI channel_def is found under the outputs, not the inputs") {
    const NamesTable t = parse(R"({"version": "0.1", "network_data_format": {
        "inputs": {"image": {"type": "image", "channel_def": {"0": "image"}}},
        "outputs": {"pred": {"type": "image", "channel_def": {"0": "background", "1": "spleen"}}}
      }})",
                               "metadata.json");
    CHECK(t.format == "MONAI bundle channel_def");
    REQUIRE(t.entries.size() == 2);
    CHECK(t.entries[1].value == 1);
    CHECK(t.entries[1].name == "spleen");
  }

  TEST_CASE("names table: load_names_table reads a file; a byte order mark is no content") {
    const fs::path folder = output_folder("load");
    const fs::path path = write_file(folder / "labels.txt", "\xEF\xBB\xBF# c\n1 a 1 2 3 4\n");
    const NamesTable t = strata::load_names_table(path);
    REQUIRE(t.entries.size() == 1);
    CHECK(t.entries[0].name == "a");
    CHECK(error_of([&] { strata::load_names_table(folder / "missing.txt"); }) ==
          (folder / "missing.txt").string() + ": no such file");
  }

  // ---- names tables, errors

  TEST_CASE("names table: malformed lines name their line and what was expected") {
    CHECK(parse_error("# x\n1 a 1 2 3 4\n2 b 1 2\n") ==
          "table.txt: line 3: expected 'value name R G B A', got '2 b 1 2'");
    CHECK(parse_error("  1  255 0 0  1 1 1 \"a\"\n  2 0 0 0 1 1 \"b\"\n") ==
          "table.txt: line 2: expected 'IDX R G B A VIS MSH \"LABEL\"', got '  2 0 0 0 1 1 \"b\"'");
    CHECK(parse_error("  1 255 0 0 1 1 1 \"a\" x\n") ==
          "table.txt: line 1: expected 'IDX R G B A VIS MSH \"LABEL\"', got '  1 255 0 0 1 1 1 "
          "\"a\" x'");
    CHECK(parse_error("  1 255 0 0 1.5 1 1 \"a\"\n") ==
          "table.txt: line 1: alpha '1.5' is not a number 0..1");
    CHECK(parse_error("  1 255 0 0 1 2 1 \"a\"\n") == "table.txt: line 1: VIS '2' is not 0 or 1");
    CHECK(parse_error("1 a 256 0 0 255\n") ==
          "table.txt: line 1: red '256' is not an integer 0..255");
    CHECK(parse_error("1 a 1 2 3 -1\n") ==
          "table.txt: line 1: alpha '-1' is not an integer 0..255");
    CHECK(parse_error("1 a\nx b\n") == "table.txt: line 2: value 'x' is not an integer");
    CHECK(parse_error("1 a\n2 b c\n") ==
          "table.txt: line 2: expected 'index name colour', got '2 b c'");
    CHECK(parse_error("LabelValue,Name,Color_R,Color_G,Color_B\n1,a,1,2\n", "t.csv") ==
          "t.csv: line 2: expected 5 columns, got 4");
    CHECK(parse_error("LabelValue,Name\n1,\"a\n", "t.csv") ==
          "t.csv: line 2: a quoted field is not closed");
    CHECK(parse_error("LabelValue,Color_R\n1,2\n", "t.csv") ==
          "t.csv: line 1: no Name column: a names table needs names");
    CHECK(parse_error("1 \xE9t\xE9 1 2 3 4\n") ==
          "table.txt: line 1: the name is not UTF-8 text (save the file as UTF-8)");
  }

  TEST_CASE("names table: duplicate values and values outside 0..65535 are errors") {
    CHECK(parse_error("1 a\n2 b\n1 c\n") ==
          "table.txt: line 3: value 1 is named twice (first at line 1)");
    CHECK(parse_error("65536 a\n") == "table.txt: line 1: value 65536 is outside 0..65535");
    CHECK(parse_error("-1 a 0 0 0 0\n") == "table.txt: line 1: value -1 is outside 0..65535");
    CHECK(parse_error("99999999999999999999 a\n") ==
          "table.txt: line 1: value '99999999999999999999' is not an integer");
    CHECK(parse_error(R"({"labels": {"a": 1, "b": 1}})") ==
          "table.txt: labels.'b': value 1 is named twice (first at labels.'a')");
    CHECK(parse_error(R"({"labels": {"a": 70000}})") ==
          "table.txt: labels.'a': value 70000 is outside 0..65535");
    CHECK(parse_error(R"({"labels": {"1": "a", "x": "b"}})") ==
          "table.txt: labels.'x': a v1 label's key must be its value (an integer)");
    CHECK(parse_error(R"({"labels": {"a": 1.5}})") ==
          "table.txt: labels.'a': expected an integer value (or a list of them), got 1.5");
    CHECK(parse_error(R"({"x": {"channel_def": {"0": 3}}})") ==
          "table.txt: x.channel_def.'0': expected the channel's name, got 3");
  }

  TEST_CASE("names table: an empty table and a file of no form are errors") {
    CHECK(parse_error("") == "table.txt: no entries: the names table is empty");
    CHECK(parse_error("# only\n# comments\n\n") ==
          "table.txt: no entries: the names table is empty");
    CHECK(parse_error(R"({"labels": {}})") == "table.txt: no entries: the names table is empty");
    CHECK(parse_error(R"({"labels": {"both": [1, 2]}})") ==
          "table.txt: no entries: the names table is empty");
    CHECK(parse_error("LabelValue,Name\n", "t.csv") ==
          "t.csv: no entries: the names table is empty");
    const std::string not_a_table = parse_error("hello world, this is prose\n");
    CHECK(
        not_a_table.starts_with("table.txt: line 1: not a names table: expected an ITK-SNAP label "
                                "description file, a 3D Slicer colour table"));
    CHECK(not_a_table.find("nnU-Net dataset.json") != std::string::npos);
    CHECK(parse_error("a,b,c\n1,2,3\n", "t.csv")
              .starts_with(
                  "t.csv: line 1: not a names table: a CSV colour table starts with the header "
                  "'LabelValue,Name,Color_R,Color_G,Color_B,Color_A'"));
    CHECK(parse_error(R"({"name": "x"})")
              .starts_with("table.txt: not a names table: JSON without \"labels\" (nnU-Net) or "
                           "\"channel_def\""));
    CHECK(parse_error("{\"labels\": ").starts_with("table.txt: parse error at line 1"));
  }

  // ---- the label table in a NIfTI header extension

  TEST_CASE("names table: NIfTI extension chain with the XML table second, .nii and .nii.gz") {
    const std::string chain = extension_chain(
        {{.code = 6, .data = "a comment, not a table"}, {.code = 0, .data = kTotalSegmentatorXml}},
        false);
    const std::string bytes = nifti_with_extensions(chain);
    const fs::path folder = output_folder("nifti_extensions");
    const fs::path nii = write_file(folder / "seg.nii", bytes);
    check_total_segmentator_table(strata::nifti_label_table(nii));
    const fs::path gz = folder / "seg.nii.gz";
    write_gzip(gz, bytes);
    check_total_segmentator_table(strata::nifti_label_table(gz));
    // The volume reader still finds the voxels after the extensions.
    const strata::Volume v = strata::load_volume(gz);
    CHECK(v.dims == glm::uvec3(2, 2, 2));
    CHECK(v.value(1, 1, 1) == 7.0f);
  }

  TEST_CASE("names table: NIfTI extensions in big-endian NIfTI-1 and in NIfTI-2") {
    const std::string be_chain = extension_chain({{.code = 0, .data = kTotalSegmentatorXml}}, true);
    check_total_segmentator_table(
        strata::nifti_label_table_from_bytes(nifti_with_extensions(be_chain, 1, true), "be.nii"));
    const std::string chain = extension_chain(
        {{.code = 4, .data = "<x/>"}, {.code = 32, .data = kTotalSegmentatorXml}}, false);
    const fs::path path =
        write_file(output_folder("nifti2") / "seg.nii", nifti_with_extensions(chain, 2));
    check_total_segmentator_table(strata::nifti_label_table(path));
  }

  TEST_CASE("names table: NIfTI without extensions or without a table has none") {
    CHECK_FALSE(strata::nifti_label_table_from_bytes(nifti_with_extensions(""), "a.nii"));
    const std::string chain = extension_chain({{.code = 6, .data = "just a comment"}}, false);
    CHECK_FALSE(strata::nifti_label_table_from_bytes(nifti_with_extensions(chain), "b.nii"));
    // Zero padding after the chain, before vox_offset, is not an extension.
    const std::string padded = nifti_with_extensions(chain + std::string(32, '\0'));
    CHECK_FALSE(strata::nifti_label_table_from_bytes(padded, "c.nii"));
    const fs::path ch2 = fs::path(STRATA_DATA_CACHE) / "mricron/ch2.nii.gz";
    REQUIRE_MESSAGE(fs::exists(ch2), "run scripts/fetch-data.sh");
    CHECK_FALSE(strata::nifti_label_table(ch2));
  }

  TEST_CASE("names table: a broken NIfTI extension chain names the file and the extension") {
    const auto error = [](const std::string& bytes) {
      return error_of([&] { strata::nifti_label_table_from_bytes(bytes, "s.nii"); });
    };
    const std::string first = extension_chain({{.code = 6, .data = "comment"}}, false);
    CHECK(error(nifti_with_extensions(
              first + extension_chain({{.code = 0, .data = "x", .esize = 20}}, false))) ==
          "s.nii: extension 2: esize = 20 is not a positive multiple of 16 (the chain is broken)");
    CHECK(error(nifti_with_extensions(
              extension_chain({{.code = 0, .data = "x", .esize = -16}}, false))) ==
          "s.nii: extension 1: esize = -16 is not a positive multiple of 16 (the chain is broken)");
    CHECK(error(nifti_with_extensions(
              first + extension_chain({{.code = 0, .data = "x", .esize = 64}}, false))) ==
          "s.nii: extension 2: esize = 64 at byte 368 runs past vox_offset (384)");
    // vox_offset past the file's end: the chain runs out of bytes.
    const std::string cut = nifti_with_extensions(first, 1, false, 4000).substr(0, 360);
    CHECK(error(cut) ==
          "s.nii: extension 1: esize = 16 at byte 352 runs past the file's end "
          "(360 bytes)");
    const std::string broken_xml = extension_chain(
        {{.code = 0, .data = "<LabelTable><Label Key=\"1\">a</LabelTable>"}}, false);
    CHECK(error(nifti_with_extensions(broken_xml))
              .starts_with("s.nii: extension 1: the label table's XML is malformed: "));
    const std::string bad_key = extension_chain(
        {{.code = 0, .data = "<LabelTable><Label Key=\"one\">a</Label></LabelTable>"}}, false);
    CHECK(error(nifti_with_extensions(bad_key)) ==
          "s.nii: extension 1: a Label's Key 'one' is not an integer");
    const std::string bad_colour = extension_chain(
        {{.code = 0,
          .data = "<LabelTable><Label Key=\"3\" Red=\"2\" Green=\"0\" Blue=\"0\">a</Label>"
                  "</LabelTable>"}},
        false);
    CHECK(error(nifti_with_extensions(bad_colour)) ==
          "s.nii: extension 1: Label Key=\"3\": Red '2' is not a number 0..1");
    const std::string twice =
        extension_chain({{.code = 0,
                          .data = "<LabelTable><Label Key=\"3\">a</Label><Label Key=\"3\">b</Label>"
                                  "</LabelTable>"}},
                        false);
    CHECK(error(nifti_with_extensions(twice)) ==
          "s.nii: extension 1: Label Key=\"3\": value 3 is named twice (first at extension 1: "
          "Label Key=\"3\")");
    CHECK(error(std::string(100, '\0')) ==
          "s.nii: not a NIfTI file: sizeof_hdr is 0 (expected 348 or 540)");
  }

  // ---- FreeSurfer MGH

  TEST_CASE("MGH: a .mgz written here gives its voxels and the world positions of its corners") {
    // x along anterior, y along right-to-left, z superior; 2, 3, 4 mm; centre voxel at c_ras.
    Mgh mgh{.dims = {3, 2, 2, 1},
            .type = 4,  // short
            .size = {2, 3, 4},
            .mdc = {0, 1, 0, -1, 0, 0, 0, 0, 1},
            .c_ras = {10, 20, 30}};
    std::string bytes = mgh.header();
    for (int16_t v = 0; v < 12; ++v) bytes += bytes_of(int16_t(v * 100 - 300), true);
    bytes += std::string(20, '\0');  // scan parameters after the voxels
    const fs::path path = output_folder("mgz") / "brain.mgz";
    write_gzip(path, bytes);
    std::vector<std::string> warnings;
    const strata::Volume v = strata::load_volume(path, {}, warnings);
    CHECK(warnings.empty());
    CHECK(v.name == "brain");
    CHECK(v.dims == glm::uvec3(3, 2, 2));
    CHECK(v.type == strata::VoxelType::int16);
    CHECK(v.spacing == glm::vec3(2, 3, 4));
    CHECK(v.value(0, 0, 0) == -300.0f);
    CHECK(v.value(2, 1, 1) == 800.0f);
    CHECK(v.value(1, 0, 1) == 400.0f);
    // RAS = c_ras + Mdc diag(size) (index - dims/2); LPS negates x and y.
    const auto expected = [](glm::vec3 index) {
      const glm::vec3 d = index - glm::vec3(1.5f, 1.0f, 1.0f);
      const glm::vec3 ras = glm::vec3(10, 20, 30) + glm::vec3(-3 * d.y, 2 * d.x, 4 * d.z);
      return glm::vec3(-ras.x, -ras.y, ras.z);
    };
    for (const glm::vec3 corner : {glm::vec3(0, 0, 0), glm::vec3(2, 0, 0), glm::vec3(0, 1, 0),
                                   glm::vec3(0, 0, 1), glm::vec3(2, 1, 1)})
      check_position(world_of(v, corner), expected(corner));
  }

  TEST_CASE("MGH: uchar, int and float voxels; no goodRASflag is FreeSurfer's 1 mm LIA at 0") {
    const fs::path folder = output_folder("mgh_types");
    Mgh mgh{.dims = {2, 2, 1, 1}, .type = 0, .good_ras = 0, .size = {7, 7, 7}};
    const fs::path uchar = write_file(folder / "u.mgh", mgh.header() + "\x01\x02\x03\xff");
    std::vector<std::string> warnings;  // (2-D images)
    const strata::Volume u = strata::load_volume(uchar, {}, warnings);
    CHECK(u.type == strata::VoxelType::uint8);
    CHECK(u.value(1, 1, 0) == 255.0f);
    CHECK(u.spacing == glm::vec3(1.0f));
    // LIA: x to the left, y inferior, z anterior; centre voxel (1, 1, 0.5) at 0.
    check_position(world_of(u, {1, 1, 0.5f}), {0, 0, 0});
    check_position(world_of(u, {0, 0, 0}), {-1, 0.5f, 1});  // RAS (1, -0.5, 1)
    mgh = {.dims = {2, 1, 1, 1}, .type = 1};
    const fs::path ints =
        write_file(folder / "i.mgh",
                   mgh.header() + bytes_of(int32_t(-70000), true) + bytes_of(int32_t(5), true));
    const strata::Volume i = strata::load_volume(ints, {}, warnings);
    CHECK(i.type == strata::VoxelType::float32);
    CHECK(i.value(0, 0, 0) == -70000.0f);
    mgh.type = 3;
    const fs::path floats =
        write_file(folder / "f.mgh", mgh.header() + bytes_of(1.5f, true) + bytes_of(-2.25f, true));
    CHECK(strata::load_volume(floats, {}, warnings).value(1, 0, 0) == -2.25f);
  }

  TEST_CASE("MGH: nibabel's test.mgz matches what nibabel reports") {
    // nibabel 5.0 (Debian 12): shape (3, 4, 5, 2), >f4, zooms 1 1 1, Mdc rows (1 2 3), (2 3 1),
    // (3 1 2) (not unit vectors: each axis is sqrt(14) mm), affine translation (-13, -11.5, -11.5),
    // voxel [2, 3, 4] at RAS (7, 5.5, 5.5); frame 0 from -1.7049814 to 2.4723177.
    const fs::path path = fs::path(STRATA_DATA_CACHE) / "nibabel/test.mgz";
    REQUIRE_MESSAGE(fs::exists(path), "run scripts/fetch-data.sh");
    std::vector<std::string> warnings;
    const strata::Volume v = strata::load_volume(path, {}, warnings);
    REQUIRE(warnings.size() == 1);
    CHECK(warnings[0].find("4-D image with 2 frames; showing frame 0") != std::string::npos);
    CHECK(v.dims == glm::uvec3(3, 4, 5));
    CHECK(v.type == strata::VoxelType::float32);
    CHECK(v.spacing.x == doctest::Approx(std::sqrt(14.0)));
    CHECK(v.spacing.z == doctest::Approx(std::sqrt(14.0)));
    CHECK(v.value(0, 0, 0) == 1.2125553f);
    CHECK(v.value(1, 2, 3) == -0.3047007f);
    CHECK(v.value(2, 3, 4) == -0.6455578f);
    CHECK(v.value_range == glm::vec2(-1.7049814f, 2.4723177f));
    check_position(world_of(v, {0, 0, 0}), {13, 11.5f, -11.5f});
    check_position(world_of(v, {2, 3, 4}), {-7, -5.5f, 5.5f});
    check_position(world_of(v, {1, 0, 0}), {12, 9.5f, -8.5f});  // + (1, 2, 3) RAS
    const strata::Volume second = strata::load_volume(path, {.frame = 1}, warnings);
    CHECK(second.value(0, 0, 0) == 0.96569985f);
    CHECK(second.value(2, 3, 4) == -0.71521044f);
  }

  TEST_CASE("MGH: bad headers and short data give one error naming the file and the reason") {
    const fs::path folder = output_folder("mgh_errors");
    const auto error = [&](const std::string& name, const std::string& bytes) {
      const fs::path path = write_file(folder / name, bytes);
      return error_of([&] { strata::load_volume(path); });
    };
    const Mgh good{.dims = {2, 2, 2, 1}, .type = 0};
    const std::string voxels(8, '\x01');
    CHECK(error("short.mgh", good.header().substr(0, 100)) ==
          (folder / "short.mgh").string() + ": header is truncated: 100 of 284 bytes");
    Mgh bad = good;
    bad.version = 2;
    CHECK(error("version.mgh", bad.header() + voxels) ==
          (folder / "version.mgh").string() +
              ": version = 2: expected 1 (not a FreeSurfer MGH file?)");
    bad = good;
    bad.type = 2;
    CHECK(error("type.mgh", bad.header() + voxels) ==
          (folder / "type.mgh").string() +
              ": type = 2: not supported (strata reads 0 uchar, 4 short, 3 float, and 1 int as "
              "float)");
    bad = good;
    bad.dims = {2, 0, 2, 1};
    CHECK(error("dims.mgh", bad.header() + voxels) ==
          (folder / "dims.mgh").string() +
              ": width, height, depth = 2x0x2: dimensions must be positive");
    bad = good;
    bad.dims[3] = 0;
    CHECK(error("frames.mgh", bad.header() + voxels) ==
          (folder / "frames.mgh").string() + ": nframes = 0: the frame count must be positive");
    bad = good;
    bad.size = {1, -1, 1};
    CHECK(error("size.mgh", bad.header() + voxels) ==
          (folder / "size.mgh").string() +
              ": xsize, ysize, zsize = 1 -1 1: spacing must be positive");
    bad = good;
    bad.mdc = {1, 0, 0, 0, 0, 0, 0, 0, 1};
    CHECK(error("mdc.mgh", bad.header() + voxels) ==
          (folder / "mdc.mgh").string() + ": Mdc: the direction of axis 1 (0 0 0) has no length");
    bad.mdc = {1, 0, 0, 1, 0, 0, 0, 0, 1};
    CHECK(error("plane.mgh", bad.header() + voxels).find("lie in one plane") != std::string::npos);
    CHECK(error("data.mgh", good.header() + "\x01\x02") ==
          (folder / "data.mgh").string() + ": voxel data has 2 bytes, the header needs 8");
    std::vector<std::string> warnings;
    const fs::path path = write_file(folder / "frame.mgh", good.header() + voxels);
    CHECK(error_of([&] { strata::load_volume(path, {.frame = 1}, warnings); }) ==
          path.string() + ": frame 1 is out of range: the image has one frame, 0");
  }
}
