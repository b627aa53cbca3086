// Picking (passes/picking.h) on lavapipe against its CPU reference: the pick walks each asked
// pixel's ray again as the picture is drawn (the resolve's walk, through the labels' lenses) and
// turns the depth where it first became opaque enough into a world point.
#include <doctest/doctest.h>

#include <algorithm>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/scene/io/scene_loader.h"
#include "frame/labelled_render.h"
#include "gpu_fixture.h"
#include "passes/picking.h"
#include "passes/volume_render_reference.h"
#include "passes/volume_renderer.h"
#include "shared/volume_shading.h"
#include "test_scenes.h"

namespace strata {
namespace {

struct Picked {
  std::vector<PickHit> gpu, cpu;
};

// The scene rendered at `size` on the GPU with `pixels` picked in the same frame, and the CPU
// reference's picks of the same pixels (the frame cast at cast_extent(size, divisor) when the
// settings are interactive).
Picked pick_both(Context& ctx, const Scene& scene, const Camera& camera, graph::Extent size,
                 const std::vector<glm::vec2>& pixels, const RenderSettings& settings = {},
                 const PickLabels& labels = {}) {
  Picked r;
  r.gpu = pick_scene(ctx, scene, camera, settings, size, pixels, 1, labels).hits;
  const RenderInputs inputs = prepare_render_inputs(scene, 2048);
  const graph::Extent cast = cast_extent(size, settings.interactive ? settings.divisor : 1u);
  r.cpu =
      pick_reference(inputs, frame_data(inputs, camera, settings, cast, 1), size, pixels, labels);
  return r;
}

// Half a voxel, and 1e-3 mm for float arithmetic: a GPU's ray math (fused multiply-adds, its own
// division) lands a few ulps of a 100 mm coordinate away from the reference's.
float half_voxel(const Scene& scene) {
  const glm::vec3 s = scene.volumes[0].spacing;
  return 0.5f * std::min({s.x, s.y, s.z}) + 1e-3f;
}

// Every GPU pick hits where the reference's does, within `tolerance` of it.
void check_matches(const Picked& p, const std::vector<glm::vec2>& pixels, float tolerance) {
  REQUIRE(p.gpu.size() == pixels.size());
  REQUIRE(p.cpu.size() == pixels.size());
  for (size_t i = 0; i < pixels.size(); ++i) {
    CAPTURE(pixels[i]);
    CHECK(p.gpu[i].hit == p.cpu[i].hit);
    if (p.gpu[i].hit && p.cpu[i].hit)
      CHECK(glm::distance(p.gpu[i].point, p.cpu[i].point) <= tolerance);
  }
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
    const float half = half_voxel(scene);
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
        CHECK(glm::distance(p.gpu[i].point, p.cpu[i].point) <= half);
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

  // Interactive rendering casts every second pixel each way: a pick walks the cast pixel that
  // holds the asked one, on the GPU as on the reference (within half a voxel), and an asked pixel
  // and its neighbour in the same cast pixel pick the same point.
  TEST_CASE_FIXTURE(test::GpuTest, "picks_of_a_frame_cast_at_half_resolution_walk_the_cast_pixel") {
    const Scene scene = load_scene(STRATA_SOURCE_DIR "/assets/scenes/head.json");
    RenderSettings settings;
    settings.interactive = true;
    settings.divisor = 2;
    const graph::Extent size{96, 96};
    std::vector<glm::vec2> pixels;
    for (float y = 8.5f; y < 96.0f; y += 16.0f) {
      for (float x = 8.5f; x < 96.0f; x += 16.0f) pixels.emplace_back(x, y);
    }
    pixels.emplace_back(48.5f, 40.5f);  // (the same cast pixel: 24, 20)
    pixels.emplace_back(49.5f, 41.5f);
    const Picked p = pick_both(ctx, scene, camera_for(scene, "front"), size, pixels, settings);
    check_matches(p, pixels, half_voxel(scene));
    const size_t hits =
        size_t(std::count_if(p.gpu.begin(), p.gpu.end(), [](const PickHit& h) { return h.hit; }));
    MESSAGE(hits << " of " << pixels.size() << " picks on the head at half resolution");
    CHECK(hits >= 10);
    REQUIRE(p.gpu[pixels.size() - 1].hit);
    CHECK(p.gpu[pixels.size() - 1].point == p.gpu[pixels.size() - 2].point);
  }

  // head.json from the front at 128² with its labels placed and ghosting on (the defaults): at and
  // around the anchor of each shown rear label whose lens opens what lies in front, the pick goes
  // through the lens: deeper than the same pixel's pick without ghosting, on the label's layer or
  // behind it and nearer the anchor's own depth; far from every lens the picks with and without
  // ghosting are the same points; and every GPU pick equals the CPU reference's within half a
  // voxel, with ghosting and without.
  TEST_CASE_FIXTURE(test::GpuTest, "a_pick_through_a_ghosted_lens_follows_what_is_drawn") {
    const Scene scene = load_scene(STRATA_SOURCE_DIR "/assets/scenes/head.json");
    const graph::Extent size{128, 128};
    LabellingSettings settings;
    REQUIRE(settings.ghost.strength > 0.0f);
    LabelledRenderer r(ctx, scene, camera_for(scene, "front"), size, settings);
    r.run();
    const std::vector<gpu::LabelGpu> labels = r.labels();
    const auto drawn_last = r.drawn();
    const std::vector<gpu::PlacementGpu> drawn(drawn_last.begin(), drawn_last.end());
    REQUIRE(drawn.size() >= labels.size());
    // (as LabelledRenderer hands them to labels.ghost: shares of the shorter side in pixels)
    const float side = float(std::min(size.width, size.height));
    const GhostSettings ghost{settings.ghost.strength, settings.ghost.radius * side,
                              settings.ghost.leader * side};
    const RenderSettings render = r.renderer().settings();
    const Camera camera = r.camera();
    gpu::FrameGpu frame = frame_data(r.renderer().inputs(), camera, render, size, 1);
    const gpu::GhostParams params = ghost_params(ghost, size, frame.layer_count, 0u);

    std::vector<size_t> rear;  // shown rear labels, fully drawn, anchors inside the image
    for (size_t i = 0; i < labels.size(); ++i) {
      const gpu::LabelGpu& l = labels[i];
      const bool inside = l.anchor.x >= 4.0f && l.anchor.y >= 4.0f &&
                          l.anchor.x <= float(size.width) - 4.0f &&
                          l.anchor.y <= float(size.height) - 4.0f;
      if ((l.flags & LABEL_ENABLED) != 0u && (l.flags & LABEL_INTERNAL) == 0u && l.layer > 0u &&
          drawn[i].shown == PLACEMENT_SHOWN && drawn[i].opacity == 1.0f && inside) {
        rear.push_back(i);
      }
    }
    REQUIRE(rear.size() >= 2);
    // Five pixels per rear label, all within a third of the radius (the lens fully open), then
    // pixels on a grid that no lens reaches (with a pixel to spare).
    std::vector<glm::vec2> pixels;
    const glm::vec2 around[] = {
        {0.0f, 0.0f}, {2.0f, 0.0f}, {-2.0f, 0.0f}, {0.0f, 2.0f}, {0.0f, -2.0f}};
    for (size_t i : rear) {
      for (glm::vec2 d : around) pixels.push_back(labels[i].anchor + d);
    }
    const size_t lens_pixels = pixels.size();
    REQUIRE(2.0f < ghost.radius / 3.0f);
    for (float y = 4.5f; y < float(size.height); y += 8.0f) {
      for (float x = 4.5f; x < float(size.width); x += 8.0f) {
        const glm::vec2 p(x, y);
        bool far = true;
        for (size_t i = 0; i < labels.size() && far; ++i) {
          far = glm::distance(p, labels[i].anchor) > ghost.radius + 1.0f &&
                gpu::ghost_opening(labels[i], drawn[i], p, params) == glm::vec2(0.0f);
        }
        if (far && pixels.size() < PICK_MAX) pixels.push_back(p);
      }
    }
    REQUIRE(pixels.size() - lens_pixels >= 20);

    const PickLabels ghosted{labels, drawn, ghost};
    const PickLabels plain{labels, drawn, {0.0f, ghost.radius, ghost.leader_radius}};
    const Picked with = pick_both(ctx, scene, camera, size, pixels, render, ghosted);
    const Picked without = pick_both(ctx, scene, camera, size, pixels, render, plain);
    const float half = half_voxel(scene);
    check_matches(with, pixels, half);
    check_matches(without, pixels, half);

    // The pick's eye depth (0: nothing picked), and the alpha the drawn (ghosted) layers in front
    // of layer `layer` composite to at pixel p of the labelled frame.
    const auto depth = [&frame](const PickHit& h) {
      return h.hit ? -(frame.world_to_view * glm::vec4(h.point, 1.0f)).z : 0.0f;
    };
    const std::vector<glm::vec4> layers = r.download_layers();
    const size_t image_pixels = size_t{size.width} * size.height;
    REQUIRE(layers.size() == image_pixels * frame.layer_count);
    const auto drawn_in_front = [&](glm::vec2 p, uint32_t layer) {
      const glm::ivec2 t = gpu::pick_texel(p, size.width, size.height);
      float alpha = 0.0f;
      for (uint32_t k = 0; k < layer; ++k) {
        const float a = layers[k * image_pixels + size_t(t.y) * size.width + size_t(t.x)].a;
        alpha += (1.0f - alpha) * a;
      }
      return alpha;
    };
    size_t opened = 0, deeper = 0, nearer = 0;
    for (size_t k = 0; k < lens_pixels; ++k) {
      const gpu::LabelGpu& l = labels[rear[k / 5]];
      CAPTURE(pixels[k]);
      CAPTURE(l.layer);
      const float front_of_layer = gpu::split_depth(frame.splits, l.layer - 1u);
      const float before = depth(without.gpu[k]), after = depth(with.gpu[k]);
      const float front_alpha = drawn_in_front(pixels[k], l.layer);
      CAPTURE(before);
      CAPTURE(after);
      CAPTURE(front_alpha);
      // A lens never brings a pick nearer.
      if (without.gpu[k].hit) CHECK((!with.gpu[k].hit || after >= before));
      // Where the unghosted pick lies in front of the label's layer but the drawn layers there
      // are too clear to be picked (their alpha below depth_alpha with a margin), the pick goes
      // through the lens to the label's layer or behind it.
      if (!without.gpu[k].hit || before >= front_of_layer || front_alpha > 0.45f) continue;
      ++opened;
      if (!with.gpu[k].hit) continue;  // (through to the background: nothing behind to pick)
      CHECK(after >= front_of_layer);
      deeper += after > before + half ? 1 : 0;
      nearer += std::abs(after - l.anchor_depth) < std::abs(before - l.anchor_depth) ? 1 : 0;
    }
    size_t same = 0;
    for (size_t k = lens_pixels; k < pixels.size(); ++k) {
      CAPTURE(pixels[k]);
      CHECK(with.gpu[k].hit == without.gpu[k].hit);
      CHECK(with.gpu[k].point == without.gpu[k].point);
      same += with.gpu[k].hit && with.gpu[k].point == without.gpu[k].point ? 1 : 0;
    }
    MESSAGE(rear.size() << " shown rear labels; of " << opened
                        << " lens picks in front of the label's layer, " << deeper
                        << " went deeper and " << nearer << " nearer the anchor's depth; " << same
                        << " of " << pixels.size() - lens_pixels
                        << " picks far from every lens on the head, unchanged");
    CHECK(opened >= 5);
    CHECK(deeper >= opened * 3 / 4);
    CHECK(nearer >= opened * 3 / 4);
    CHECK(same >= 10);
  }
}

}  // namespace strata
