// save_scene_json writes what it read: every demo scene and every example of
// docs/scene-format.md, written (with a new camera position) and loaded again, is the same scene,
// and written again gives the same bytes. An atlas stays an atlas entry.
#include <doctest/doctest.h>

#include <filesystem>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/scene/io/scene_loader.h"
#include "engine/scene/io/volume_loader.h"
#include "test_files.h"

namespace fs = std::filesystem;

namespace strata {
namespace {

const fs::path source = STRATA_SOURCE_DIR;

fs::path normal(const fs::path& path) {
  return path.empty() ? path : fs::absolute(path).lexically_normal();
}

void check_same_tf(const Scene& a, int ia, const Scene& b, int ib) {
  REQUIRE((ia < 0) == (ib < 0));
  if (ia < 0) return;
  const TransferFunction& x = a.transfer_functions.at(size_t(ia));
  const TransferFunction& y = b.transfer_functions.at(size_t(ib));
  CHECK(normal(x.source) == normal(y.source));
  REQUIRE(x.stops.size() == y.stops.size());
  for (size_t i = 0; i < x.stops.size(); ++i) {
    CHECK(x.stops[i].position == y.stops[i].position);
    CHECK(x.stops[i].color == y.stops[i].color);
  }
}

// Everything a scene file says, compared field by field.
void check_same_scene(const Scene& a, const Scene& b) {
  REQUIRE(a.volumes.size() == b.volumes.size());
  for (size_t i = 0; i < a.volumes.size(); ++i) {
    const Volume &x = a.volumes[i], &y = b.volumes[i];
    INFO("volume " << x.name);
    CHECK(x.name == y.name);
    CHECK(normal(x.source) == normal(y.source));
    CHECK(x.dims == y.dims);
    CHECK(x.transform == y.transform);
    CHECK(x.index_to_patient() == y.index_to_patient());
    CHECK(x.value_range == y.value_range);
    CHECK(x.voxels == y.voxels);
    check_same_tf(a, x.transfer_function, b, y.transfer_function);
  }
  REQUIRE(a.meshes.size() == b.meshes.size());
  for (size_t i = 0; i < a.meshes.size(); ++i) {
    const Mesh &x = a.meshes[i], &y = b.meshes[i];
    INFO("mesh " << x.name);
    CHECK(x.name == y.name);
    CHECK(normal(x.source) == normal(y.source));
    CHECK(x.color == y.color);
    CHECK(x.transform == y.transform);
    CHECK(x.positions == y.positions);
    CHECK(x.indices == y.indices);
  }
  REQUIRE(a.labels.size() == b.labels.size());
  for (size_t i = 0; i < a.labels.size(); ++i) {
    const Label &x = a.labels[i], &y = b.labels[i];
    INFO("label " << x.text);
    CHECK(x.id == y.id);
    CHECK(x.text == y.text);
    CHECK(x.anchor == y.anchor);
    CHECK(x.size == y.size);
    CHECK(x.priority == y.priority);
    REQUIRE(x.image.has_value() == y.image.has_value());
    if (x.image) {
      CHECK(normal(x.image->file) == normal(y.image->file));
      CHECK(x.image->height == y.image->height);
      CHECK(x.image->side == y.image->side);
      CHECK(x.image->pixels.pixels == y.image->pixels.pixels);
    }
  }
  CHECK(a.has_camera == b.has_camera);
  CHECK(a.camera.view == b.camera.view);
  CHECK(a.camera.fov_y_degrees == b.camera.fov_y_degrees);
  CHECK(a.camera.near_plane == b.camera.near_plane);
  CHECK(a.camera.far_plane == b.camera.far_plane);
  REQUIRE(a.camera_positions.size() == b.camera_positions.size());
  for (size_t i = 0; i < a.camera_positions.size(); ++i) {
    CHECK(a.camera_positions[i].name == b.camera_positions[i].name);
    CHECK(a.camera_positions[i].view == b.camera_positions[i].view);
  }
  CHECK(a.settings.layer_count == b.settings.layer_count);
  CHECK(a.settings.ghost == b.settings.ghost);
  CHECK(a.settings.ghost_radius == b.settings.ghost_radius);
  const CostWeights &w = a.settings.weights, &v = b.settings.weights;
  CHECK(w.label_shadow == v.label_shadow);
  CHECK(w.anchor_constraint == v.anchor_constraint);
  CHECK(w.connector_shadow == v.connector_shadow);
  CHECK(w.integral_costs == v.integral_costs);
  CHECK(w.distance_to_anchor == v.distance_to_anchor);
  CHECK(w.connector_direction == v.connector_direction);
  CHECK(w.previous_position == v.previous_position);
  CHECK(w.leader_crossing == v.leader_crossing);
  CHECK(w.illegible == v.illegible);
}

// As the viewer saves: the loaded (completed) scene with one new position, written to `out`;
// loaded again it is that scene, and written again (beside it) the same bytes.
void check_round_trip(const fs::path& file, const fs::path& out) {
  INFO(file.string());
  Scene scene = load_scene(file);
  scene.camera_positions.push_back(
      {"saved", glm::lookAt(glm::vec3(1.5f, -300.25f, 20.0f), glm::vec3(0.0f, 0.0f, 10.0f),
                            glm::vec3(0.0f, 0.0f, 1.0f))});
  save_scene_json(out, scene);
  const Scene reloaded = load_scene(out);
  check_same_scene(scene, reloaded);
  fs::path again = out;
  again.replace_extension(".again.json");
  save_scene_json(again, reloaded);
  CHECK(test::read_file(again) == test::read_file(out));
}

// The ```-fenced blocks of a page that are strata scenes.
std::vector<test::CodeBlock> scene_blocks(const std::string& markdown) {
  std::vector<test::CodeBlock> blocks = test::code_blocks(markdown);
  std::erase_if(blocks, [](const test::CodeBlock& block) {
    return block.text.find("\"strata_scene\"") == std::string::npos;
  });
  return blocks;
}

}  // namespace

TEST_SUITE("loaders") {
  TEST_CASE("every_demo_scene_written_and_loaded_again_is_the_same_scene") {
    const fs::path out = test::fresh_folder("scene_writer", "demo");
    size_t scenes = 0;
    for (const auto& entry : fs::directory_iterator(source / "assets/scenes")) {
      if (entry.path().extension() != ".json") continue;
      check_round_trip(entry.path(), out / entry.path().filename());
      ++scenes;
    }
    CHECK(scenes >= 4);
  }

  TEST_CASE("an_atlas_written_back_stays_an_atlas_entry") {
    const fs::path out = test::fresh_folder("scene_writer", "atlas") / "head-surfaces.json";
    save_scene_json(out, load_scene(source / "assets/scenes/head-surfaces.json"));
    const std::string text = test::read_file(out);
    CHECK(text.find("\"atlas\"") != std::string::npos);
    CHECK(text.find("aal.nii.gz") == text.rfind("aal.nii.gz"));  // once: not also a mesh file
    CHECK(text.find("\"meshes\"") == std::string::npos);
    CHECK(text.find("head-t1.json") != std::string::npos);  // the transfer function by file
    CHECK(load_scene(out).meshes.size() == 5);
  }

  TEST_CASE("every_scene_example_in_the_format_page_written_and_loaded_again_is_the_same") {
    // The examples' paths are as seen from assets/scenes/: that layout, the data linked in.
    const fs::path root = test::fresh_folder("scene_writer", "examples");
    fs::create_directories(root / "scenes");
    fs::create_directory_symlink(source / "assets/cache", root / "cache");
    fs::create_directory_symlink(source / "assets/transfer_functions", root / "transfer_functions");
    fs::create_directory_symlink(source / "assets/scenes/pictures", root / "scenes/pictures");
    test::write_file(root / "models/skull.ply",
                     "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                     "property float y\nproperty float z\nelement face 1\n"
                     "property list uchar int vertex_indices\nend_header\n"
                     "0 0 0\n10 0 0\n0 10 0\n3 0 1 2\n");
    const fs::path out = root / "written";
    fs::create_directories(out);
    size_t scenes = 0;
    for (const test::CodeBlock& block :
         scene_blocks(test::read_file(source / "docs/scene-format.md"))) {
      INFO("docs/scene-format.md line " << block.line);
      const std::string name = "example-" + std::to_string(block.line) + ".json";
      check_round_trip(test::write_file(root / "scenes" / name, block.text), out / name);
      ++scenes;
    }
    CHECK(scenes >= 1);
  }

  TEST_CASE("a_volume_opened_as_a_scene_written_and_loaded_again_is_the_same_scene") {
    const fs::path folder = test::fresh_folder("scene_writer", "volume");
    Volume volume;
    volume.type = VoxelType::uint8;
    volume.dims = {6, 5, 4};
    volume.spacing = {1.0f, 1.5f, 2.0f};
    volume.voxels.resize(volume.voxel_count());
    for (size_t i = 0; i < volume.voxels.size(); ++i) volume.voxels[i] = std::byte(i * 7 % 251);
    write_metaimage(folder / "scan.mha", volume, false);
    check_round_trip(folder / "scan.mha", folder / "scan.scene.json");
  }
}

}  // namespace strata
