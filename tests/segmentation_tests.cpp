// The segmentation model (engine/scene/segmentation.h): regions packed into layers, label maps
// with names, anchors deepest inside each region (checked against a brute-force search), and the
// geometry checks against the scan.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <set>

#include <zlib.h>

#include "engine/core/error.h"
#include "engine/scene/atlas.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/segmentation.h"
#include "test_files.h"

using namespace strata;

namespace {

Volume grid(glm::uvec3 dims, glm::vec3 spacing = glm::vec3(1.0f)) {
  Volume v;
  v.name = "grid";
  v.source = "seg.nii.gz";
  v.dims = dims;
  v.spacing = spacing;
  v.origin = {-10.0f, 20.0f, 5.0f};
  return v;
}

size_t at(const Volume& v, int x, int y, int z) {
  return (size_t(z) * v.dims.y + y) * v.dims.x + x;
}

// A C: a thick ring around the z axis at the grid's middle, open toward +x.
std::vector<uint8_t> c_shape(const Volume& g) {
  std::vector<uint8_t> inside(g.voxel_count(), 0);
  const glm::vec2 centre = glm::vec2(g.dims.x, g.dims.y) * 0.5f;
  for (int z = 2; z < int(g.dims.z) - 2; ++z)
    for (int y = 0; y < int(g.dims.y); ++y)
      for (int x = 0; x < int(g.dims.x); ++x) {
        const glm::vec2 d = glm::vec2(x, y) + 0.5f - centre;
        const float r = glm::length(d);
        if (r >= 6.0f && r <= 10.0f && !(d.x > 0.0f && std::fabs(d.y) < 4.0f))
          inside[at(g, x, y, z)] = 1;
      }
  return inside;
}

std::vector<uint8_t> ball(const Volume& g, glm::vec3 centre, float radius) {
  std::vector<uint8_t> inside(g.voxel_count(), 0);
  for (int z = 0; z < int(g.dims.z); ++z)
    for (int y = 0; y < int(g.dims.y); ++y)
      for (int x = 0; x < int(g.dims.x); ++x)
        if (glm::length((glm::vec3(x, y, z) - centre) * g.spacing) <= radius)
          inside[at(g, x, y, z)] = 1;
  return inside;
}

glm::vec3 world_of(const Volume& g, glm::vec3 index) {
  return glm::vec3(g.index_to_world() * glm::vec4(index, 1.0f));
}

}  // namespace

TEST_CASE("segmentation: regions that overlap go to another layer, the others share one") {
  const Volume g = grid({24, 24, 16});
  Segmentation s;
  s.source = g.source;
  add_region_voxels(s, g, ball(g, {6, 6, 8}, 4.0f), {.number = 1, .name = "left"});
  add_region_voxels(s, g, ball(g, {17, 17, 8}, 4.0f), {.number = 2, .name = "right"});
  add_region_voxels(s, g, ball(g, {8, 8, 8}, 4.0f), {.number = 3, .name = "over left"});
  REQUIRE(s.layers.size() == 2);
  CHECK(s.regions[0].layer == 0);
  CHECK(s.regions[1].layer == 0);
  CHECK(s.regions[2].layer == 1);
  CHECK(s.regions[2].value == 3);
  CHECK(s.layers[1].type == VoxelType::uint16);
  CHECK(s.layers[1].origin == g.origin);
  CHECK(region_contains(s, s.regions[2], world_of(g, {8, 8, 8})));
  CHECK(region_contains(s, s.regions[0], world_of(g, {6, 6, 8})));
  CHECK_FALSE(region_contains(s, s.regions[1], world_of(g, {6, 6, 8})));
  CHECK_FALSE(region_contains(s, s.regions[1], world_of(g, {-3, 6, 8})));  // outside the grid
  // The same number again in one layer would merge two regions: it goes to the next layer
  // where its number is free.
  add_region_voxels(s, g, ball(g, {20, 4, 8}, 2.0f), {.number = 1, .name = "again"});
  CHECK(s.regions[3].layer == 1);
  add_region_voxels(s, g, ball(g, {20, 20, 2}, 1.0f), {.number = 1, .name = "third"});
  CHECK(s.regions[4].layer == 2);
  CHECK_THROWS_WITH_AS(add_region_voxels(s, g, ball(g, {1, 1, 1}, 1.0f), {.number = 0}),
                       doctest::Contains("number 0 is outside 1..65535"), Error);
  CHECK_THROWS_WITH_AS(add_region_voxels(s, g, std::vector<uint8_t>(5, 1), {.number = 9}),
                       doctest::Contains("has 5 voxels, the grid 9216"), Error);
}

