// Picking (passes/picking.h) on lavapipe against its CPU reference: the renderer's own walk
// records where each pixel first became opaque enough; the pick turns that into a world point.
#include <doctest/doctest.h>

#include <algorithm>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/scene/io/scene_loader.h"
#include "gpu_fixture.h"
#include "passes/picking.h"
#include "passes/volume_render_reference.h"
#include "passes/volume_renderer.h"
#include "test_scenes.h"

namespace strata {
namespace {

struct Picked {
  std::vector<PickHit> gpu, cpu;
};

// The scene rendered at `size` on the GPU with `pixels` picked in the same frame, and the CPU
// reference's picks of the same pixels.
Picked pick_both(Context& ctx, const Scene& scene, const Camera& camera, graph::Extent size,
                 const std::vector<glm::vec2>& pixels) {
  Picked r;
  r.gpu = pick_scene(ctx, scene, camera, {}, size, pixels).hits;
  const RenderInputs inputs = prepare_render_inputs(scene, 2048);
  const RenderSettings settings;
  const ReferenceImage image = render_reference(inputs, camera, settings, size);
  r.cpu = pick_reference(image, frame_data(inputs, camera, settings, size, 1), pixels);
  return r;
}

}  // namespace

TEST_SUITE("gpu") {
  // head.json from four views at 96²: 50 pixels each (seeded, spread over the image). Every GPU
  // pick equals the reference's within half a voxel (one ray step of 0.5 mm where the two walks
  // cross depth_alpha a sample apart); the background picks nothing, on both; and a pick lies on
  // its pixel's ray, inside the head's bounds.
  TEST_CASE_FIXTURE(test::GpuTest,
                    "picks_on_the_head_match_the_cpu_reference_within_half_a_voxel") {
    const Scene scene = load_scene(STRATA_SOURCE_DIR "/assets/scenes/head.json");
    const graph::Extent size{96, 96};
    const float half_voxel =
        0.5f * std::min({scene.volumes[0].spacing.x, scene.volumes[0].spacing.y,
                         scene.volumes[0].spacing.z});
    uint32_t seed = 2024u;
    size_t hits = 0, misses = 0;
    for (const char* view : {"front", "left", "top", "oblique"}) {
      CAPTURE(view);
      std::vector<glm::vec2> pixels;
      for (int i = 0; i < 50; ++i) {
        seed = seed * 1664525u + 1013904223u;
        const float x = float(seed >> 8 & 0xFFFFu) / 65536.0f * float(size.width);
        seed = seed * 1664525u + 1013904223u;
        const float y = float(seed >> 8 & 0xFFFFu) / 65536.0f * float(size.height);
        pixels.emplace_back(x, y);
      }
      const Picked p = pick_both(ctx, scene, camera_for(scene, view), size, pixels);
      REQUIRE(p.gpu.size() == pixels.size());
      REQUIRE(p.cpu.size() == pixels.size());
      for (size_t i = 0; i < pixels.size(); ++i) {
        CAPTURE(pixels[i]);
        CHECK(p.gpu[i].hit == p.cpu[i].hit);
        if (!p.gpu[i].hit || !p.cpu[i].hit) {
          misses += !p.gpu[i].hit;
          continue;
        }
        ++hits;
        CHECK(glm::distance(p.gpu[i].point, p.cpu[i].point) <= half_voxel);
      }
    }
    MESSAGE(hits << " picks on the head, " << misses << " on the background");
    CHECK(hits >= 60);
    CHECK(misses >= 10);
  }

  // A mesh: an opaque enough quad (alpha 0.7) picks on its plane, a faint one (0.3) alone does
  // not, and where the faint one lies in front of the opaque one the pick is the one behind
  // (their alphas together first pass 0.5 there).
  TEST_CASE_FIXTURE(test::GpuTest,
                    "picks_on_meshes_find_the_first_fragment_that_is_opaque_enough") {
    Scene scene;
    scene.meshes = {test::quad(0.0f, {0.9f, 0.2f, 0.1f, 0.7f}, 10.0f, {-6.0f, 0.0f}),
                    test::quad(6.0f, {0.1f, 0.3f, 0.9f, 0.3f}, 6.0f, {6.0f, 0.0f})};
    Camera camera;
    camera.view = glm::lookAt(glm::vec3(0.0f, 0.0f, 60.0f), glm::vec3(0.0f), glm::vec3(0, 1, 0));
    const graph::Extent size{64, 64};
    // (left of the centre: the opaque quad alone; right: the faint one over the opaque one;
    // far right: the faint one alone; a corner: nothing)
    const std::vector<glm::vec2> pixels{
        {20.5f, 32.5f}, {35.5f, 32.5f}, {45.5f, 32.5f}, {1.5f, 1.5f}};
    const Picked p = pick_both(ctx, scene, camera, size, pixels);
    for (size_t i = 0; i < pixels.size(); ++i) {
      CAPTURE(i);
      REQUIRE(p.gpu[i].hit == p.cpu[i].hit);
      if (p.gpu[i].hit) CHECK(glm::distance(p.gpu[i].point, p.cpu[i].point) <= 1e-3f);
    }
    CHECK(p.gpu[0].hit);
    CHECK(p.gpu[0].point.z == doctest::Approx(0.0f).epsilon(1e-3));
    CHECK(p.gpu[1].hit);
    CHECK(p.gpu[1].point.z == doctest::Approx(0.0f).epsilon(1e-3));
    CHECK_FALSE(p.gpu[2].hit);
    CHECK_FALSE(p.gpu[3].hit);
  }
}

}  // namespace strata
