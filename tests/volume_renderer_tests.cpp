// The renderer on lavapipe against its CPU reference (passes/volume_render_reference.h), which
// runs the same resolve code on ray-cast fragments and software-filtered samples.
//
// Tolerance: a channel may differ by 3/255 (hardware texture filtering uses fixed-point weights,
// rgba8 packing of mesh colours); 1% of pixels may differ more: pixels whose centre lies on a
// triangle edge, where rasterisation rules and ray-triangle tests can disagree (volume boxes are
// ray-box tests on both sides).
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>

#include "engine/core/png.h"
#include "engine/graph/graph_runner.h"
#include "engine/graph/headless_target.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/transfer_function_presets.h"
#include "gpu_fixture.h"
#include "passes/volume_render_reference.h"
#include "passes/volume_renderer.h"
#include "test_scenes.h"

namespace strata {
namespace {

using test::quad;

// A ball of radius `radius` voxels whose value falls off linearly from the centre.
Volume ball(glm::uvec3 dims, glm::vec3 origin, float radius) {
  Volume v;
  v.name = "ball";
  v.type = VoxelType::uint8;
  v.dims = dims;
  v.origin = origin;
  v.voxels.resize(v.voxel_count());
  const glm::vec3 centre = glm::vec3(dims - 1u) * 0.5f;
  for (uint32_t k = 0; k < dims.z; ++k) {
    for (uint32_t j = 0; j < dims.y; ++j) {
      for (uint32_t i = 0; i < dims.x; ++i) {
        const float r = glm::length(glm::vec3(i, j, k) - centre) / radius;
        v.voxels[(size_t(k) * dims.y + j) * dims.x + i] =
            std::byte(uint8_t(255.0f * glm::clamp(1.0f - r, 0.0f, 1.0f)));
      }
    }
  }
  v.value_range = {0.0f, 255.0f};
  return v;
}

TransferFunction ramp(glm::vec3 color) {
  TransferFunction tf;
  tf.name = "ramp";
  tf.stops = {{0.0f, glm::vec4(color, 0.0f)},
              {0.15f, glm::vec4(color, 0.0f)},
              {0.5f, glm::vec4(color, 0.2f)},
              {1.0f, glm::vec4(glm::vec3(1.0f), 0.6f)}};
  return tf;
}

void add_volume(Scene& scene, Volume v, TransferFunction tf) {
  v.transfer_function = int(scene.transfer_functions.size());
  scene.transfer_functions.push_back(std::move(tf));
  scene.volumes.push_back(std::move(v));
}

Camera camera_at(glm::vec3 eye, glm::vec3 target = glm::vec3(0.0f)) {
  return {glm::lookAt(eye, target, glm::vec3(0.0f, 1.0f, 0.0f)), 40.0f, 1.0f, 300.0f};
}

struct GpuResult {
  std::vector<uint8_t> final;
  std::vector<glm::vec4> layers;
  RenderStats stats;
};

GpuResult render_gpu(Context& ctx, const Scene& scene, const Camera& camera,
                     const RenderSettings& settings, graph::Extent size, uint32_t table = 0) {
  VolumeRenderer renderer(ctx, scene, settings);
  renderer.set_camera(camera);
  if (table) renderer.set_table_size(table);
  HeadlessTarget target(ctx);
  graph::Graph g;
  const auto out = renderer.add_to(g);
  target.add_output(g, out.final);
  graph::GraphRunner runner(ctx, std::move(g));
  runner.set_viewport(size);
  target.bind(runner);
  runner.run_now();
  GpuResult r;
  r.stats = renderer.collect(runner);
  r.final.assign(target.pixels().begin(), target.pixels().end());
  const std::vector<std::byte> bytes = runner.download_image(out.layers);
  const auto* half = reinterpret_cast<const uint16_t*>(bytes.data());
  for (size_t i = 0; i + 3 < bytes.size() / 2; i += 4) {
    r.layers.emplace_back(glm::unpackHalf1x16(half[i]), glm::unpackHalf1x16(half[i + 1]),
                          glm::unpackHalf1x16(half[i + 2]), glm::unpackHalf1x16(half[i + 3]));
  }
  return r;
}

std::vector<uint8_t> to_rgba8(const std::vector<glm::vec4>& colors) {
  std::vector<uint8_t> out;
  for (const glm::vec4& c : colors) {
    for (int ch = 0; ch < 4; ++ch)
      out.push_back(uint8_t(std::lround(glm::clamp(c[ch], 0.0f, 1.0f) * 255.0f)));
  }
  return out;
}

// Checks the tolerance above; on failure writes actual, expected and difference images.
void check_against_reference(Context& ctx, const Scene& scene, const Camera& camera,
                             const std::string& name, RenderSettings settings = {},
                             graph::Extent size = {96, 96}) {
  const GpuResult gpu = render_gpu(ctx, scene, camera, settings, size);
  CHECK(gpu.stats.overflow == 0);
  const RenderInputs inputs = prepare_render_inputs(scene, 2048);
  const ReferenceImage ref = render_reference(inputs, camera, settings, size);
  // Guards against comparing two empty pictures: a fifth of the view shows something.
  size_t covered = 0;
  for (const glm::vec4& c : ref.final)
    covered += glm::length(glm::vec3(c) - settings.background.color) > 0.02f;
  CHECK_MESSAGE(covered * 5 >= ref.final.size(),
                name << ": only " << covered << " pixels show anything");
  test::check_close(gpu.final, to_rgba8(ref.final), size, name);
  // The walk itself agrees: as many samples taken and shaded (2% for edge pixels).
  CHECK(double(gpu.stats.samples) == doctest::Approx(double(ref.samples)).epsilon(0.02));
  CHECK(double(gpu.stats.shaded) == doctest::Approx(double(ref.shaded)).epsilon(0.02));
  if (std::getenv("STRATA_KEEP_IMAGES")) {
    write_png(test::output_dir() + "/" + name + ".png", size.width, size.height, gpu.final);
  }
}

}  // namespace

TEST_SUITE("cpu") {
  // The resolve's workgroup rows: every row once, and each half of the dispatch order (what each of
  // lavapipe's two threads takes) reaches over the whole image.
  TEST_CASE("resolve_rows_are_a_permutation_spread_over_the_image") {
    for (uint32_t rows = 1; rows <= 130; ++rows) {
      std::vector<int> seen(rows, 0);
      for (uint32_t r = 0; r < rows; ++r) {
        const uint32_t row = gpu::resolve_group_row(r, rows);
        REQUIRE(row < rows);
        ++seen[row];
      }
      CHECK(std::count(seen.begin(), seen.end(), 1) == int(rows));
      if (rows < 2 * VR_ROW_INTERLEAVE) continue;
      for (uint32_t half = 0; half < 2; ++half) {
        uint32_t lowest = rows, highest = 0;
        for (uint32_t r = half * (rows / 2); r < (half + 1) * (rows / 2); ++r) {
          lowest = std::min(lowest, gpu::resolve_group_row(r, rows));
          highest = std::max(highest, gpu::resolve_group_row(r, rows));
        }
        CHECK(lowest < VR_ROW_INTERLEAVE);
        CHECK(highest >= rows - VR_ROW_INTERLEAVE);
      }
    }
  }

  // Every order takes every workgroup of the grid once.
  TEST_CASE("resolve_group_orders_take_every_workgroup_once") {
    for (uint32_t order : {VR_ORDER_ROWS, VR_ORDER_ROWS_INTERLEAVED}) {
      for (uint32_t gx = 1; gx <= 35; gx += 2) {
        for (uint32_t gy = 1; gy <= 20; gy += 3) {
          std::vector<int> seen(size_t(gx) * gy, 0);
          for (uint32_t y = 0; y < gy; ++y) {
            for (uint32_t x = 0; x < gx; ++x) {
              const glm::uvec2 g = gpu::resolve_group({x, y}, {gx, gy}, order);
              REQUIRE(g.x < gx);
              REQUIRE(g.y < gy);
              ++seen[size_t(g.y) * gx + g.x];
            }
          }
          CHECK(std::count(seen.begin(), seen.end(), 1) == int(gx * gy));
        }
      }
    }
  }
}

TEST_SUITE("gpu") {
  // The bundled head demo, 256x256, front camera, 4 layers, against tests/golden/head-front-256.png
  // (rendered by lavapipe). Tolerance as above; actual and difference images are written on
  // failure.
  TEST_CASE_FIXTURE(test::GpuTest, "head_demo_matches_its_golden_image") {
    const Scene scene = load_scene(STRATA_SOURCE_DIR "/assets/scenes/head.json");
    const graph::Extent size{256, 256};
    const GpuResult gpu = render_gpu(ctx, scene, camera_for(scene, "front"), {}, size);
    CHECK(gpu.stats.overflow == 0);
    const Rgba8Image golden = read_png(STRATA_SOURCE_DIR "/tests/golden/head-front-256.png");
    REQUIRE(golden.width == size.width);
    test::check_close(gpu.final, golden.pixels, size, "head-front-256");
  }

  TEST_CASE_FIXTURE(test::GpuTest,
                    "two_transparent_meshes_match_the_reference_in_both_draw_orders") {
    Scene scene;
    scene.meshes = {quad(0.0f, {0.9f, 0.2f, 0.1f, 0.5f}, 10.0f, {-3.0f, 0.0f}),
                    quad(8.0f, {0.1f, 0.3f, 0.9f, 0.5f}, 8.0f, {4.0f, 2.0f})};
    const Camera camera = camera_at({5.0f, 4.0f, 60.0f});
    check_against_reference(ctx, scene, camera, "meshes-ab");
    Scene reversed = scene;
    std::swap(reversed.meshes[0], reversed.meshes[1]);
    check_against_reference(ctx, reversed, camera, "meshes-ba");
    const GpuResult a = render_gpu(ctx, scene, camera, {}, {96, 96});
    const GpuResult b = render_gpu(ctx, reversed, camera, {}, {96, 96});
    CHECK(a.final == b.final);  // the HA-Buffer sorts: draw order cannot matter
  }

  // Interactive rendering: at divisor 1 the same picture as without it; at divisor 3 the cast
  // pixels are the picture of a third the size, upscaled as the reference does.
  TEST_CASE_FIXTURE(test::GpuTest, "interactive_rendering_casts_fewer_pixels_and_upscales_them") {
    Scene scene;
    add_volume(scene, ball({24, 24, 24}, glm::vec3(-12.0f), 11.0f), ramp({1.0f, 0.6f, 0.3f}));
    const Camera camera = camera_at({12.0f, 9.0f, 32.0f});
    const graph::Extent size{70, 52};
    RenderSettings settings;
    settings.layer_count = 2;
    const GpuResult plain = render_gpu(ctx, scene, camera, settings, size);
    settings.interactive = true;
    const GpuResult full = render_gpu(ctx, scene, camera, settings, size);
    CHECK(full.final == plain.final);
    CHECK(full.layers == plain.layers);
    settings.divisor = 3;
    const GpuResult upscaled = render_gpu(ctx, scene, camera, settings, size);
    settings.interactive = false;
    const GpuResult small = render_gpu(ctx, scene, camera, settings, cast_extent(size, 3));
    REQUIRE(small.layers.size() == size_t(24) * 18 * 2);
    const std::vector<glm::vec4> expected = upscale_reference(small.layers, size, 3, 2);
    REQUIRE(upscaled.layers.size() == expected.size());
    float worst = 0.0f;
    for (size_t i = 0; i < expected.size(); ++i) {
      worst = std::max(worst, glm::length(upscaled.layers[i] - expected[i]));
    }
    CHECK(worst < 4e-3f);                  // (half floats)
    CHECK(upscaled.final != plain.final);  // fewer rays: not the same picture
  }

  // Transfer functions in the volume's values: the same CT with two value ranges (one voxel of
  // padding at -3000 HU, as scanners write outside the field of view) looks the same through a
  // window or a function in HU, and not through one written for 0..1 of the first one's range.
  TEST_CASE_FIXTURE(test::GpuTest, "windows_and_hounsfield_functions_look_alike_on_two_ranges") {
    std::vector<std::string> warnings;
    const Volume a = load_volume(
        std::filesystem::path(STRATA_SOURCE_DIR) / "assets/cache/dicom/CT5N", {}, warnings);
    REQUIRE(a.type == VoxelType::int16);
    // The padding replaces the lowest voxel (air already, below every window here).
    size_t lowest = 0;
    for (size_t i = 0; i < a.voxel_count(); ++i) {
      int16_t v, w;
      std::memcpy(&v, a.voxels.data() + 2 * i, 2);
      std::memcpy(&w, a.voxels.data() + 2 * lowest, 2);
      if (v < w) lowest = i;
    }
    Volume b = a;
    const int16_t padding = -3000;
    std::memcpy(b.voxels.data() + 2 * lowest, &padding, 2);
    b.value_range.x = -3000.0f;
    TransferFunction hu;
    hu.name = "bone and tissue";
    hu.units = "HU";
    hu.stops = {{-500.0f, glm::vec4(0.0f)},
                {-50.0f, glm::vec4(0.9f, 0.6f, 0.5f, 0.3f)},
                {1300.0f, glm::vec4(1.0f)}};
    Scene first;
    first.volumes.push_back(a);
    complete_scene(first);
    const Camera camera = first.camera;  // (the same for both: the same box)
    const graph::Extent size{48, 48};
    const auto picture = [&](const Volume& v, const TransferFunction* tf,
                             std::optional<glm::vec2> window) {
      Scene scene;
      scene.volumes.push_back(v);
      if (tf) {
        scene.transfer_functions.push_back(*tf);
        scene.volumes[0].transfer_function = 0;
      }
      complete_scene(scene, "", window);
      return render_gpu(ctx, scene, camera, {}, size).final;
    };
    // The share of pixels that differ by more than 3 of 255 in a channel.
    const auto differing = [&](const std::vector<uint8_t>& x, const std::vector<uint8_t>& y) {
      size_t count = 0, shown = 0;
      for (size_t p = 0; p < x.size(); p += 4) {
        bool differs = false;
        for (size_t c = 0; c < 4; ++c)
          differs = differs || std::abs(int(x[p + c]) - int(y[p + c])) > 3;
        count += differs ? 1 : 0;
        shown += x[p + 3] > 0 ? 1 : 0;
      }
      CHECK(shown > x.size() / 4 / 4);  // (something to compare)
      return double(count) / double(x.size() / 4);
    };
    const double window = differing(picture(a, nullptr, glm::vec2(400.0f, 1800.0f)),
                                    picture(b, nullptr, glm::vec2(400.0f, 1800.0f)));
    const double in_hu = differing(picture(a, &hu, {}), picture(b, &hu, {}));
    const TransferFunction range = in_value_range(hu, a);  // 0..1 of a's range, as files were
    const double in_range = differing(picture(a, &range, {}), picture(b, &range, {}));
    MESSAGE("pixels differing: window ", window, ", HU ", in_hu, ", 0..1 of the range ", in_range);
    CHECK(window <= 0.02);
    CHECK(in_hu <= 0.02);
    CHECK(in_range >= 0.2);
  }

  TEST_CASE_FIXTURE(test::GpuTest, "one_volume_matches_the_reference") {
    Scene scene;
    add_volume(scene, ball({24, 24, 24}, glm::vec3(-12.0f), 11.0f), ramp({1.0f, 0.6f, 0.3f}));
    check_against_reference(ctx, scene, camera_at({12.0f, 9.0f, 32.0f}), "one-volume");
  }

  // With no background (render --no-labels --background transparent) the final image keeps its
  // alpha, straight, as the reference's: nothing around the ball, partly there at its soft edge.
  TEST_CASE_FIXTURE(test::GpuTest, "a_transparent_final_image_is_straight_alpha_as_the_reference") {
    Scene scene;
    add_volume(scene, ball({24, 24, 24}, glm::vec3(-12.0f), 11.0f), ramp({1.0f, 0.6f, 0.3f}));
    RenderSettings settings;
    settings.background.transparent = true;
    const Camera camera = camera_at({12.0f, 9.0f, 32.0f});
    const graph::Extent size{96, 96};
    const GpuResult gpu = render_gpu(ctx, scene, camera, settings, size);
    const ReferenceImage ref =
        render_reference(prepare_render_inputs(scene, 2048), camera, settings, size);
    test::check_close(gpu.final, to_rgba8(ref.final), size, "one-volume-transparent", 3, 4);
    size_t clear = 0, partial = 0;
    for (size_t p = 0; p < gpu.final.size() / 4; ++p) {
      clear += gpu.final[4 * p + 3] == 0;
      partial += gpu.final[4 * p + 3] > 0 && gpu.final[4 * p + 3] < 255;
    }
    CHECK(clear > 0);
    CHECK(partial > 0);
  }

  // A scene of one volume and no meshes gets the resolve specialised for it (which the test above
  // checks against the reference); a mesh or a second volume, the general one.
  TEST_CASE_FIXTURE(test::GpuTest, "one_volume_without_meshes_takes_the_specialised_resolve") {
    const auto resolve_of = [&](const Scene& scene) {
      return VolumeRenderer(ctx, scene, {}).pipeline_statistics().at(0).name;
    };
    Scene scene;
    add_volume(scene, ball({24, 24, 24}, glm::vec3(-12.0f), 11.0f), ramp({1.0f, 0.6f, 0.3f}));
    CHECK(resolve_of(scene) == "habuffer_resolve_one_volume.comp");
    Scene with_mesh = scene;
    with_mesh.meshes = {quad(0.0f, {0.2f, 0.9f, 0.3f, 0.7f}, 6.0f)};
    CHECK(resolve_of(with_mesh) == "habuffer_resolve.comp");
    add_volume(scene, ball({20, 28, 20}, glm::vec3(-4.0f, -14.0f, -8.0f), 9.0f),
               ramp({0.2f, 0.5f, 1.0f}));
    CHECK(resolve_of(scene) == "habuffer_resolve.comp");
  }

  // Volume boxes are ray-box tests in the resolve: a scene of volumes only rasterises nothing and
  // needs no HA-Buffer slots; a mesh brings the table back.
  TEST_CASE_FIXTURE(test::GpuTest, "volume_boxes_take_no_habuffer_slots") {
    Scene scene;
    add_volume(scene, ball({24, 24, 24}, glm::vec3(-12.0f), 11.0f), ramp({1.0f, 0.6f, 0.3f}));
    const Camera camera = camera_at({12.0f, 9.0f, 32.0f});
    const GpuResult volumes_only = render_gpu(ctx, scene, camera, {}, {32, 32});
    CHECK(volumes_only.stats.table_size == 1);
    CHECK(volumes_only.stats.fragments == 0);
    CHECK(volumes_only.stats.samples > 0);
    scene.meshes = {quad(0.0f, {0.2f, 0.9f, 0.3f, 0.7f}, 6.0f)};
    const GpuResult with_mesh = render_gpu(ctx, scene, camera, {}, {32, 32});
    CHECK(with_mesh.stats.table_size > 32 * 32);
    CHECK(with_mesh.stats.fragments > 0);
  }

  // Cut-aways: a crop box and a plane, GPU = reference; where the front volume is cut away the
  // picture shows what lies behind it, exactly as without it.
  TEST_CASE_FIXTURE(test::GpuTest, "cut_away_volumes_match_the_reference_and_show_what_is_behind") {
    Scene cut;
    add_volume(cut, ball({24, 24, 24}, glm::vec3(-12.0f), 11.0f), ramp({1.0f, 0.6f, 0.3f}));
    cut.volumes[0].cut = crop_planes(glm::vec3(-20.0f, -6.0f, -20.0f), glm::vec3(20.0f));
    cut.volumes[0].cut.push_back(clip_plane(glm::vec3(0.0f), glm::vec3(-1.0f, 0.0f, 1.0f)));
    check_against_reference(ctx, cut, camera_at({12.0f, 9.0f, 32.0f}), "cut-away");

    Scene behind;  // a ball 20 behind another, seen through it
    add_volume(behind, ball({24, 24, 24}, glm::vec3(-12.0f, -12.0f, -32.0f), 11.0f),
               ramp({0.3f, 0.6f, 1.0f}));
    Scene both = behind;
    add_volume(both, ball({24, 24, 24}, glm::vec3(-12.0f, -12.0f, 8.0f), 11.0f),
               ramp({1.0f, 0.6f, 0.3f}));
    const Camera camera = camera_at({0.0f, 0.0f, 90.0f});
    const graph::Extent size{48, 48};
    const std::vector<uint8_t> alone = render_gpu(ctx, behind, camera, {}, size).final;
    CHECK(render_gpu(ctx, both, camera, {}, size).final != alone);
    both.volumes[1].cut = {clip_plane(glm::vec3(0.0f, 0.0f, 2.0f), glm::vec3(0.0f, 0.0f, -1.0f))};
    CHECK(render_gpu(ctx, both, camera, {}, size).final == alone);
    // (a label anchored in the cut-away ball is cut away with it; one in the kept ball is not)
    // (and one in no volume is not)
    CHECK(anchors_cut_away(both, {glm::vec3(0.0f, 0.0f, 20.0f), glm::vec3(0.0f, 0.0f, -20.0f),
                                  glm::vec3(0.0f, 0.0f, 60.0f)}) ==
          std::vector<bool>{true, false, false});
  }

  TEST_CASE_FIXTURE(test::GpuTest, "two_overlapping_volumes_match_the_reference") {
    Scene scene;
    add_volume(scene, ball({24, 24, 24}, glm::vec3(-16.0f, -12.0f, -12.0f), 11.0f),
               ramp({1.0f, 0.4f, 0.2f}));
    add_volume(scene, ball({20, 28, 20}, glm::vec3(-4.0f, -14.0f, -8.0f), 9.0f),
               ramp({0.2f, 0.5f, 1.0f}));
    check_against_reference(ctx, scene, camera_at({6.0f, 6.0f, 38.0f}), "two-volumes");
  }

  TEST_CASE_FIXTURE(test::GpuTest, "a_mesh_inside_a_volume_matches_the_reference") {
    Scene scene;
    add_volume(scene, ball({24, 24, 24}, glm::vec3(-12.0f), 11.0f), ramp({1.0f, 0.8f, 0.6f}));
    scene.meshes = {quad(0.0f, {0.2f, 0.9f, 0.3f, 0.7f}, 6.0f)};
    check_against_reference(ctx, scene, camera_at({5.0f, 4.0f, 32.0f}), "mesh-in-volume");
  }

  TEST_CASE_FIXTURE(test::GpuTest, "a_camera_inside_a_volume_starts_its_rays_at_the_near_plane") {
    Scene scene;
    add_volume(scene, ball({32, 32, 32}, glm::vec3(-16.0f), 15.0f), ramp({0.9f, 0.9f, 0.5f}));
    const Camera camera = camera_at({2.0f, 1.0f, 9.0f});
    check_against_reference(ctx, scene, camera, "camera-inside");
    const GpuResult gpu = render_gpu(ctx, scene, camera, {}, {96, 96});
    CHECK(gpu.stats.samples > 0);  // with no front faces in view, only the near-plane start sees it
  }

  TEST_CASE_FIXTURE(test::GpuTest, "layer_images_composite_to_the_final_image") {
    Scene scene;
    add_volume(scene, ball({24, 24, 24}, glm::vec3(-12.0f), 11.0f), ramp({1.0f, 0.6f, 0.3f}));
    scene.meshes = {quad(-4.0f, {0.2f, 0.9f, 0.3f, 0.6f}, 5.0f),
                    quad(6.0f, {0.9f, 0.2f, 0.6f, 0.4f}, 4.0f)};
    RenderSettings settings;
    settings.layer_count = 4;
    const graph::Extent size{80, 80};
    const GpuResult gpu = render_gpu(ctx, scene, camera_at({0.0f, 0.0f, 50.0f}), settings, size);
    std::vector<glm::vec4> composite(size_t(size.width) * size.height);
    for (size_t p = 0; p < composite.size(); ++p) {
      glm::vec4 all(0.0f);
      for (uint32_t l = 0; l < settings.layer_count; ++l)
        all = all + (1.0f - all.a) * gpu.layers[l * composite.size() + p];
      composite[p] = glm::vec4(glm::vec3(all) + (1.0f - all.a) * settings.background.color, 1.0f);
    }
    size_t non_empty_layers = 0;
    for (uint32_t l = 0; l < settings.layer_count; ++l) {
      float alpha = 0.0f;
      for (size_t p = 0; p < composite.size(); ++p) alpha += gpu.layers[l * composite.size() + p].a;
      non_empty_layers += alpha > 1.0f;
    }
    CHECK(non_empty_layers >= 3);
    test::check_close(gpu.final, to_rgba8(composite), size, "layers-composite", 2);
  }

  TEST_CASE_FIXTURE(test::GpuTest, "empty_space_skipping_changes_nothing_but_the_sample_count") {
    Scene scene;
    add_volume(scene, ball({40, 40, 40}, glm::vec3(-20.0f), 12.0f), ramp({1.0f, 0.6f, 0.3f}));
    RenderSettings on, off;
    off.skip_empty = false;
    const Camera camera = camera_at({15.0f, 10.0f, 70.0f});
    const GpuResult a = render_gpu(ctx, scene, camera, on, {64, 64});
    const GpuResult b = render_gpu(ctx, scene, camera, off, {64, 64});
    test::check_close(a.final, b.final, {64, 64}, "skipping", 1);
    CHECK(a.stats.samples < b.stats.samples);
  }

  TEST_CASE_FIXTURE(test::GpuTest,
                    "habuffer_overflow_is_counted_and_the_picture_is_right_by_the_second_frame") {
    Scene scene;
    add_volume(scene, ball({24, 24, 24}, glm::vec3(-12.0f), 11.0f), ramp({1.0f, 0.6f, 0.3f}));
    scene.meshes = {quad(0.0f, {0.2f, 0.9f, 0.3f, 0.7f}, 6.0f)};
    const Camera camera = camera_at({8.0f, 6.0f, 60.0f});
    const graph::Extent size{64, 64};
    VolumeRenderer renderer(ctx, scene, {});
    renderer.set_camera(camera);
    renderer.set_table_size(32);  // far fewer slots than the quad's fragments
    HeadlessTarget target(ctx);
    graph::Graph g;
    target.add_output(g, renderer.add_to(g).final);
    graph::GraphRunner runner(ctx, std::move(g));
    runner.set_viewport(size);
    target.bind(runner);
    const RenderInputs inputs = prepare_render_inputs(scene, 2048);
    const std::vector<uint8_t> expected =
        to_rgba8(render_reference(inputs, camera, {}, size).final);

    std::vector<RenderStats> frames;
    for (int frame = 0; frame < 2; ++frame) {
      runner.run_now();
      frames.push_back(renderer.collect(runner));
    }
    CHECK(frames[0].overflow > 0);
    CHECK(frames[0].table_size == 32);
    CHECK(frames[1].overflow == 0);
    CHECK(frames[1].table_size > 32);
    test::check_close(std::vector<uint8_t>(target.pixels().begin(), target.pixels().end()),
                      expected, size, "overflow-second-frame");
  }
}

}  // namespace strata