TEST_CASE("segmentation: a label map with a names table keeps the table's order and names") {
  Volume map = grid({8, 8, 8});
  map.type = VoxelType::uint8;
  map.voxels.assign(map.voxel_count(), std::byte{0});
  map.voxels[at(map, 1, 1, 1)] = std::byte{7};
  map.voxels[at(map, 2, 2, 2)] = std::byte{3};
  map.voxels[at(map, 3, 3, 3)] = std::byte{9};  // named by no one
  NamesTable names{"test",
                   {{0, "background", {}},
                    {7, "liver", glm::vec3(1, 0, 0)},
                    {3, "spleen", {}},
                    {5, "aorta", {}}}};
  std::vector<std::string> warnings;
  const Segmentation s = segmentation_from_label_map(map, names, warnings);
  REQUIRE(s.regions.size() == 3);
  CHECK(s.regions[0].name == "liver");
  CHECK(s.regions[0].colour == glm::vec3(1, 0, 0));
  CHECK(s.regions[1].name == "spleen");
  CHECK(s.regions[2].name == "aorta");
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0].find("left out: 9") != std::string::npos);
  const std::vector<RegionSummary> summary = summarise_regions(s);
  CHECK(summary[0].voxels == 1);
  CHECK(summary[2].voxels == 0);  // named, no voxels
  CHECK(summary[0].anchor == world_of(map, {1, 1, 1}));

  Volume fractions = map;
  fractions.type = VoxelType::float32;
  fractions.voxels.assign(fractions.voxel_count() * 4, std::byte{0});
  const float half = 0.5f;
  std::memcpy(fractions.voxels.data() + 4 * 10, &half, 4);
  CHECK_THROWS_WITH_AS(segmentation_from_label_map(fractions, names, warnings),
                       doctest::Contains("not a whole number"), Error);
}

TEST_CASE("segmentation: the C-shape's anchor is inside it, where its centroid is not") {
  const Volume g = grid({28, 28, 12}, {0.8f, 0.8f, 2.0f});
  Segmentation s;
  s.source = g.source;
  const std::vector<uint8_t> c = c_shape(g);
  add_region_voxels(s, g, c, {.number = 4, .name = "C"});
  glm::dvec3 sum(0.0);
  size_t count = 0;
  for (int z = 0; z < 12; ++z)
    for (int y = 0; y < 28; ++y)
      for (int x = 0; x < 28; ++x)
        if (c[at(g, x, y, z)]) sum += glm::dvec3(x, y, z), ++count;
  const glm::vec3 centroid = world_of(g, glm::vec3(sum / double(count)));
  CHECK_FALSE(region_contains(s, s.regions[0], centroid));
  const RegionSummary summary = summarise_regions(s)[0];
  CHECK(summary.parts == 1);
  CHECK(summary.voxels == count);
  CHECK(summary.millilitres == doctest::Approx(double(count) * 0.8 * 0.8 * 2.0 / 1000.0));
  CHECK(region_contains(s, s.regions[0], summary.anchor));
  // The deepest point of a ring 4 voxels thick is on the ring's middle circle (radius 8), at
  // the middle slice pair, and opposite the opening (toward the centroid's side: -x).
  const glm::vec3 index =
      glm::vec3(glm::inverse(g.index_to_world()) * glm::vec4(summary.anchor, 1.0f));
  const glm::vec2 d = glm::vec2(index) + 0.5f - glm::vec2(14.0f);
  CHECK(glm::length(d) == doctest::Approx(8.0f).epsilon(0.12));
  CHECK(d.x < 0.0f);
}

