// Atlas regions: names, centroid labels, masks and smoothed surfaces.
#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <map>

#include "engine/core/error.h"
#include "engine/scene/atlas.h"
#include "engine/scene/io/volume_loader.h"

namespace strata {
namespace {

// A label volume with spacing and origin: region 3 is a ball of radius `r` voxels around `c`,
// region 7 a 2x3x4 box.
Volume synthetic_atlas(glm::uvec3 dims, glm::vec3 c, float r) {
  Volume v;
  v.name = "synthetic";
  v.type = VoxelType::uint8;
  v.dims = dims;
  v.spacing = {2.0f, 1.0f, 0.5f};
  v.origin = {-10.0f, 5.0f, 100.0f};
  v.voxels.assign(v.voxel_count(), std::byte{0});
  for (uint32_t z = 0; z < dims.z; ++z) {
    for (uint32_t y = 0; y < dims.y; ++y) {
      for (uint32_t x = 0; x < dims.x; ++x) {
        const size_t i = (size_t(z) * dims.y + y) * dims.x + x;
        if (glm::length(glm::vec3(x, y, z) - c) <= r) v.voxels[i] = std::byte{3};
        if (x < 2 && y < 3 && z < 4) v.voxels[i] = std::byte{7};
      }
    }
  }
  v.value_range = {0.0f, 7.0f};
  return v;
}

const std::vector<AtlasRegion> kRegions = {{3, "Ball_L", 0}, {5, "Absent", 0}, {7, "Box_R", 0}};

}  // namespace

TEST_SUITE("loaders") {
  TEST_CASE("aal_names_file_gives_116_named_regions") {
    const auto regions = load_atlas_names(STRATA_DATA_CACHE "/mricron/aal.nii.txt");
    REQUIRE(regions.size() == 116);
    CHECK(regions.front().index == 1);
    CHECK(regions.front().name == "Precentral_L");
    CHECK(regions.front().colour == 2001);
    CHECK(regions.back().index == 116);
  }

  TEST_CASE("aal_atlas_yields_116_labels_inside_the_head") {
    const Volume aal = load_volume(STRATA_DATA_CACHE "/mricron/aal.nii.gz");
    const auto regions = load_atlas_names(STRATA_DATA_CACHE "/mricron/aal.nii.txt");
    const std::vector<Label> labels = atlas_labels(aal, regions);
    REQUIRE(labels.size() == 116);
    const auto [lo, hi] = aal.world_bounds();
    for (const Label& l : labels) {
      CHECK(glm::all(glm::greaterThanEqual(l.anchor, lo)));
      CHECK(glm::all(glm::lessThanEqual(l.anchor, hi)));
    }
    CHECK(labels.front().text == "Precentral L");
    // Left-hemisphere regions lie on the other side of the midline from their right twins.
    CHECK((labels[0].anchor.x - labels[1].anchor.x) * (labels[2].anchor.x - labels[3].anchor.x) >
          0.0f);
  }

  TEST_CASE("atlas_labels_sit_at_region_centroids_in_world_space") {
    const Volume v = synthetic_atlas({20, 16, 12}, {10, 8, 6}, 4.0f);
    const std::vector<Label> labels = atlas_labels(v, kRegions);
    REQUIRE(labels.size() == 2);  // "Absent" has no voxels
    CHECK(labels[0].id == 3);
    CHECK(labels[0].text == "Ball L");
    // The ball is symmetric about voxel (10, 8, 6): world = origin + spacing * index.
    CHECK(labels[0].anchor.x == doctest::Approx(-10.0f + 2.0f * 10));
    CHECK(labels[0].anchor.y == doctest::Approx(5.0f + 1.0f * 8));
    CHECK(labels[0].anchor.z == doctest::Approx(100.0f + 0.5f * 6));
    CHECK(labels[1].anchor.x == doctest::Approx(-10.0f + 2.0f * 0.5f));
    CHECK(labels[1].anchor.y == doctest::Approx(5.0f + 1.0f * 1.0f));
    CHECK(labels[1].anchor.z == doctest::Approx(100.0f + 0.5f * 1.5f));
  }

  // A point is named by the region of its nearest voxel (spacing and origin applied), with '_'
  // as ' '; outside the volume, on 0 and on an index without a name: none. The scene's first
  // atlas that names it wins.
  TEST_CASE("atlas_region_at_names_the_region_of_the_nearest_voxel") {
    SceneAtlas atlas{synthetic_atlas({20, 16, 12}, {10, 8, 6}, 4.0f), {}};
    for (const AtlasRegion& r : kRegions) atlas.names[r.index] = r.name;
    const auto world = [&](glm::vec3 index) {
      return glm::vec3(atlas.labels.index_to_world() * glm::vec4(index, 1.0f));
    };
    CHECK(atlas_region_at(atlas, world({10.0f, 8.0f, 6.0f})) == "Ball L");
    CHECK(atlas_region_at(atlas, world({10.4f, 7.6f, 6.3f})) == "Ball L");
    CHECK(atlas_region_at(atlas, world({1.0f, 2.0f, 3.0f})) == "Box R");
    CHECK(atlas_region_at(atlas, world({1.0f, 2.0f, 3.6f})).empty());  // (voxel 4: region 0)
    CHECK(atlas_region_at(atlas, world({-0.6f, 0.0f, 0.0f})).empty());  // outside
    CHECK(atlas_region_at(atlas, world({19.0f, 15.0f, 12.0f})).empty());
    atlas.names.erase(7);
    CHECK(atlas_region_at(atlas, world({1.0f, 2.0f, 3.0f})).empty());
    Scene scene;
    scene.atlases = {atlas, atlas};
    scene.atlases[1].names[7] = "Other_Box";
    CHECK(atlas_region_at(scene, world({1.0f, 2.0f, 3.0f})) == "Other Box");
    CHECK(atlas_region_at(scene, world({10.0f, 8.0f, 6.0f})) == "Ball L");
  }

  TEST_CASE("atlas_mask_marks_exactly_the_region_voxels") {
    const Volume v = synthetic_atlas({20, 16, 12}, {10, 8, 6}, 4.0f);
    const Volume mask = atlas_mask(v, kRegions[2]);
    CHECK(mask.type == VoxelType::uint8);
    CHECK(mask.dims == v.dims);
    CHECK(mask.index_to_world() == v.index_to_world());
    size_t inside = 0;
    for (size_t i = 0; i < mask.voxel_count(); ++i) {
      const bool in_region = v.voxels[i] == std::byte{7};
      CHECK((mask.voxels[i] == std::byte{255}) == in_region);
      inside += in_region;
    }
    CHECK(inside == 2 * 3 * 4);
  }

  TEST_CASE("atlas_surface_is_closed_outward_and_keeps_the_ball_size") {
    Volume v = synthetic_atlas({24, 24, 24}, {12, 12, 12}, 7.0f);
    v.spacing = glm::vec3(1.0f);
    v.origin = glm::vec3(0.0f);
    const Mesh mesh = atlas_surface(v, kRegions[0], 10);
    REQUIRE(mesh.triangle_count() > 100);
    CHECK(mesh.normals.size() == mesh.positions.size());

    // Closed: every undirected edge is used by exactly two triangles, once in each direction.
    std::map<std::pair<uint32_t, uint32_t>, int> directed;
    for (size_t t = 0; t < mesh.indices.size(); t += 3) {
      for (int i = 0; i < 3; ++i) ++directed[{mesh.indices[t + i], mesh.indices[t + (i + 1) % 3]}];
    }
    size_t unmatched = 0;
    for (const auto& [edge, count] : directed) {
      unmatched += count != 1 || directed.count({edge.second, edge.first}) != 1;
    }
    CHECK(unmatched == 0);

    // Outward: the enclosed volume by the divergence theorem is positive and close to the ball's
    // voxel count; smoothing does not shrink the radius.
    double volume = 0.0, radius = 0.0;
    const glm::vec3 centre(12.0f);
    for (size_t t = 0; t < mesh.indices.size(); t += 3) {
      const glm::dvec3 a = mesh.positions[mesh.indices[t]] - centre;
      const glm::dvec3 b = mesh.positions[mesh.indices[t + 1]] - centre;
      const glm::dvec3 c = mesh.positions[mesh.indices[t + 2]] - centre;
      volume += glm::dot(a, glm::cross(b, c)) / 6.0;
    }
    size_t outward = 0;
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      radius += glm::length(mesh.positions[i] - centre);
      outward += glm::dot(mesh.normals[i], mesh.positions[i] - centre) > 0.0f;
    }
    radius /= double(mesh.positions.size());
    const double ball = 4.0 / 3.0 * 3.14159265 * 7.0 * 7.0 * 7.0;
    CHECK(volume == doctest::Approx(ball).epsilon(0.12));
    CHECK(radius == doctest::Approx(7.0).epsilon(0.08));
    CHECK(outward == mesh.positions.size());
  }

  TEST_CASE("atlas_inputs_that_are_not_atlases_are_clear_errors") {
    CHECK_THROWS_WITH_AS(load_atlas_names("/nonexistent/aal.txt"),
                         doctest::Contains("no such file"), Error);
    const std::string bad = STRATA_TEST_OUTPUT "/bad-names.txt";
    std::filesystem::create_directories(STRATA_TEST_OUTPUT);
    { std::ofstream(bad) << "1 Precentral_L 2001\nnot-a-number here\n"; }
    CHECK_THROWS_WITH_AS(load_atlas_names(bad), doctest::Contains("line 2"), Error);
    Volume empty;
    CHECK_THROWS_AS(atlas_labels(empty, kRegions), Error);
  }
}

}  // namespace strata
