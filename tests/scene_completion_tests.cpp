// What a scene gets that its file does not give: the fitted camera and anatomical views, and
// transfer-function presets; and volumes and label files opened as scenes.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <tuple>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/scene/fitted_camera.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/scene_bounds.h"
#include "engine/scene/transfer_function_presets.h"
#include "test_files.h"

namespace fs = std::filesystem;
using strata::test::error_of;
using strata::test::write_file;

namespace {

const fs::path cache = STRATA_DATA_CACHE;

fs::path output_folder(const std::string& name) {
  return strata::test::fresh_folder("scene_completion_tests", name);
}

const strata::CameraPose* position(const strata::Scene& scene, const std::string& name) {
  for (const strata::CameraPose& p : scene.camera_positions) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

// A small int16 volume of Hounsfield-like values: air around a block of soft tissue.
strata::Volume ct_block() {
  strata::Volume v;
  v.name = "block";
  v.type = strata::VoxelType::int16;
  v.dims = {8, 8, 8};
  v.spacing = {2.0f, 2.0f, 2.0f};
  std::vector<int16_t> values(v.voxel_count(), -1000);
  for (uint32_t k = 2; k < 6; ++k)
    for (uint32_t j = 2; j < 6; ++j)
      for (uint32_t i = 2; i < 6; ++i) values[(k * 8 + j) * 8 + i] = 40;
  values[0] = 1200;
  v.voxels.resize(values.size() * 2);
  std::memcpy(v.voxels.data(), values.data(), v.voxels.size());
  v.value_range = {-1000.0f, 1200.0f};
  return v;
}

}  // namespace

TEST_SUITE("loaders") {
  TEST_CASE("fitted_views_hold_the_content_and_look_from_the_patients_sides") {
    strata::Scene scene;
    scene.volumes.push_back(ct_block());
    scene.volumes[0].origin = {-100.0f, 20.0f, 5.0f};
    const strata::FittedCamera fitted = strata::fitted_camera(scene);
    REQUIRE(fitted.positions.size() == 14);
    const strata::Bounds bounds = strata::scene_bounds(scene);
    const glm::vec3 centre = bounds.centre();
    for (const strata::CameraPose& pose : fitted.positions) {
      INFO(pose.name);
      strata::Camera camera = fitted.camera;
      camera.view = pose.view;
      // Every corner of the box projects inside a square image, and not far inside (fitted).
      float widest = 0.0f;
      for (int c = 0; c < 8; ++c) {
        const glm::vec3 p((c & 1) ? bounds.hi.x : bounds.lo.x, (c & 2) ? bounds.hi.y : bounds.lo.y,
                          (c & 4) ? bounds.hi.z : bounds.lo.z);
        const strata::ProjectedPoint projected = strata::project(camera, p, {100, 100});
        CHECK(projected.visible);
        widest = std::max(widest, glm::length(projected.pixel - glm::vec2(50.0f)));
      }
      CHECK(widest > 40.0f);
      // The eye is on the named sides of the centre (LPS: anterior is -y, left +x, superior +z).
      const glm::vec3 eye = glm::normalize(camera.eye() - centre);
      const auto view = strata::anatomical_view_named(pose.name);
      if (view) {
        CHECK(glm::dot(eye, glm::vec3(strata::side_of(*view).eye_direction)) > 0.999f);
        continue;
      }
      const auto named = [&](const char* word) {
        return pose.name.find(word) != std::string::npos;
      };
      CHECK((named("anterior") ? eye.y < -0.5f : eye.y > 0.5f));
      CHECK((named("left") ? eye.x > 0.5f : eye.x < -0.5f));
      CHECK((named("superior") ? eye.z > 0.4f : eye.z < -0.4f));
      CHECK(std::abs(eye.z) < 0.6f);  // 30 degrees up or down
    }
    CHECK(fitted.camera.view == fitted.positions[0].view);  // anterior first
    CHECK(fitted.positions[0].name == "anterior");

    // One axial slice is seen from above, not edge-on from the front.
    strata::Scene slice;
    slice.volumes.push_back(ct_block());
    slice.volumes[0].dims.z = 1;
    slice.volumes[0].voxels.resize(8 * 8 * 2);
    const strata::FittedCamera flat = strata::fitted_camera(slice);
    CHECK(flat.positions[4].name == "superior");
    CHECK(flat.camera.view == flat.positions[4].view);
  }

  // What a crop box and a clipping plane keep of a volume's box, and the views fitted to it: by
  // default without a camera, with fit on for a scene's own camera (turned no other way).
  TEST_CASE("views_are_fitted_to_what_the_cut_aways_keep") {
    strata::Scene scene;
    scene.volumes.push_back(ct_block());  // voxel centres 0..14 mm on each axis
    scene.volumes[0].cut =
        strata::crop_planes(glm::vec3(-5.0f, 2.0f, 4.0f), glm::vec3(7.0f, 30.0f, 9.0f));
    strata::Bounds kept = strata::kept_bounds(scene);
    CHECK(kept.lo == glm::vec3(0.0f, 2.0f, 4.0f));
    CHECK(kept.hi == glm::vec3(7.0f, 14.0f, 9.0f));
    // A plane x + y >= 14 cuts the corner (0, 2) off: x runs from 0 to 7 where y reaches 14.
    scene.volumes[0].cut.push_back(
        strata::clip_plane(glm::vec3(7.0f, 7.0f, 0.0f), glm::vec3(1, 1, 0)));
    kept = strata::kept_bounds(scene);
    CHECK(kept.lo.x == doctest::Approx(0.0f));
    CHECK(kept.lo.y == doctest::Approx(7.0f));
    CHECK(kept.hi.y == doctest::Approx(14.0f));

    strata::Scene bare = scene;
    strata::complete_scene(bare);
    const glm::vec3 centre = kept.centre();
    const glm::vec3 eye = bare.camera.eye();
    CHECK(eye.x == doctest::Approx(centre.x));  // from the front, at the kept part's centre
    CHECK(eye.z == doctest::Approx(centre.z));
    strata::Scene whole = scene;
    strata::complete_scene(whole, "", std::nullopt, false);
    CHECK(whole.camera.eye().x == doctest::Approx(7.0f));  // --no-fit: the whole box's centre

    strata::Scene own = scene;
    own.has_camera = true;
    own.camera.view = glm::lookAt(glm::vec3(7, -500, 7), glm::vec3(7, 7, 7), glm::vec3(0, 0, 1));
    own.camera_positions.push_back({"mine", own.camera.view});
    strata::Scene kept_own = own;
    strata::complete_scene(own);
    CHECK(own.camera.view == kept_own.camera.view);  // (fit is off for a scene's own camera)
    strata::complete_scene(kept_own, "", std::nullopt, true);
    CHECK(kept_own.camera.eye().x == doctest::Approx(centre.x));
    CHECK(kept_own.camera.eye().y > -500.0f);
    CHECK(glm::mat3(kept_own.camera.view) == glm::mat3(own.camera.view));
    CHECK(kept_own.camera_positions[0].view == kept_own.camera.view);
  }

  TEST_CASE("presets_follow_hounsfield_units_and_are_chosen_from_the_values") {
    const strata::Volume ct = ct_block();
    const strata::PresetChoice choice = strata::choose_transfer_function_preset(ct);
    CHECK(choice.name == "ct-skin");
    CHECK(choice.reason.find("Hounsfield") != std::string::npos);
    const strata::TransferFunction bone = strata::make_transfer_function_preset("ct-bone", ct);
    REQUIRE(bone.stops.size() >= 2);
    CHECK(bone.stops.front().position == 0.0f);
    CHECK(bone.stops.back().position == 1.0f);
    CHECK(std::is_sorted(bone.stops.begin(), bone.stops.end(),
                         [](const auto& a, const auto& b) { return a.position < b.position; }));
    const auto at_hu = [&](const strata::TransferFunction& tf, float hu) {
      return tf.sample((hu + 1000.0f) / 2200.0f);
    };
    CHECK(at_hu(bone, -1000.0f).a == 0.0f);  // air
    CHECK(at_hu(bone, 40.0f).a == 0.0f);     // soft tissue: not bone
    CHECK(at_hu(bone, 1000.0f).a > 0.3f);    // bone
    const strata::TransferFunction skin = strata::make_transfer_function_preset("ct-skin", ct);
    CHECK(at_hu(skin, -1000.0f).a == 0.0f);
    CHECK(at_hu(skin, -100.0f).a > 0.05f);

    strata::Volume mr = ct;
    mr.value_range = {0.0f, 255.0f};
    CHECK(strata::choose_transfer_function_preset(mr).name == "mr-head");
    CHECK(error_of([&] { strata::make_transfer_function_preset("bone", ct); }) ==
          "no transfer-function preset 'bone' (ct-skin, ct-soft-tissue, ct-bone, ct-lung, "
          "mr-head, mr-brain)");
  }

  // A preset for the other modality maps the values to nothing (or everything): it warns.
  TEST_CASE("a_preset_for_the_other_modality_warns") {
    strata::Volume mr = ct_block();
    mr.value_range = {0.0f, 255.0f};
    for (const auto& [volume, preset_name, warns] :
         {std::tuple{ct_block(), "ct-bone", false}, std::tuple{ct_block(), "mr-head", true},
          std::tuple{mr, "ct-bone", true}, std::tuple{mr, "mr-brain", false}}) {
      const std::string preset = preset_name;  // (a lambda cannot capture a structured binding)
      CAPTURE(preset);
      strata::Scene scene;
      scene.volumes.push_back(volume);
      strata::complete_scene(scene, preset);
      REQUIRE(scene.transfer_functions.size() == 1);
      CHECK(scene.transfer_functions[0].name == preset);
      const bool warned =
          std::any_of(scene.warnings.begin(), scene.warnings.end(), [&](const std::string& w) {
            return w.find(std::string("preset ") + preset + " is for") != std::string::npos;
          });
      CHECK(warned == warns);
    }
  }

  // A volume's "preset" is that preset made for its values, as --preset makes it; the scene
  // writer writes a preset or a window back by name and values, and a function of no file in the
  // volume's values, never 0..1 of one scan's range.
  TEST_CASE("a_volume_preset_key_applies_the_preset_and_is_written_back") {
    const fs::path folder = output_folder("preset_key");
    const std::string ct5n = (cache / "dicom/CT5N").string();
    const auto scene_with = [&](const std::string& name, const std::string& keys) {
      return write_file(folder / name, R"({"strata_scene": 1, "volumes": [{"file": ")" + ct5n +
                                           R"(", )" + keys + "}]}");
    };
    const strata::Scene keyed =
        strata::load_scene(scene_with("bone.json", R"("preset": "ct-bone")"));
    strata::SceneOpenOptions option;
    option.preset = "ct-bone";
    const strata::Scene given = strata::load_scene(ct5n, option);
    const strata::Volume& v = keyed.volumes[0];
    CHECK(v.preset == "ct-bone");
    CHECK(keyed.warnings.empty());
    const strata::TransferFunction& tf = keyed.transfer_functions[size_t(v.transfer_function)];
    const strata::TransferFunction& want =
        given.transfer_functions[size_t(given.volumes[0].transfer_function)];
    REQUIRE(tf.stops.size() == want.stops.size());
    for (size_t i = 0; i < tf.stops.size(); ++i) {
      CHECK(tf.stops[i].position == want.stops[i].position);
      CHECK(tf.stops[i].color == want.stops[i].color);
    }
    // The command line's --window wins over the file's preset.
    strata::SceneOpenOptions window;
    window.window = glm::vec2(900.0f, 1200.0f);
    const strata::Scene grey =
        strata::load_scene(scene_with("bone.json", R"("preset": "ct-bone")"), window);
    CHECK(grey.volumes[0].preset.empty());
    CHECK(grey.volumes[0].window == glm::vec2(900.0f, 1200.0f));

    const auto error = [&](const std::string& keys) {
      const fs::path path = scene_with("bad.json", keys);
      return error_of([&] { strata::load_scene(path); }).substr(path.string().size());
    };
    CHECK(error(R"("preset": "ct-bones")") ==
          ": volumes[0].preset: no preset 'ct-bones' (ct-skin, ct-soft-tissue, ct-bone, ct-lung, "
          "mr-head, mr-brain)");
    CHECK(error(R"("preset": 3)").starts_with(": volumes[0].preset: "));
    CHECK(error(R"("preset": "ct-bone", "window": [40, 400])") ==
          ": volumes[0].window: give one of transfer_function, preset and window");
    CHECK(error(R"("preset": "ct-bone", "transfer_function": "x.json")") ==
          ": volumes[0].preset: give one of transfer_function, preset and window");

    // A volume opened directly and saved: its preset and window by name and values.
    const fs::path saved = folder / "saved.json";
    strata::save_scene_json(saved, given);
    CHECK(strata::test::read_file(saved).find(R"("preset": "ct-bone")") != std::string::npos);
    CHECK(strata::load_scene(saved).volumes[0].preset == "ct-bone");
    strata::save_scene_json(saved, strata::load_scene(ct5n, window));
    CHECK(strata::test::read_file(saved).find(R"("window": [)") != std::string::npos);
    CHECK(strata::load_scene(saved).volumes[0].window == glm::vec2(900.0f, 1200.0f));
    // A function of no file, edited (as the viewer does): written in HU.
    strata::Scene edited = strata::load_scene(ct5n);
    edited.volumes[0].preset.clear();
    edited.volumes[0].look_edited = true;
    strata::save_scene_json(saved, edited);
    const std::string text = strata::test::read_file(saved);
    CHECK(text.find(R"("units": "HU")") != std::string::npos);
    const strata::Scene back = strata::load_scene(saved);
    const strata::TransferFunction& a =
        edited.transfer_functions[size_t(edited.volumes[0].transfer_function)];
    const strata::TransferFunction& b =
        back.transfer_functions[size_t(back.volumes[0].transfer_function)];
    for (float t : {0.0f, 0.3f, 0.6f, 1.0f}) {
      const glm::vec4 d = a.sample(t) - b.sample(t);
      CHECK(glm::length(d) < 1e-4f);
    }
  }

  // A volume's window and a transfer function in HU are made 0..1 of its value range; HU on a
  // volume whose values are not Hounsfield units warns.
  TEST_CASE("windows_and_functions_in_the_volumes_values_map_to_its_range") {
    const fs::path folder = output_folder("values");
    const std::string ct5n = (cache / "dicom/CT5N").string();
    const strata::Scene windowed = strata::load_scene(write_file(
        folder / "w.json",
        R"({"strata_scene": 1, "volumes": [{"file": ")" + ct5n + R"(", "window": [-400, 800]}]})"));
    const strata::Volume& v = windowed.volumes[0];
    REQUIRE(v.value_range == glm::vec2(-888.0f, 85.0f));
    const strata::TransferFunction& tf = windowed.transfer_functions[size_t(v.transfer_function)];
    CHECK(tf.name == "window -400/800");
    CHECK(tf.units.empty());
    const auto at = [&](float value) { return tf.sample((value + 888.0f) / 973.0f); };
    CHECK(at(-800.0f) == glm::vec4(0.0f));
    CHECK(at(-400.0f).a == doctest::Approx(0.5f).epsilon(1e-4));
    CHECK(at(0.0f).a == doctest::Approx(0.5f + 400.0f / 800.0f).epsilon(1e-4));
    CHECK(error_of([&] {
            strata::load_scene(write_file(folder / "both.json",
                                          R"({"strata_scene": 1, "volumes": [{"file": ")" + ct5n +
                                              R"(", "window": [40, 80], "transfer_function": {
              "stops": [{"position": 0, "color": [1, 1, 1, 1]}]}}]})"));
          }).find("volumes[0].window: give one of transfer_function, preset and window") !=
          std::string::npos);

    strata::Scene mr;
    strata::Volume volume = ct_block();
    volume.value_range = {0.0f, 255.0f};
    mr.volumes.push_back(volume);
    strata::TransferFunction hu;
    hu.name = "bone";
    hu.units = "HU";
    hu.stops = {{300.0f, glm::vec4(0.0f)}, {1000.0f, glm::vec4(1.0f)}};
    mr.transfer_functions.push_back(hu);
    mr.volumes[0].transfer_function = 0;
    strata::complete_scene(mr);
    CHECK(mr.transfer_functions.size() == 2);
    CHECK(mr.volumes[0].transfer_function == 1);
    CHECK(std::any_of(mr.warnings.begin(), mr.warnings.end(), [](const std::string& w) {
      return w.find("transfer function bone is in Hounsfield units, but values 0 to 255") !=
             std::string::npos;
    }));
  }

  TEST_CASE("a_volume_opens_as_a_scene_with_a_preset_a_fitted_camera_and_named_views") {
    const fs::path ch2 = cache / "mricron/ch2.nii.gz";
    REQUIRE_MESSAGE(fs::exists(ch2), "run scripts/fetch-data.sh");
    const strata::Scene scene = strata::load_scene(ch2);
    REQUIRE(scene.volumes.size() == 1);
    CHECK(scene.volumes[0].name == "ch2");
    REQUIRE(scene.volumes[0].transfer_function == 0);
    CHECK(scene.transfer_functions[0].name == "mr-head");
    REQUIRE(scene.warnings.size() == 1);
    CHECK(scene.warnings[0] ==
          "volume 'ch2' has no transfer function; preset mr-head (values 0 to 254: not Hounsfield "
          "units, taken as MR; --preset NAME to choose)");
    CHECK_FALSE(scene.has_camera);
    for (const char* name : strata::kAnatomicalViewNames) CHECK(position(scene, name));
    // From the front: the eye in front of the face (LPS: anterior is -y).
    CHECK(scene.camera.eye().y < strata::scene_bounds(scene).lo.y);

    strata::SceneOpenOptions options;
    options.preset = "mr-brain";
    options.labels = STRATA_TEST_DATA "/labels/landmarks_ras.csv";
    const strata::Scene chosen = strata::load_scene(ch2, options);
    CHECK(chosen.warnings.empty());  // a preset given is no surprise
    CHECK(chosen.transfer_functions[0].name == "mr-brain");
    REQUIRE(chosen.labels.size() == 3);
    CHECK(chosen.labels[0].text == "Ventricule latéral");
  }

  // Every scene knows the six anatomical views, fitted to its content with its own lens, and
  // the camera's planes hold the content from each of them.
  TEST_CASE("every_demo_scene_has_the_six_anatomical_views_besides_its_own") {
    for (const std::string name : {"head", "head-100", "head-surfaces", "head-images"}) {
      CAPTURE(name);
      const strata::Scene scene =
          strata::load_scene(fs::path(STRATA_SOURCE_DIR "/assets/scenes") / (name + ".json"));
      CHECK(strata::camera_for(scene, "front").view != strata::camera_for(scene, "anterior").view);
      for (size_t v = 0; v < strata::kAnatomicalViewNames.size(); ++v) {
        const std::string view = strata::kAnatomicalViewNames[v];
        CAPTURE(view);
        const strata::Camera camera = strata::camera_for(scene, view);
        // (the scenes' own "left" wins)
        const bool fitted = camera.view == strata::fitted_view(scene, strata::AnatomicalView(v),
                                                               scene.camera.fov_y_degrees);
        CHECK(fitted == (view != "left"));
        // (the content's box between the planes)
        const strata::Bounds bounds = strata::scene_bounds(scene);
        for (int corner = 0; corner < 8; ++corner) {
          const glm::vec3 p((corner & 1) ? bounds.hi.x : bounds.lo.x,
                            (corner & 2) ? bounds.hi.y : bounds.lo.y,
                            (corner & 4) ? bounds.hi.z : bounds.lo.z);
          const float depth = -(camera.view * glm::vec4(p, 1.0f)).z;
          CHECK(depth > camera.near_plane);
          CHECK(depth < camera.far_plane);
        }
      }
      // Its own names come first, as in the file (the keys 1 to 9 follow them); saved, the
      // scene's file keeps its own positions only.
      CHECK(scene.camera_positions.front().name == "front");
      const fs::path saved = output_folder("anatomical") / (name + ".json");
      strata::save_scene_json(saved, scene);
      const strata::Scene back = strata::load_scene(saved);
      CHECK(back.camera_positions.size() == scene.camera_positions.size());
      CHECK(strata::test::read_file(saved).find("\"anterior\"") == std::string::npos);
    }
  }

  TEST_CASE("a_scene_with_a_camera_keeps_it_and_its_labels_may_come_from_a_label_file") {
    const fs::path folder = output_folder("label_file");
    const fs::path scene_path =
        write_file(folder / "s.json", R"({"strata_scene": 1, "labels": ")" STRATA_TEST_DATA
                                      R"(/labels/landmarks_lps.fcsv",
          "camera": {"eye": [0, -500, 0], "target": [0, 0, 0], "up": [0, 0, 1],
                     "positions": [{"name": "left", "eye": [9, 0, 0], "target": [0, 0, 0],
                                    "up": [0, 0, 1]}]}})");
    const strata::Scene scene = strata::load_scene(scene_path);
    CHECK(scene.has_camera);
    CHECK(scene.camera.view ==
          glm::lookAt(glm::vec3(0, -500, 0), glm::vec3(0), glm::vec3(0, 0, 1)));
    // The standard views besides its own positions; its own "left" wins.
    REQUIRE(scene.camera_positions.size() == 14);
    CHECK(scene.camera_positions[0].name == "left");
    CHECK(scene.camera_positions[0].view ==
          glm::lookAt(glm::vec3(9, 0, 0), glm::vec3(0), glm::vec3(0, 0, 1)));
    for (const char* name : {"anterior", "posterior", "right", "superior", "inferior"}) {
      CAPTURE(name);
      CHECK(std::count_if(scene.camera_positions.begin(), scene.camera_positions.end(),
                          [&](const strata::CameraPose& p) { return p.name == name; }) == 1);
    }
    REQUIRE(scene.labels.size() == 3);
    CHECK(scene.labels[0].id == 0);
    CHECK(scene.labels[2].id == 2);

    const fs::path bad =
        write_file(folder / "bad.json", R"({"strata_scene": 1, "labels": "missing.mrk.json"})");
    CHECK(error_of([&] { strata::load_scene(bad); }).starts_with(bad.string() + ": labels: "));
  }
}