TEST_CASE("segmentation: the anchor is the deepest voxel, as a brute-force search finds it") {
  std::mt19937 random(7);
  for (int round = 0; round < 4; ++round) {
    const glm::vec3 spacing(0.7f + 0.3f * float(round), 1.3f, 2.1f - 0.4f * float(round));
    const Volume g = grid({14, 12, 10}, spacing);
    std::vector<uint8_t> inside(g.voxel_count(), 0);
    // A few overlapping balls: one connected blob of odd shape.
    for (int b = 0; b < 4; ++b) {
      const glm::vec3 c(float(4 + random() % 6), float(4 + random() % 4), float(3 + random() % 4));
      const std::vector<uint8_t> one = ball(g, c, 2.5f + float(random() % 3u));
      for (size_t i = 0; i < inside.size(); ++i) inside[i] |= one[i];
    }
    Segmentation s;
    s.source = g.source;
    add_region_voxels(s, g, inside, {.number = 1, .name = "blob"});
    const RegionSummary summary = summarise_regions(s)[0];
    // Brute force: each inside voxel's distance (mm) to the nearest voxel outside the region,
    // the grid's outside counting as outside.
    const auto depth = [&](glm::ivec3 p) {
      double best = 1e300;
      for (int z = -1; z <= int(g.dims.z); ++z)
        for (int y = -1; y <= int(g.dims.y); ++y)
          for (int x = -1; x <= int(g.dims.x); ++x) {
            const bool out = x < 0 || y < 0 || z < 0 || x >= int(g.dims.x) || y >= int(g.dims.y) ||
                             z >= int(g.dims.z) || !inside[at(g, x, y, z)];
            if (!out) continue;
            const glm::dvec3 d = glm::dvec3(glm::ivec3(x, y, z) - p) * glm::dvec3(spacing);
            best = std::min(best, glm::dot(d, d));
          }
      return best;
    };
    double deepest = 0.0;
    for (int z = 0; z < int(g.dims.z); ++z)
      for (int y = 0; y < int(g.dims.y); ++y)
        for (int x = 0; x < int(g.dims.x); ++x)
          if (inside[at(g, x, y, z)]) deepest = std::max(deepest, depth({x, y, z}));
    const glm::vec3 index =
        glm::round(glm::vec3(glm::inverse(g.index_to_world()) * glm::vec4(summary.anchor, 1.0f)));
    CAPTURE(round);
    CHECK(depth(glm::ivec3(index)) == doctest::Approx(deepest));
    CHECK(region_contains(s, s.regions[0], summary.anchor));
  }
}

TEST_CASE("segmentation: a region in two parts is anchored in the larger, ties toward the centre") {
  const Volume g = grid({30, 12, 12});
  Segmentation s;
  s.source = g.source;
  std::vector<uint8_t> two = ball(g, {6, 6, 6}, 3.0f);
  const std::vector<uint8_t> big = ball(g, {20, 6, 6}, 5.0f);
  for (size_t i = 0; i < two.size(); ++i) two[i] |= big[i];
  add_region_voxels(s, g, two, {.number = 2, .name = "split"});
  const RegionSummary summary = summarise_regions(s)[0];
  CHECK(summary.parts == 2);
  CHECK(summary.anchor == world_of(g, {20, 6, 6}));

  // A bar: every voxel of its middle line is equally deep; the one nearest its centroid wins.
  Segmentation bar;
  bar.source = g.source;
  std::vector<uint8_t> inside(g.voxel_count(), 0);
  for (int z = 5; z <= 7; ++z)
    for (int y = 5; y <= 7; ++y)
      for (int x = 3; x <= 25; ++x) inside[at(g, x, y, z)] = 1;
  add_region_voxels(bar, g, inside, {.number = 1, .name = "bar"});
  CHECK(summarise_regions(bar)[0].anchor == world_of(g, {14, 6, 6}));
}

