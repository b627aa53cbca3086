#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "engine/core/error.h"
#include "engine/core/png.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/io/transfer_function_loader.h"
#include "engine/scene/io/volume_loader.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;

const fs::path voly_scenes = fs::path(STRATA_TEST_DATA) / "voly-labeller/scenes";

fs::path test_folder(const std::string& name) {
  return strata::test::fresh_folder("scene_loader_tests", name);
}

using strata::test::error_of;
using strata::test::write_file;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void check_vec(const glm::vec3& v, double x, double y, double z) {
  CHECK(v.x == float(x));
  CHECK(v.y == float(y));
  CHECK(v.z == float(z));
}

const char* const tetrahedron_obj =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

}  // namespace

TEST_SUITE("loaders") {
  TEST_CASE("dice_xml_import_gives_its_21_labels_as_in_the_file") {
    const strata::Scene scene = strata::load_scene(voly_scenes / "dice.xml");
    REQUIRE(scene.labels.size() == 21);
    std::vector<int> ids;
    for (const strata::Label& label : scene.labels) ids.push_back(label.id);
    CHECK(ids == std::vector<int>{1,  2,  4,  5,  6,  7,  8,  9,  10, 11, 12,
                                  13, 14, 15, 16, 17, 18, 19, 20, 21, 22});
    const strata::Label& first = scene.labels.front();
    CHECK(first.id == 1);
    CHECK(first.text == "N11");
    check_vec(first.anchor, 1.676204801e-02, 2.820012532e-02, -4.842323363e-01);
    CHECK(first.size == glm::vec2(128.0f, 32.0f));
    const strata::Label& third = scene.labels[2];
    CHECK(third.id == 4);
    CHECK(third.text == "N22");
    check_vec(third.anchor, -1.596263498e-01, -4.831686020e-01, -1.638088375e-01);
    const strata::Label& last = scene.labels.back();
    CHECK(last.id == 22);
    CHECK(last.text == "N66");
    check_vec(last.anchor, 1.868119091e-01, -1.664885879e-01, 5.020207167e-01);
    CHECK(last.size == glm::vec2(128.0f, 32.0f));
  }

  TEST_CASE("dice_xml_import_gives_its_camera_and_named_positions") {
    const strata::Scene scene = strata::load_scene(voly_scenes / "dice.xml");
    const strata::Camera& camera = scene.camera;
    // r{row}c{col} in the file is view[col][row].
    CHECK(camera.view[0][0] == float(-9.624520540e-01));
    CHECK(camera.view[2][0] == float(2.714517415e-01));   // r0c2
    CHECK(camera.view[0][1] == float(2.714416683e-01));   // r1c0
    CHECK(camera.view[3][2] == float(-1.681165457e+00));  // r2c3: the translation
    CHECK(camera.view[3][3] == 1.0f);
    // From the projection's r1c1 = 2.414213419, r2c2 = -1.513750076, r2c3 = -1.434267998.
    CHECK(camera.fov_y_degrees ==
          doctest::Approx(2.0 * std::atan(1.0 / 2.414213419) * 180.0 / std::numbers::pi));
    CHECK(camera.fov_y_degrees == doctest::Approx(45.0).epsilon(1e-6));
    CHECK(camera.near_plane == doctest::Approx(-1.434267998 / (-1.513750076 - 1.0)));
    // (widened: the dice seen from a corner, as the oblique views see them, reach further)
    CHECK(camera.far_plane > -1.434267998 / (-1.513750076 + 1.0));
    // Its own six, then the six anatomical and the eight oblique views every scene has.
    REQUIRE(scene.camera_positions.size() == 6 + 14);
    for (size_t i = 0; i < 6; ++i) CHECK(scene.camera_positions[i].name == "S" + std::to_string(i));
    CHECK(scene.camera_positions[6].name == "anterior");
    const glm::mat4& s5 = scene.camera_positions[5].view;
    CHECK(s5[0][0] == float(-9.615108371e-01));
    CHECK(s5[3][0] == float(1.172330454e-01));   // r0c3
    CHECK(s5[1][2] == float(-8.041925430e-01));  // r2c1
    CHECK(s5[3][2] == float(-3.315389752e-01));  // r2c3
  }

  TEST_CASE("dice_xml_import_warns_once_about_the_missing_volume_and_loads_the_rest") {
    const fs::path path = voly_scenes / "dice.xml";
    const strata::Scene scene = strata::load_scene(path);
    REQUIRE(scene.warnings.size() == 1);
    CHECK(scene.warnings[0] ==
          path.string() + ": volume 'assets/datasets/dice.mha' not found; skipped");
    CHECK(scene.volumes.empty());
    CHECK(scene.source == path);
    // Its transfer function is found in the sibling folder transferfunctions/.
    REQUIRE(scene.transfer_functions.size() == 1);
    CHECK(scene.transfer_functions[0].name == "dice4");
    CHECK(scene.transfer_functions[0].stops.size() == 6);
  }

  TEST_CASE("jet_engine_and_sponza_xml_import_with_their_meshes_missing") {
    struct Expected {
      const char* file;
      const char* mesh;
      size_t labels, positions;
      const char* first_text;
    };
    for (const Expected& e :
         {Expected{"jet-engine.xml", "assets/models/jet_engine1.dae", 10, 6 + 14, "Fan"},
          Expected{"sponza.xml", "assets/models/crytek-sponza/sponza.obj", 10, 5 + 14, nullptr}}) {
      CAPTURE(e.file);
      const fs::path path = voly_scenes / e.file;
      const strata::Scene scene = strata::load_scene(path);
      CHECK(scene.labels.size() == e.labels);
      CHECK(scene.camera_positions.size() == e.positions);
      CHECK(scene.meshes.empty());
      REQUIRE(scene.warnings.size() == 1);
      CHECK(scene.warnings[0] == path.string() + ": mesh '" + e.mesh + "' not found; skipped");
      if (e.first_text) CHECK(scene.labels[0].text == e.first_text);
    }
  }

  TEST_CASE("xml_import_loads_referenced_meshes_found_beside_the_scene") {
    const fs::path folder = test_folder("xml_mesh");
    write_file(folder / "models/tetrahedron.obj", tetrahedron_obj);
    // jet-engine.xml with its mesh replaced by one in a folder beside the scene's folder.
    std::string text = read_text(voly_scenes / "jet-engine.xml");
    const std::string reference = "assets/models/jet_engine1.dae";
    text.replace(text.find(reference), reference.size(), "assets/models/tetrahedron.obj");
    const fs::path path = write_file(folder / "scenes/jet.xml", text);
    const strata::Scene scene = strata::load_scene(path);
    CHECK(scene.warnings.empty());
    REQUIRE(scene.meshes.size() == 1);
    CHECK(scene.meshes[0].triangle_count() == 4);
    CHECK(scene.meshes[0].transform[0][0] == float(9.999998845e-03));
    CHECK(scene.meshes[0].transform[3][2] == 1.0f);  // r2c3
  }

  TEST_CASE("xml_import_loads_a_volume_found_beside_the_scene_with_its_transfer_function") {
    const fs::path folder = test_folder("xml_volume");
    strata::Volume dice;
    dice.dims = {4, 3, 2};
    dice.voxels.assign(24, std::byte{7});
    dice.voxels[5] = std::byte{9};
    dice.value_range = {7.0f, 9.0f};
    fs::create_directories(folder / "datasets");
    strata::write_metaimage(folder / "datasets/dice.mha", dice);
    fs::create_directories(folder / "transferfunctions");
    fs::copy_file(fs::path(STRATA_TEST_DATA) / "voly-labeller/transferfunctions/dice4.gra",
                  folder / "transferfunctions/dice4.gra");
    const fs::path path =
        write_file(folder / "scenes/dice.xml", read_text(voly_scenes / "dice.xml"));
    const strata::Scene scene = strata::load_scene(path);
    CHECK(scene.warnings.empty());
    REQUIRE(scene.volumes.size() == 1);
    const strata::Volume& volume = scene.volumes[0];
    CHECK(volume.name == "dice");
    CHECK(volume.dims == glm::uvec3(4, 3, 2));
    for (int axis = 0; axis < 3; ++axis) CHECK(volume.transform[axis][axis] == 18.0f);
    CHECK(volume.transform[3][3] == 1.0f);  // overallTransformation: 18 times the identity
    REQUIRE(volume.transfer_function == 0);
    CHECK(scene.transfer_functions[0].source == folder / "transferfunctions/dice4.gra");
    CHECK(scene.labels.size() == 21);
  }

  TEST_CASE("malformed_and_truncated_xml_give_one_error_with_pugixml_reason_and_place") {
    const fs::path folder = test_folder("bad_xml");
    const fs::path malformed =
        write_file(folder / "malformed.xml",
                   "<boost_serialization>\n<data><item></data>\n</boost_serialization>\n");
    CHECK(error_of([&] { strata::load_scene(malformed); }) ==
          malformed.string() +
              ": XML error at line 2, column 15 (offset 36): Start-end tags mismatch");

    const std::string dice = read_text(voly_scenes / "dice.xml");
    const fs::path truncated =
        write_file(folder / "truncated.xml", dice.substr(0, dice.size() / 2));
    const std::string message = error_of([&] { strata::load_scene(truncated); });
    CHECK(message.rfind(truncated.string() + ": XML error at line ", 0) == 0);

    const fs::path other = write_file(folder / "other.xml", "<svg/>");
    CHECK(error_of([&] { strata::load_scene(other); }) ==
          other.string() + ": not a voly-labeller scene (no <boost_serialization><data>)");

    std::string bad_number = dice;
    bad_number.replace(bad_number.find("1.676204801e-02"), 15, "one");
    const fs::path number = write_file(folder / "number.xml", bad_number);
    CHECK(error_of([&] { strata::load_scene(number); }) ==
          number.string() +
              ": item[2] (LabelNode).label.label.anchorPosition.x: expected a number, got 'one'");

    std::string no_class = dice;
    const std::string first_label = "class_id=\"7\" class_name=\"LabelNode\"";
    no_class.replace(no_class.find(first_label), first_label.size(), "class_id_reference=\"7\"");
    const fs::path reference = write_file(folder / "reference.xml", no_class);
    CHECK(error_of([&] { strata::load_scene(reference); }) ==
          reference.string() + ": item[2]: class_id_reference '7' names no class seen before");

    const fs::path missing = folder / "missing.xml";
    CHECK(error_of([&] { strata::load_scene(missing); }) == missing.string() + ": no such file");
  }

  TEST_CASE("json_scene_resolves_paths_against_its_folder") {
    const fs::path folder = test_folder("json_meshes");
    write_file(folder / "models/tetrahedron.obj", tetrahedron_obj);
    const fs::path path = write_file(folder / "scenes/scene.json", R"({
      "strata_scene": 1,
      "meshes": [{"file": "../models/tetrahedron.obj", "color": [1, 0, 0, 0.5],
                  "transform": [1, 0, 0, 5,  0, 1, 0, 6,  0, 0, 1, 7,  0, 0, 0, 1]}],
      "labels": [{"id": 7, "text": "Tip", "anchor": [0, 0, 1], "size": [64, 16]},
                 {"id": 8, "text": "Base", "anchor": [0.25, 0.25, 0], "priority": 2.5}],
      "camera": {"fov_y": 30, "near": 0.5, "far": 50, "eye": [0, 0, 10], "target": [0, 0, 0],
                 "positions": [{"name": "side", "eye": [10, 0, 0], "target": [0, 0, 0], "up": [0, 0, 1]},
                               {"name": "moved", "view": [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, -3,  0, 0, 0, 1]}]},
      "settings": {"layers": 3, "weights": {"label_shadow": 2, "previous_position": 0.5}}
    })");
    const strata::Scene scene = strata::load_scene(path);
    CHECK(scene.warnings.empty());
    REQUIRE(scene.meshes.size() == 1);
    CHECK(scene.meshes[0].triangle_count() == 4);
    CHECK(scene.meshes[0].color == glm::vec4(1.0f, 0.0f, 0.0f, 0.5f));
    CHECK(scene.meshes[0].transform[3] == glm::vec4(5.0f, 6.0f, 7.0f, 1.0f));  // row-major in JSON
    REQUIRE(scene.labels.size() == 2);
    CHECK(scene.labels[0].id == 7);
    CHECK(scene.labels[0].text == "Tip");
    CHECK(scene.labels[0].size == glm::vec2(64.0f, 16.0f));
    CHECK(scene.labels[1].size == glm::vec2(0.0f));  // from the text
    CHECK(scene.labels[0].priority == 0.0f);
    CHECK(scene.labels[1].priority == 2.5f);
    CHECK(scene.camera.fov_y_degrees == 30.0f);
    CHECK(scene.camera.near_plane == 0.5f);
    CHECK(scene.camera.far_plane == 50.0f);
    CHECK(scene.camera.view[3] == glm::vec4(0.0f, 0.0f, -10.0f, 1.0f));
    REQUIRE(scene.camera_positions.size() == 2 + 14);  // (and the fourteen standard views)
    CHECK(scene.camera_positions[0].name == "side");
    const glm::vec4 side_eye = glm::inverse(scene.camera_positions[0].view)[3];
    CHECK(side_eye.x == doctest::Approx(10.0));
    CHECK(scene.camera_positions[1].view[3][2] == -3.0f);
    CHECK(scene.settings.layer_count == 3);
    CHECK(scene.settings.weights.label_shadow == 2.0f);
    CHECK(scene.settings.weights.previous_position == 0.5f);
    CHECK(scene.settings.weights.anchor_constraint == 1e6f);  // the default stays
  }

  TEST_CASE("json_scene_volume_loads_with_its_transfer_function") {
    const fs::path folder = test_folder("json_volume");
    const fs::path volume = fs::path(STRATA_DATA_CACHE) / "mricron/ch2.nii.gz";
    REQUIRE_MESSAGE(fs::exists(volume), "scripts/fetch-data.sh fills assets/cache");
    strata::TransferFunction tf;
    tf.name = "head tf";
    tf.stops = {{0.0f, glm::vec4(0.0f)}, {1.0f, glm::vec4(1.0f)}};
    fs::create_directories(folder / "scenes/tf");
    strata::write_transfer_function_json(folder / "scenes/tf/head.json", tf);
    const std::string relative = fs::relative(volume, folder / "scenes").generic_string();
    const fs::path path = write_file(folder / "scenes/head.json",
                                     R"({"strata_scene": 1,
      "volumes": [{"name": "head", "file": ")" +
                                         relative + R"(", "transfer_function": "tf/head.json",
                   "transform": [2, 0, 0, 0,  0, 2, 0, 0,  0, 0, 2, 0,  0, 0, 0, 1]},
                  {"file": ")" + volume.string() +
                                         R"(", "transfer_function": "tf/../tf/head.json"}]})");
    const strata::Scene scene = strata::load_scene(path);
    REQUIRE(scene.volumes.size() == 2);
    const strata::Volume& head = scene.volumes[0];
    CHECK(head.name == "head");
    CHECK(head.dims == glm::uvec3(181, 217, 181));
    CHECK(head.transform[0][0] == 2.0f);
    CHECK(scene.volumes[1].name == "ch2");  // the file name before its first dot
    // Both name one file: it is loaded once.
    REQUIRE(scene.transfer_functions.size() == 1);
    CHECK(head.transfer_function == 0);
    CHECK(scene.volumes[1].transfer_function == 0);
    CHECK(scene.transfer_functions[0].name == "head tf");
    CHECK(scene.transfer_functions[0].stops.size() == 2);
  }

  TEST_CASE("json_scene_atlas_entry_makes_labels_masks_and_surfaces") {
    const fs::path folder = test_folder("json_atlas");
    const std::string cache = fs::path(STRATA_DATA_CACHE).generic_string();
    const std::string atlas = R"({"strata_scene": 1, "atlas": [{"labels": ")" + cache +
                              R"(/mricron/aal.nii.gz", "names": ")" + cache +
                              R"(/mricron/aal.nii.txt", )";
    const strata::Scene chosen = strata::load_scene(write_file(folder / "chosen.json", atlas + R"(
       "regions": ["Precentral_R", "Precentral_L"], "make": ["labels", "masks", "surfaces"],
       "surface_color": [0, 1, 0, 0.25]}]})"));
    REQUIRE(chosen.labels.size() == 2);
    CHECK(chosen.labels[0].text == "Precentral R");  // the order asked for
    CHECK(chosen.labels[1].text == "Precentral L");
    REQUIRE(chosen.volumes.size() == 2);
    CHECK(chosen.volumes[0].name == "Precentral_R");
    REQUIRE(chosen.volumes[0].transfer_function >= 0);
    // Clear below the boundary between outside (0) and inside (1), the surface colour above it.
    const strata::TransferFunction& mask_tf =
        chosen.transfer_functions[size_t(chosen.volumes[0].transfer_function)];
    CHECK(mask_tf.sample(0.3f).a == 0.0f);
    CHECK(mask_tf.sample(1.0f) == chosen.meshes[1].color);
    REQUIRE(chosen.meshes.size() == 2);
    CHECK(chosen.meshes[1].name == "Precentral_L");
    CHECK(chosen.meshes[1].color == glm::vec4(0.0f, 1.0f, 0.0f, 0.25f));
    CHECK(chosen.meshes[1].triangle_count() > 100);

    const strata::Scene first = strata::load_scene(
        write_file(folder / "first.json", atlas + R"("regions": "all", "limit": 3}]})"));
    REQUIRE(first.labels.size() == 3);  // the names file's order
    CHECK(first.labels[0].text == "Precentral L");
    CHECK(first.labels[1].text == "Precentral R");
    CHECK(first.labels[2].text == "Frontal Sup L");
    CHECK(first.volumes.empty());
    CHECK(first.meshes.empty());

    const fs::path unknown = write_file(folder / "unknown.json",
                                        atlas + R"("regions": ["Precentral_L", "Precentral"]}]})");
    CHECK(error_of([&] { strata::load_scene(unknown); }) ==
          unknown.string() + ": atlas[0].regions[1]: no region 'Precentral' in " + cache +
              "/mricron/aal.nii.txt");
  }

  TEST_CASE("json_scene_errors_name_the_file_field_and_reason") {
    const fs::path folder = test_folder("bad_json");
    const std::string prefix = (folder / "s.json").string() + ": ";
    const auto load = [&](const std::string& text) {
      const fs::path path = write_file(folder / "s.json", text);
      return error_of([&] { strata::load_scene(path); });
    };
    CHECK(load("{\n  \"strata_scene\": 1,\n  \"labels\": [\n}") ==
          prefix +
              "parse error at line 4, column 1: syntax error while parsing value - unexpected '}'; "
              "expected '[', '{', or a literal");
    CHECK(load(R"({"strata_scene": 2})") ==
          prefix + "strata_scene: version 2 is not supported (this strata reads version 1)");
    CHECK(load(R"({"volumes": []})") == prefix + "not a strata scene (no \"strata_scene\": 1)");
    CHECK(load(R"({"strata_scene": 1, "lables": []})") ==
          prefix +
              "unknown key 'lables' (expected strata_scene, volumes, meshes, atlas, "
              "segmentations, labels, camera, settings)");
    CHECK(load(R"({"strata_scene": 1, "volumes": [{"file": "x.nii", "trasform": []}]})") ==
          prefix +
              "volumes[0]: unknown key 'trasform' (expected name, file, frame, series, "
              "transfer_function, preset, window, crop, clip, transform)");
    CHECK(
        load(
            R"({"strata_scene": 1, "volumes": [{"file": "x.nii", "crop": [0, 0, 5, 1, 1, 4]}]})") ==
        prefix +
            "volumes[0].crop: expected [x0, y0, z0, x1, y1, z1] with x0 < x1, y0 < y1, z0 < z1");
    CHECK(load(R"({"strata_scene": 1, "volumes": [{"file": "x.nii",
            "clip": [{"point": [0, 0, 0], "normal": [0, 0, 0]}]}]})") ==
          prefix + "volumes[0].clip[0].normal: expected a non-zero normal");
    CHECK(load(R"({"strata_scene": 1, "volumes": [{"file": "x.nii", "transform": [1, 2, 3]}]})") ==
          prefix + "volumes[0].transform: expected 16 numbers");
    CHECK(load(R"({"strata_scene": 1, "volumes": [{"file": 3}]})") ==
          prefix + "volumes[0].file: expected a string");
    CHECK(load(R"({"strata_scene": 1, "volumes": [{"file": "x.nii",
                   "transfer_function": {"stops": [{"position": 0, "color": [1, 1]}]}}]})") ==
          prefix +
              "volumes[0].transfer_function.stops[0].color: expected 4 numbers [r, g, b, a] in "
              "[0, 1]");
    CHECK(load(R"({"strata_scene": 1, "meshes": [{"file": "missing.obj"}]})") ==
          prefix + "meshes[0].file: " + (folder / "missing.obj").string() + ": no such file");
    CHECK(load(R"({"strata_scene": 1, "labels": {}})") == prefix + "labels: expected an array");
    CHECK(load(R"({"strata_scene": 1, "labels": [{"id": 1, "text": "a", "anchor": [0, 0]}]})") ==
          prefix + "labels[0].anchor: expected 3 numbers");
    CHECK(load(R"({"strata_scene": 1, "labels": [{"id": 1, "text": "a", "anchor": [0, 0, 0]},
                                                 {"id": 1, "text": "b", "anchor": [0, 0, 0]}]})") ==
          prefix + "labels: id 1 is used by two labels");
    CHECK(load(R"({"strata_scene": 1, "camera": {"near": 10, "far": 1}})") ==
          prefix + "camera.far: expected a number > near");
    CHECK(load(R"({"strata_scene": 1, "camera": {"positions": [{"name": "a"}]}})") ==
          prefix + "camera.positions[0]: missing 'view' or 'eye'/'target'");
    CHECK(load(R"({"strata_scene": 1, "camera": {"eye": [0, 0, 1], "view": []}})") ==
          prefix + "camera: give either 'view' or 'eye'/'target'/'up', not both");
    CHECK(load(R"({"strata_scene": 1, "settings": {"weights": {"label_shadw": 1}}})") ==
          prefix +
              "settings.weights: unknown key 'label_shadw' (expected label_shadow, "
              "anchor_constraint, connector_shadow, integral_costs, distance_to_anchor, "
              "connector_direction, previous_position, leader_crossing, illegible)");
    CHECK(load(R"({"strata_scene": 1, "settings": {"layers": 0}})") ==
          prefix + "settings.layers: expected an integer from 1 to 8");
    CHECK(load(R"({"strata_scene": 1, "settings": {"layers": 9}})") ==
          prefix + "settings.layers: expected an integer from 1 to 8");
    CHECK(load(R"({"strata_scene": 1, "settings": {"ghost": 1.5}})") ==
          prefix + "settings.ghost: expected a number from 0 (off) to 1, got 1.5");
    CHECK(load(R"({"strata_scene": 1, "settings": {"ghost_radius": 0}})") ==
          prefix +
              "settings.ghost_radius: expected a share of the picture's shorter side from 0.005 "
              "to 0.5, got 0");
    // Numbers that would wrap or turn infinite, and matrices that flatten the scene.
    CHECK(load(R"({"strata_scene": 1, "labels": [{"id": 2147483648, "text": "a",
                   "anchor": [0, 0, 0]}]})") ==
          prefix +
              "labels[0].id: expected an integer from -2147483648 to 2147483647, got "
              "2147483648");
    CHECK(load(R"({"strata_scene": 1, "labels": [{"id": -1099511627776, "text": "a",
                   "anchor": [0, 0, 0]}]})")
              .find("labels[0].id: expected an integer from") != std::string::npos);
    CHECK(load(R"({"strata_scene": 1, "camera": {"far": 1e39}})") ==
          prefix + "camera.far: expected a number of at most 3.4e38");
    CHECK(load(R"({"strata_scene": 1, "labels": [{"id": 1, "text": "a",
                   "anchor": [1e39, 0, 0]}]})") ==
          prefix + "labels[0].anchor: expected numbers of at most 3.4e38");
    CHECK(load(R"({"strata_scene": 1, "camera": {"view": [0, 0, 0, 0, 0, 0, 0, 0,
                   0, 0, 0, 0, 0, 0, 0, 0]}})") ==
          prefix + "camera.view: the matrix is singular (determinant 0.0)");
    CHECK(load(R"({"strata_scene": 1, "atlas": [{"make": ["meshes"]}]})") ==
          prefix + "atlas[0].make[0]: 'meshes' is not one of labels, masks, surfaces");
    const fs::path missing = folder / "missing.json";
    CHECK(error_of([&] { strata::load_scene(missing); }) == missing.string() + ": no such file");
    const fs::path unknown = write_file(folder / "scene.yaml", "");
    CHECK(error_of([&] { strata::load_scene(unknown); }) ==
          unknown.string() +
              ": unknown scene format '.yaml' (expected a scene: .json, or .xml from the "
              "thesis program; or a volume: .nii, .nii.gz, .mhd, .mha, .nrrd, "
              ".nhdr, .mgz, .mgh, .dcm and DICOM folders)");
  }

  TEST_CASE("json_scene_label_image_is_read_with_its_height_and_side") {
    const fs::path folder = test_folder("label_image");
    const std::vector<uint8_t> pixels = {255, 0, 0,   255, 0, 255, 0, 128,  //
                                         0,   0, 255, 255, 9, 9,   9, 0,    //
                                         1,   2, 3,   4,   5, 6,   7, 8};
    fs::create_directories(folder / "pictures");
    strata::write_png((folder / "pictures/p.png").string(), 2, 3, pixels);
    const fs::path path = write_file(folder / "scenes/scene.json", R"({"strata_scene": 1,
      "labels": [{"id": 1, "text": "Photo", "anchor": [0, 0, 0], "image": "../pictures/p.png"},
                 {"id": 2, "text": "Side", "anchor": [0, 0, 0], "image": "../pictures/p.png",
                  "image_height": 40, "image_side": "left"},
                 {"id": 3, "text": "None", "anchor": [0, 0, 0]}]})");
    const strata::Scene scene = strata::load_scene(path);
    REQUIRE(scene.labels.size() == 3);
    REQUIRE(scene.labels[0].image);
    const strata::LabelImage& above = *scene.labels[0].image;
    CHECK(above.file == (folder / "pictures/p.png").lexically_normal());
    CHECK(above.pixels.width == 2);
    CHECK(above.pixels.height == 3);
    CHECK(above.pixels.pixels == pixels);  // straight alpha, as in the file
    CHECK(above.height == 64.0f);
    CHECK(above.side == strata::LabelImage::Side::above);
    REQUIRE(scene.labels[1].image);
    CHECK(scene.labels[1].image->height == 40.0f);
    CHECK(scene.labels[1].image->side == strata::LabelImage::Side::left);
    CHECK_FALSE(scene.labels[2].image);

    // Written and read back: the picture's path relative to the new file, height and side kept.
    const fs::path saved = folder / "out/saved.json";
    fs::create_directories(saved.parent_path());
    strata::save_scene_json(saved, scene);
    CHECK(read_text(saved).find("\"image\": \"../pictures/p.png\"") != std::string::npos);
    const strata::Scene back = strata::load_scene(saved);
    REQUIRE(back.labels[1].image);
    CHECK(back.labels[1].image->pixels.pixels == pixels);
    CHECK(back.labels[1].image->height == 40.0f);
    CHECK(back.labels[1].image->side == strata::LabelImage::Side::left);
    CHECK_FALSE(back.labels[2].image);
  }

  TEST_CASE("json_scene_label_image_errors_name_the_label_field") {
    const fs::path folder = test_folder("bad_label_image");
    write_file(folder / "notes.png", "not a picture");
    const std::string prefix = (folder / "s.json").string() + ": labels[0].";
    const auto load = [&](const std::string& image_fields) {
      const fs::path path = write_file(folder / "s.json",
                                       R"({"strata_scene": 1, "labels": [{"id": 1, "text": "a",
                                           "anchor": [0, 0, 0], )" +
                                           image_fields + "}]}");
      return error_of([&] { strata::load_scene(path); });
    };
    CHECK(load(R"("image": "missing.png")") ==
          prefix + "image: " + (folder / "missing.png").string() + ": no such file");
    CHECK(load(R"("image": "notes.png")") ==
          prefix + "image: " + (folder / "notes.png").string() + ": not a PNG or JPEG file");
    CHECK(load(R"("image": 5)") == prefix + "image: expected a string");
    CHECK(load(R"("image": "missing.png", "image_height": 0)") ==
          prefix + "image_height: expected pixels from 1 to 1024");
    CHECK(load(R"("image": "missing.png", "image_side": "below")") ==
          prefix + "image_side: 'below' is not one of above, left");
    CHECK(load(R"("image_side": "left")") ==
          (folder / "s.json").string() +
              ": labels[0]: 'image_height' and 'image_side' need an 'image'");
  }

  TEST_CASE("saved_json_scene_reads_back_the_imported_thesis_scene") {
    const fs::path folder = test_folder("save");
    write_file(folder / "models/tetrahedron.obj", tetrahedron_obj);
    strata::Scene scene = strata::load_scene(voly_scenes / "dice.xml");
    scene.meshes = strata::load_scene(write_file(folder / "meshes.json", R"({"strata_scene": 1,
      "meshes": [{"file": "models/tetrahedron.obj", "color": [0, 0, 1, 1],
                  "transform": [1, 0, 0, 2,  0, 1, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1]}]})"))
                       .meshes;
    scene.settings.weights.integral_costs = 3.5f;
    scene.settings.ghost = 0.75f;
    scene.settings.ghost_radius = 0.2f;
    const fs::path path = folder / "out/dice.json";
    fs::create_directories(path.parent_path());
    strata::save_scene_json(path, scene);
    CHECK(read_text(path).find("\"file\": \"../models/tetrahedron.obj\"") != std::string::npos);
    const strata::Scene back = strata::load_scene(path);
    REQUIRE(back.labels.size() == scene.labels.size());
    for (size_t i = 0; i < back.labels.size(); ++i) {
      CHECK(back.labels[i].id == scene.labels[i].id);
      CHECK(back.labels[i].text == scene.labels[i].text);
      CHECK(back.labels[i].anchor == scene.labels[i].anchor);
      CHECK(back.labels[i].size == scene.labels[i].size);
    }
    CHECK(back.settings.ghost == 0.75f);
    CHECK(back.settings.ghost_radius == 0.2f);
    CHECK(back.camera.view == scene.camera.view);
    CHECK(back.camera.fov_y_degrees == scene.camera.fov_y_degrees);
    CHECK(back.camera.near_plane == scene.camera.near_plane);
    // (the mesh added widens it for the oblique views that see it)
    CHECK(back.camera.far_plane >= scene.camera.far_plane);
    REQUIRE(back.camera_positions.size() == 6 + 14);
    CHECK(back.camera_positions[5].name == "S5");
    CHECK(back.camera_positions[5].view == scene.camera_positions[5].view);
    REQUIRE(back.meshes.size() == 1);
    CHECK(back.meshes[0].color == glm::vec4(0.0f, 0.0f, 1.0f, 1.0f));
    CHECK(back.meshes[0].transform == scene.meshes[0].transform);
    CHECK(back.settings.weights.integral_costs == 3.5f);
  }

  TEST_CASE("scenes_with_more_labels_than_placement_holds_are_refused_when_they_load") {
    const fs::path folder = test_folder("label_limit");
    std::string labels, csv = "label,l,p,s\n";
    for (int i = 0; i < 4097; ++i) {
      labels += std::string(i ? "," : "") + "{\"id\": " + std::to_string(i) +
                ", \"text\": \"L\", \"anchor\": [0, 0, 0]}";
      csv += "L," + std::to_string(i) + ",0,0\n";
    }
    const fs::path scene =
        write_file(folder / "many.json", "{\"strata_scene\": 1, \"labels\": [" + labels + "]}");
    CHECK(strata::test::error_of([&] { strata::load_scene(scene); }) ==
          scene.string() + ": 4097 labels; strata places at most 4096 in a scene");
    // The same through a label file added on the command line.
    const fs::path one = write_file(folder / "one.json", "{\"strata_scene\": 1}");
    const fs::path file = write_file(folder / "many.csv", csv);
    CHECK(strata::test::error_of([&] {
            strata::load_scene(one, {.labels = file});
          }).find("4097 labels; strata places at most 4096") != std::string::npos);
  }

  // Found beside the fuzz targets (their inputs, at most 64 KiB, nest too shallowly): the version's
  // error message dumped the value, and nlohmann's dump() recurses once per level of nesting.
  TEST_CASE("json_scene_with_a_deeply_nested_version_is_an_error_not_a_stack_overflow") {
    const fs::path folder = test_folder("deep_version");
    const size_t depth = 1'000'000;
    const fs::path path =
        write_file(folder / "s.json", R"({"strata_scene": )" + std::string(depth, '[') +
                                          std::string(depth, ']') + "}");
    CHECK(error_of([&] { strata::load_scene(path); }) ==
          path.string() +
              ": strata_scene: version [...] is not supported (this strata reads "
              "version 1)");
  }

  // Found by fuzz_thesis_xml: a label id of 8.1e40 became inf as a float and its conversion to
  // int was undefined (UBSan); 3e9 fits a float but not an int.
  TEST_CASE("xml_import_refuses_numbers_beyond_float_and_ids_beyond_int") {
    const fs::path folder = test_folder("xml_numbers");
    const std::string dice = read_text(voly_scenes / "dice.xml");
    const auto load = [&](const std::string& from, const std::string& to) {
      std::string text = dice;
      const size_t at = text.find(from);
      REQUIRE(at != std::string::npos);
      text.replace(at, from.size(), to);
      const fs::path path = write_file(folder / "dice.xml", text);
      return error_of([&] { strata::load_scene(path); });
    };
    CHECK(load("<label.id>8</label.id>", "<label.id>81e39</label.id>")
              .ends_with("label.id: expected a number, got '81e39'"));
    CHECK(load("<label.id>8</label.id>", "<label.id>3e9</label.id>")
              .ends_with("label.id: expected an integer from -2147483648 to 2147483647"));
    CHECK(load("<label.id>8</label.id>", "<label.id>-2147483648</label.id>") == "(no error)");
    CHECK(load("<r0c0>-9.624520540e-01</r0c0>", "<r0c0>1e300</r0c0>")
              .ends_with("r0c0: expected a number, got '1e300'"));
  }
}
