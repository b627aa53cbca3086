// Values a float holds but a picture cannot use (value_limits.h): each is refused with the file
// and the field, and values just inside the limits still load. Also label ids past int's range and
// 2-D NRRD images in a 2-D space.
#include <doctest/doctest.h>

#include <climits>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "engine/core/error.h"
#include "engine/scene/camera.h"
#include "engine/scene/fitted_camera.h"
#include "engine/scene/io/label_file_loader.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/io/volume_loader.h"
#include "engine/scene/value_limits.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using strata::test::error_of;
using strata::test::write_file;

fs::path folder_for(const std::string& name) {
  return strata::test::fresh_folder("value_limits", name);
}

template <class T>
void put(std::string& bytes, size_t offset, T value) {
  std::memcpy(bytes.data() + offset, &value, sizeof value);
}

// A little-endian NIfTI-1 file of 2x2x2 uint8 voxels, pixdim 1, no qform or sform.
std::string nifti(std::array<float, 3> pixdim) {
  std::string bytes(352 + 8, '\0');
  put<int32_t>(bytes, 0, 348);
  put<int16_t>(bytes, 40, 3);
  for (size_t axis = 0; axis < 3; ++axis) put<int16_t>(bytes, 42 + 2 * axis, 2);
  put<int16_t>(bytes, 70, 2);  // uint8
  put<float>(bytes, 76, 1.0f);
  for (size_t axis = 0; axis < 3; ++axis) put<float>(bytes, 80 + 4 * axis, pixdim[axis]);
  put<float>(bytes, 108, 352.0f);
  std::memcpy(bytes.data() + 344, "n+1\0", 4);
  for (size_t i = 0; i < 8; ++i) bytes[352 + i] = char(i * 30);
  return bytes;
}

// A MetaImage (.mha) of float voxels, `dims` voxels, with the given spacing and offset.
std::string metaimage(const std::vector<float>& voxels, glm::ivec3 dims,
                      std::string spacing = "1 1 1", std::string offset = "0 0 0") {
  std::string text = "ObjectType = Image\nNDims = 3\nDimSize = " + std::to_string(dims.x) + " " +
                     std::to_string(dims.y) + " " + std::to_string(dims.z) +
                     "\nElementType = MET_FLOAT\nElementSpacing = " + spacing +
                     "\nOffset = " + offset + "\nElementDataFile = LOCAL\n";
  std::string data(voxels.size() * sizeof(float), '\0');
  std::memcpy(data.data(), voxels.data(), data.size());
  return text + data;
}

std::string load_error(const fs::path& path) {
  return error_of([&] {
    std::vector<std::string> warnings;
    strata::load_volume(path, {}, warnings);
  });
}

std::string scene_error(const fs::path& folder, const std::string& json,
                        const strata::SceneOpenOptions& options = {}) {
  const fs::path path = write_file(folder / "scene.json", json);
  return error_of([&] { strata::load_scene(path, options); });
}

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

}  // namespace