TEST_CASE("segmentation: a grid that misses the scan or turns away from it is refused") {
  const Volume g = grid({10, 10, 10});
  Segmentation s;
  s.source = "seg.nii.gz";
  add_region_voxels(s, g, ball(g, {5, 5, 5}, 3.0f), {.number = 1, .name = "ball"});
  Volume scan = grid({20, 20, 20});
  scan.source = "ct.nii.gz";
  CHECK_NOTHROW(check_segmentation_fits(s, scan));
  // Axes swapped and flipped are the same orientation.
  scan.direction = glm::mat3(glm::vec3(0, -1, 0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1));
  CHECK_NOTHROW(check_segmentation_fits(s, scan));
  scan.direction = glm::mat3(1.0f);
  scan.origin = {500.0f, 20.0f, 5.0f};
  CHECK_THROWS_WITH_AS(check_segmentation_fits(s, scan),
                       doctest::Contains("seg.nii.gz and ct.nii.gz: the segmentation's grid "
                                         "does not overlap the scan"),
                       Error);
  scan.origin = g.origin;
  const float a = glm::radians(30.0f);
  scan.direction = glm::mat3(glm::vec3(std::cos(a), std::sin(a), 0),
                             glm::vec3(-std::sin(a), std::cos(a), 0), glm::vec3(0, 0, 1));
  CHECK_THROWS_WITH_AS(check_segmentation_fits(s, scan),
                       doctest::Contains("their orientations disagree"), Error);
}

// ---- a segmentation in a scene (add_segmentation, the "segmentations" entry)

namespace {

namespace fs = std::filesystem;

// A label map on the scan's grid (a 40^3 box, 2 mm voxels) holding the given balls, written as
// .mha, and an ITK-SNAP names table for values 1..names.size().
struct TestSegmentation {
  fs::path folder, scan, labels, names;
};

TestSegmentation write_segmentation(const std::string& name,
                                    const std::vector<std::pair<glm::vec3, float>>& balls,
                                    const std::vector<std::string>& names,
                                    glm::vec3 labels_origin = glm::vec3(-40.0f),
                                    glm::mat3 labels_direction = glm::mat3(1.0f)) {
  TestSegmentation t;
  t.folder = test::fresh_folder("segmentation", name);
  Volume scan = grid({40, 40, 40}, glm::vec3(2.0f));
  scan.origin = glm::vec3(-40.0f);
  scan.type = VoxelType::uint8;
  scan.voxels.assign(scan.voxel_count(), std::byte{60});
  t.scan = t.folder / "scan.mha";
  write_metaimage(t.scan, scan);
  Volume map = grid({40, 40, 40}, glm::vec3(2.0f));
  map.origin = labels_origin;
  map.direction = labels_direction;
  map.type = VoxelType::uint16;
  map.voxels.assign(map.voxel_count() * 2, std::byte{0});
  for (size_t b = 0; b < balls.size(); ++b) {
    const std::vector<uint8_t> inside = ball(map, balls[b].first, balls[b].second);
    const uint16_t value = uint16_t(b + 1);
    for (size_t i = 0; i < inside.size(); ++i)
      if (inside[i]) std::memcpy(map.voxels.data() + 2 * i, &value, 2);
  }
  t.labels = t.folder / "labels.mha";
  write_metaimage(t.labels, map);
  std::string table = "# ITK-SNAP Label Description File\n";
  for (size_t n = 0; n < names.size(); ++n)
    table += std::to_string(n + 1) + " 200 100 50 1 1 1 \"" + names[n] + "\"\n";
  t.names = test::write_file(t.folder / "names.txt", table);
  return t;
}

// A scene of scan.mha with labels.mha and names.txt beside it (write_segmentation's files).
std::string scene_json(const std::string& entry_keys, const std::string& labels = "[]") {
  return R"({"strata_scene": 1, "volumes": [{"file": "scan.mha"}], "labels": )" + labels +
         R"(, "segmentations": [{"file": "labels.mha", "names": "names.txt")" + entry_keys + "}]}";
}

}  // namespace

TEST_CASE("segmentation in a scene: labels named after the regions, anchored inside them") {
  const TestSegmentation t = write_segmentation(
      "scene", {{{10, 10, 10}, 12.0f}, {{28, 28, 28}, 10.0f}, {{30, 8, 20}, 6.0f}},
      {"liver", "spleen_tip", "kidney"});
  const fs::path file = test::write_file(
      t.folder / "scene.json", scene_json(R"(, "make": ["labels", "masks"])",
                                          R"([{"id": 0, "text": "own", "anchor": [0, 0, 0]}])"));
  const Scene scene = load_scene_json(file);
  REQUIRE(scene.labels.size() == 4);
  CHECK(scene.labels[1].text == "liver");
  CHECK(scene.labels[2].text == "spleen tip");
  CHECK(scene.labels[3].text == "kidney");
  std::set<int> ids;
  for (const Label& l : scene.labels) ids.insert(l.id);
  CHECK(ids.size() == 4);
  // Anchors at the balls' centres (the deepest voxels), in world space.
  CHECK(glm::length(scene.labels[1].anchor - glm::vec3(-40.0f + 2.0f * 10.0f)) < 1e-3f);
  REQUIRE(scene.atlases.size() == 1);
  for (size_t l = 1; l < 4; ++l) CHECK(atlas_region_at(scene, scene.labels[l].anchor) != "");
  CHECK(atlas_region_at(scene, scene.labels[3].anchor) == "kidney");
  // A mask per region, in the table's colour.
  REQUIRE(scene.volumes.size() == 4);
  CHECK(scene.volumes[1].name == "liver");
  const TransferFunction& tf =
      scene.transfer_functions.at(size_t(scene.volumes[1].transfer_function));
  CHECK(glm::length(glm::vec3(tf.sample(1.0f)) - glm::vec3(200, 100, 50) / 255.0f) < 1e-3f);
  REQUIRE(scene.segmentations.size() == 1);
  CHECK(scene.segmentations[0].masks);
}

TEST_CASE("segmentation in a scene: regions chosen by name, empty ones warned, faults refused") {
  const TestSegmentation t = write_segmentation(
      "choose", {{{10, 10, 10}, 8.0f}, {{30, 30, 30}, 6.0f}}, {"liver", "spleen", "pancreas"});
  const Scene some = load_scene_json(
      test::write_file(t.folder / "some.json", scene_json(R"(, "regions": ["spleen"])")));
  REQUIRE(some.labels.size() == 1);
  CHECK(some.labels[0].text == "spleen");

  const Scene all = load_scene_json(test::write_file(t.folder / "all.json", scene_json("")));
  CHECK(all.labels.size() == 2);
  REQUIRE(all.warnings.size() == 1);
  CHECK(all.warnings[0].find("region 'pancreas' (3) has no voxels: skipped") != std::string::npos);

  const std::string unknown = test::error_of([&] {
    load_scene_json(
        test::write_file(t.folder / "unknown.json", scene_json(R"(, "regions": ["heart"])")));
  });
  CHECK(unknown.find("no region 'heart' (it has 3: liver, spleen, pancreas)") != std::string::npos);
  CHECK(unknown.find("segmentations[0].file") != std::string::npos);
}