TEST_SUITE("loaders") {
  TEST_CASE("volume_spacing_outside_the_plausible_range_is_refused_naming_the_field") {
    const fs::path folder = folder_for("spacing");
    const fs::path huge = write_file(folder / "head.nii", nifti({3e38f, 1.0f, 1.0f}));
    CHECK(load_error(huge) ==
          huge.string() + ": pixdim[1]: spacing 3e+38 mm is outside 1e-06..10000");
    const fs::path tiny = write_file(folder / "tiny.nii", nifti({1.0f, 1.0f, 1e-7f}));
    CHECK(load_error(tiny) ==
          tiny.string() + ": pixdim[3]: spacing 1e-07 mm is outside 1e-06..10000");
    // The limits themselves load: electron microscopy to a coarse survey.
    const fs::path fine = write_file(folder / "fine.nii", nifti({1e-6f, 1e-6f, 1e-6f}));
    CHECK(strata::load_volume(fine).spacing.x == 1e-6f);
    const fs::path coarse = write_file(folder / "coarse.nii", nifti({1e4f, 1e4f, 1e4f}));
    CHECK(strata::load_volume(coarse).spacing.z == 1e4f);

    const fs::path mha = write_file(folder / "far.mha", metaimage({0, 1}, {2, 1, 1}, "1 2e5 1"));
    CHECK(load_error(mha) ==
          mha.string() + ": ElementSpacing[1]: spacing 200000 mm is outside 1e-06..10000");
  }

  TEST_CASE("volume_origin_far_from_the_world_origin_is_refused") {
    const fs::path folder = folder_for("origin");
    const fs::path far =
        write_file(folder / "far.mha", metaimage({0, 1}, {2, 1, 1}, "1 1 1", "0 0 3e38"));
    CHECK(load_error(far) ==
          far.string() + ": Offset: origin 0 0 3e+38 mm is outside -1e+06..1e+06");
    const fs::path edge =
        write_file(folder / "edge.mha", metaimage({0, 1}, {2, 1, 1}, "1 1 1", "-1e6 0 0"));
    CHECK(strata::load_volume(edge).origin.x == -1e6f);
    // Voxels of 1 µm a kilometre away all land on a few float values.
    const fs::path crowded = write_file(
        folder / "crowded.mha", metaimage({0, 1}, {2, 1, 1}, "0.001 0.001 0.001", "1e6 0 0"));
    CHECK(load_error(crowded).find("Offset: 1e+06 0 0 mm: 0.001 mm voxels") != std::string::npos);
    // 10 m voxels reaching past 10 km: the scene's box would leave the limits.
    std::vector<float> row(2000, 1.0f);
    row[0] = 0.0f;
    const fs::path long_row =
        write_file(folder / "long.mha", metaimage(row, {2000, 1, 1}, "1e4 1 1"));
    CHECK(load_error(long_row) ==
          long_row.string() +
              ": TransformMatrix: the volume's far corner 1.999e+07 0 0 mm is outside "
              "-1e+07..1e+07");
  }

  TEST_CASE("voxel_values_that_are_not_finite_are_refused_or_kept_as_no_data") {
    const fs::path folder = folder_for("voxels");
    const fs::path all_inf =
        write_file(folder / "inf.mha", metaimage({kInf, -kInf, kNaN, kInf}, {2, 2, 1}));
    CHECK(load_error(all_inf) ==
          all_inf.string() + ": voxels: none of the 4 is a finite number (all NaN or infinite)");
    const fs::path wide =
        write_file(folder / "wide.mha", metaimage({-3e38f, 3e38f, 0, 1}, {2, 2, 1}));
    CHECK(load_error(wide).starts_with(
        wide.string() +
        ": voxels: values from -3e+38 to 3e+38: the range is wider than a 32-bit "
        "float holds"));
    // NaN as "no data" (a masked map): shown as the lowest value, counted in a warning.
    const fs::path masked =
        write_file(folder / "masked.mha", metaimage({kNaN, 5.0f, -2.0f, kInf}, {2, 2, 1}));
    std::vector<std::string> warnings;
    const strata::Volume volume = strata::load_volume(masked, {}, warnings);
    CHECK(volume.value_range == glm::vec2(-2.0f, 5.0f));
    CHECK(volume.value(0, 0, 0) == -2.0f);
    CHECK(volume.value(1, 1, 0) == -2.0f);
    CHECK(volume.value(1, 0, 0) == 5.0f);
    bool warned = false;
    for (const std::string& w : warnings)
      warned |= w == masked.string() +
                         ": 2 of 4 voxels are NaN or infinite; shown as the lowest value, -2 "
                         "(no data)";
    CHECK(warned);
  }

  TEST_CASE("camera_lens_outside_the_limits_is_refused_naming_the_field") {
    const fs::path folder = folder_for("camera");
    const std::string prefix = (folder / "scene.json").string() + ": ";
    CHECK(scene_error(folder, R"({"strata_scene": 1, "camera": {"fov_y": 1e-7}})") ==
          prefix + "camera.fov_y: expected degrees from 0.1 to 179, got 1e-07");
    CHECK(scene_error(folder, R"({"strata_scene": 1, "camera": {"fov_y": 179.5}})") ==
          prefix + "camera.fov_y: expected degrees from 0.1 to 179, got 179.5");
    CHECK(scene_error(folder, R"({"strata_scene": 1, "camera": {"near": 0.1, "far": 1e9}})") ==
          prefix +
              "camera.far: far / near = 1e+09 / 0.1 = 1e+10, more than 1e+06: the depth range is "
              "too deep for a float projection (raise near or lower far)");
    CHECK(scene_error(folder, R"({"strata_scene": 1, "camera": {"near": 1e5, "far": 2e9}})") ==
          prefix + "camera.far: far plane 2e+09 mm is past 1e+09");
    CHECK(scene_error(
              folder,
              R"({"strata_scene": 1, "camera": {"eye": [0, 0, 3e38], "target": [0, 0, 0]}})") ==
          prefix + "camera.eye: the eye 0 0 3e+38 mm is outside -1e+07..1e+07");
    // Inside the limits: loads as written.
    const fs::path ok =
        write_file(folder / "ok.json",
                   R"({"strata_scene": 1, "labels": [{"id": 0, "text": "a", "anchor": [0, 0, 0]}],
            "camera": {"fov_y": 0.1, "near": 1, "far": 1e6, "eye": [0, 0, 10], "target": [0, 0, 0]}})");
    const strata::Scene scene = strata::load_scene(ok);
    CHECK(scene.camera.far_plane == 1e6f);
  }

  TEST_CASE("far_near_limit_keeps_the_far_plane_unprojectable_in_float") {
    // The renderer's rays come from the inverse projection at depth 1 (resolve_walk.h's
    // pixel_ray); its w must stay away from 0.
    const auto far_w = [](float near, float far) {
      strata::Camera camera;
      camera.near_plane = near;
      camera.far_plane = far;
      const glm::vec4 p = glm::inverse(camera.projection(1.0f)) * glm::vec4(0.5f, 0.5f, 1.0f, 1.0f);
      return p.w;
    };
    const float at_limit = far_w(1.0f, float(strata::value_limits::kMaxFarNearRatio));
    CHECK(at_limit > 0.0f);
    CHECK(at_limit == doctest::Approx(1e-6).epsilon(0.1));  // 1 / far, within 10 %
    CHECK_FALSE(far_w(0.1f, 1e9f) > 0.0f);  // the tester's scene: the far plane is lost
  }

  TEST_CASE("label_anchor_far_from_the_world_origin_is_refused_in_every_label_source") {
    const fs::path folder = folder_for("anchor");
    CHECK(
        scene_error(
            folder,
            R"({"strata_scene": 1, "labels": [{"id": 0, "text": "a", "anchor": [0, 0, 3e38]}]})") ==
        (folder / "scene.json").string() +
            ": labels[0].anchor: anchor 0 0 3e+38 mm is outside -1e+06..1e+06");
    const fs::path csv = write_file(folder / "far.csv", "text,l,p,s\na,0,0,1\nb,0,-2e6,0\n");
    CHECK(error_of([&] { strata::load_label_file(csv); }) ==
          csv.string() + ": line 3: anchor 0 -2e+06 0 mm is outside -1e+06..1e+06");
    const fs::path fcsv = write_file(folder / "far.fcsv",
                                     "# CoordinateSystem = LPS\n"
                                     "# columns = id,x,y,z,ow,ox,oy,oz,vis,sel,lock,label,desc,"
                                     "associatedNodeID\n"
                                     "p1,3e38,0,0,0,0,0,1,1,1,0,a,,\n");
    CHECK(error_of([&] { strata::load_label_file(fcsv); }) ==
          fcsv.string() + ": line 3: anchor 3e+38 0 0 mm is outside -1e+06..1e+06");
    const fs::path markups = write_file(
        folder / "far.mrk.json",
        R"({"@schema": "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/Schema/markups-schema-v1.0.3.json#",
            "markups": [{"type": "Fiducial", "coordinateSystem": "LPS",
                         "controlPoints": [{"label": "a", "position": [0, 0, 1e7]}]}]})");
    CHECK(
        error_of([&] { strata::load_label_file(markups); }) ==
        markups.string() +
            ": markups[0].controlPoints[0].position: anchor 0 0 1e+07 mm is outside -1e+06..1e+06");
    // The limit itself is an anchor; the fitted camera of such labels is finite and usable.
    const fs::path edge = write_file(folder / "edge.csv", "text,l,p,s\na,1e6,0,0\nb,-1e6,0,0\n");
    strata::Scene scene;
    scene.labels = strata::load_label_file(edge);
    const strata::FittedCamera fitted = strata::fitted_camera(scene);
    CHECK_FALSE(strata::lens_problem(fitted.camera).has_value());
    CHECK(std::isfinite(fitted.camera.eye().y));
  }

  TEST_CASE("volume_placed_past_the_scene_limit_by_its_transform_is_refused") {
    const fs::path folder = folder_for("transform");
    write_file(folder / "small.mha", metaimage({0, 1}, {2, 1, 1}));
    const std::string error =
        scene_error(folder, R"({"strata_scene": 1, "volumes": [{"file": "small.mha",
                    "transform": [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 3e37,  0, 0, 0, 1]}]})");
    CHECK(error == (folder / "scene.json").string() + ": volume 'small' (" +
                       (folder / "small.mha").string() +
                       "), placed by its transform: a corner at 0 0 3e+37 mm is outside "
                       "-1e+07..1e+07");
  }

  TEST_CASE("label_ids_past_int_max_are_an_error_naming_the_line") {
    const fs::path folder = folder_for("ids");
    const fs::path csv = write_file(folder / "more.csv", "text,l,p,s\na,0,0,0\nb,1,0,0\n");
    // The last id that fits, then one past it: the second row.
    CHECK(error_of([&] { strata::load_label_file(csv, INT_MAX); }) ==
          csv.string() +
              ": line 3: label id 2147483648 is past the largest, 2147483647 (this file's ids "
              "start at 2147483647, after the labels before it)");
    CHECK(strata::load_label_file(csv, INT_MAX - 1).back().id == INT_MAX);
  }

  TEST_CASE("labels_added_to_a_scene_with_the_largest_id_take_the_lowest_unused_ids") {
    const fs::path folder = folder_for("ids-free");
    const fs::path csv = write_file(folder / "more.csv", "text,l,p,s\na,0,0,0\nb,1,0,0\n");
    const fs::path scene = write_file(folder / "scene.json", R"({"strata_scene": 1, "labels": [
        {"id": 2147483647, "text": "a", "anchor": [0, 0, 9]},
        {"id": 1, "text": "b", "anchor": [0, 0, 8]}]})");
    const strata::Scene loaded = strata::load_scene(scene, {.labels = csv});
    REQUIRE(loaded.labels.size() == 4);
    CHECK(loaded.labels[2].id == 0);
    CHECK(loaded.labels[3].id == 2);
    CHECK(loaded.added_labels == 2);
  }

  TEST_CASE("nrrd_2d_in_a_2d_space_opens_as_one_slice_with_its_spacing_and_orientation") {
    const fs::path folder = folder_for("nrrd_2d");
    const std::string voxels = std::string("\x01\x02\x03\x04\x05\x06", 6);
    // As ITK writes a 2-D image: a 2-D space, 2-component vectors.
    const fs::path itk = write_file(folder / "slice.nrrd",
                                    "NRRD0004\ntype: unsigned char\ndimension: 2\n"
                                    "space dimension: 2\nsizes: 3 2\n"
                                    "space directions: (0,0.5) (0.25,0)\nkinds: domain domain\n"
                                    "endian: little\nencoding: raw\nspace origin: (10,20)\n\n" +
                                        voxels);
    std::vector<std::string> warnings;
    const strata::Volume v = strata::load_volume(itk, {}, warnings);
    CHECK(v.dims == glm::uvec3(3, 2, 1));
    CHECK(v.spacing == glm::vec3(0.5f, 0.25f, 1.0f));
    CHECK(v.direction[0] == glm::vec3(0, 1, 0));
    CHECK(v.direction[1] == glm::vec3(1, 0, 0));
    CHECK(v.direction[2] == glm::vec3(0, 0, -1));  // i x j: a right-handed frame
    CHECK(v.origin == glm::vec3(10, 20, 0));
    CHECK(v.value(2, 1, 0) == 6.0f);
    // The same slice in a 3-D space.
    const fs::path in_3d = write_file(folder / "slice3d.nrrd",
                                      "NRRD0004\ntype: unsigned char\ndimension: 2\n"
                                      "space: left-posterior-superior\nsizes: 3 2\n"
                                      "space directions: (0,0.5,0) (0.25,0,0)\n"
                                      "encoding: raw\nspace origin: (10,20,5)\n\n" +
                                          voxels);
    const strata::Volume w = strata::load_volume(in_3d, {}, warnings);
    CHECK(w.spacing == v.spacing);
    CHECK(w.direction == v.direction);
    CHECK(w.origin == glm::vec3(10, 20, 5));
    // A 2-D space cannot hold a 3-D image.
    const fs::path mismatch = write_file(folder / "mismatch.nrrd",
                                         "NRRD0004\ntype: unsigned char\ndimension: 3\n"
                                         "space dimension: 2\nsizes: 3 2 1\n"
                                         "space directions: (0,0.5) (0.25,0) (1,1)\n"
                                         "encoding: raw\n\n" +
                                             voxels);
    CHECK(load_error(mismatch) ==
          mismatch.string() +
              ": space dimension = 2: a 2-D space holds a 2-D image, but dimension is 3");
  }
}