TEST_CASE("segmentation in a scene: a grid of its own is placed through world space") {
  // The label map's x axis runs right to left and its y and z axes are swapped: its voxel
  // (10, 12, 8) is world (40 - 20, -40 + 16, -40 + 24).
  const glm::mat3 turned(glm::vec3(-1, 0, 0), glm::vec3(0, 0, 1), glm::vec3(0, 1, 0));
  const TestSegmentation t = write_segmentation("turned", {{{10, 12, 8}, 7.0f}}, {"liver"},
                                                glm::vec3(40.0f, -40.0f, -40.0f), turned);
  const Scene scene = load_scene_json(test::write_file(t.folder / "turned.json", scene_json("")));
  REQUIRE(scene.labels.size() == 1);
  CHECK(glm::length(scene.labels[0].anchor - glm::vec3(20.0f, -24.0f, -16.0f)) < 1e-3f);
  CHECK(atlas_region_at(scene, scene.labels[0].anchor) == "liver");
}

TEST_CASE("segmentation in a scene: a grid elsewhere, and more regions than labels, are refused") {
  const TestSegmentation far = write_segmentation("far", {{{10, 10, 10}, 8.0f}}, {"liver"},
                                                  glm::vec3(400.0f, -40.0f, -40.0f));
  const std::string elsewhere = test::error_of(
      [&] { load_scene_json(test::write_file(far.folder / "far.json", scene_json(""))); });
  CHECK(elsewhere.find("labels.mha and " + (far.folder / "scan.mha").string() +
                       ": the segmentation's grid does not overlap the scan") != std::string::npos);

  // 4100 regions, one voxel each, on a 17^3 grid.
  const fs::path folder = test::fresh_folder("segmentation", "many");
  Volume map = grid({17, 17, 17});
  map.type = VoxelType::uint16;
  map.voxels.assign(map.voxel_count() * 2, std::byte{0});
  std::string table;
  for (uint16_t v = 1; v <= 4100; ++v) {
    std::memcpy(map.voxels.data() + 2 * size_t(v), &v, 2);
    table += std::to_string(v) + " 0 0 0 1 1 1 \"r" + std::to_string(v) + "\"\n";
  }
  write_metaimage(folder / "labels.mha", map);
  test::write_file(folder / "names.txt", "# ITK-SNAP Label Description File\n" + table);
  Scene scene;
  const std::string many = test::error_of([&] {
    add_segmentation(scene, {.file = folder / "labels.mha", .names = folder / "names.txt"}, {});
  });
  CHECK(many.find("4100 regions with voxels, but a scene holds at most 4096 labels: choose "
                  "regions with --regions NAME,... or the entry's \"regions\"") !=
        std::string::npos);
}

TEST_CASE("segmentation: a TotalSegmentator label map names its regions from its header") {
  // A NIfTI-1 label map 28 x 28 x 12 (0.8 x 0.8 x 2 mm), its label table in an extension of
  // code 0 as TotalSegmentator writes it: value 1 a C, value 2 a ball, value 3 named, absent.
  const Volume g = grid({28, 28, 12}, {0.8f, 0.8f, 2.0f});
  const std::vector<uint8_t> c = c_shape(g), b = ball(g, {25, 2, 6}, 2.0f);  // (apart)
  std::string voxels(g.voxel_count(), '\0');
  for (size_t i = 0; i < voxels.size(); ++i) voxels[i] = char(c[i] ? 1 : b[i] ? 2 : 0);
  const std::string xml =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?> <CaretExtension> <VolumeInformation "
      "Index=\"0\"> <LabelTable>\n"
      "<Label Key=\"1\" Red=\"1.0\" Green=\"0.5\" Blue=\"0.0\" Alpha=\"1\"><![CDATA[aorta]]>"
      "</Label>\n<Label Key=\"2\" Red=\"0.0\" Green=\"0.0\" Blue=\"1.0\" Alpha=\"1\">"
      "<![CDATA[kidney_left]]></Label>\n<Label Key=\"3\" Red=\"0\" Green=\"1\" Blue=\"0\" "
      "Alpha=\"1\"><![CDATA[spleen]]></Label>\n</LabelTable> </VolumeInformation>"
      "</CaretExtension>\n";
  const size_t esize = (8 + xml.size() + 15) / 16 * 16;
  std::string header(348, '\0');
  const auto put = [&](size_t at, auto value) {
    std::memcpy(header.data() + at, &value, sizeof value);
  };
  put(0, int32_t(348));
  const int16_t dim[8] = {3, 28, 28, 12, 1, 1, 1, 1};
  std::memcpy(header.data() + 40, dim, sizeof dim);
  put(70, int16_t(2));  // uint8
  put(72, int16_t(8));
  const float pixdim[8] = {1, 0.8f, 0.8f, 2.0f, 1, 1, 1, 1};
  std::memcpy(header.data() + 76, pixdim, sizeof pixdim);
  put(108, float(352 + esize));
  put(254, int16_t(1));  // sform: RAS x -> LPS -x
  const float srow[12] = {0.8f, 0, 0, 10, 0, 0.8f, 0, -20, 0, 0, 2, 5};
  std::memcpy(header.data() + 280, srow, sizeof srow);
  header.replace(344, 4, std::string("n+1\0", 4));
  std::string extension(8, '\0');
  const int32_t size_code[2] = {int32_t(esize), 0};
  std::memcpy(extension.data(), size_code, 8);
  extension += xml;
  extension.resize(esize, '\0');
  const std::filesystem::path folder = test::fresh_folder("segmentation", "totalsegmentator");
  const std::filesystem::path file = folder / "segmentations.nii.gz";
  gzFile out = gzopen(file.c_str(), "wb");
  REQUIRE(out != nullptr);
  const std::string bytes = header + std::string("\1\0\0\0", 4) + extension + voxels;
  CHECK(gzwrite(out, bytes.data(), unsigned(bytes.size())) == int(bytes.size()));
  CHECK(gzclose(out) == Z_OK);

  CHECK(is_segmentation(file));
  std::vector<std::string> warnings;
  const Segmentation s = load_segmentation(file, std::nullopt, {}, warnings);
  CHECK(warnings.empty());
  REQUIRE(s.regions.size() == 3);
  CHECK(s.regions[0].name == "aorta");
  CHECK(s.regions[1].name == "kidney_left");
  REQUIRE(s.regions[0].colour);
  CHECK(glm::length(*s.regions[0].colour - glm::vec3(1.0f, 0.5f, 0.0f)) < 1e-4f);
  const std::vector<RegionSummary> summaries = summarise_regions(s);
  CHECK(region_contains(s, s.regions[0], summaries[0].anchor));
  CHECK(region_contains(s, s.regions[1], summaries[1].anchor));
  CHECK(summaries[2].voxels == 0);
  // The ball's anchor is its centre, voxel (25, 2, 6): RAS (30, -18.4, 17), LPS x and y negated.
  CHECK(glm::length(summaries[1].anchor - glm::vec3(-30.0f, 18.4f, 17.0f)) < 1e-3f);
  // The C's centroid is outside it; its anchor is not.
  glm::dvec3 sum(0.0);
  size_t count = 0;
  for (size_t i = 0; i < c.size(); ++i)
    if (c[i]) {
      const size_t x = i % 28, y = i / 28 % 28, z = i / (28 * 28);
      sum += glm::dvec3(x, y, z), ++count;
    }
  const glm::vec3 centroid =
      glm::vec3(s.layers[0].index_to_world() * glm::vec4(glm::vec3(sum / double(count)), 1.0f));
  CHECK_FALSE(region_contains(s, s.regions[0], centroid));
  // A names table given with it replaces the header's names, matched by value.
  const std::filesystem::path table =
      test::write_file(folder / "names.txt",
                       "1 Aorta 255 0 0 255\n2 Left_kidney 0 0 255 255\n3 Spleen 0 255 0 255\n");
  const Segmentation renamed = load_segmentation(file, table, {}, warnings);
  CHECK(renamed.regions[1].name == "Left_kidney");
}
