// The viewer's debug views (passes/debug_view.h) on lavapipe against their CPU reference, which
// runs the shader's own per-pixel code: first on hand-made buffers, then on a frame the renderer
// and the placement produced.
//
// Tolerance: 1/255 per channel (the GPU rounds to 8 bits its own way and may contract
// multiply-adds in the colour ramps); constraint bits and fragment counts exactly.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>

#include "engine/core/png.h"
#include "engine/gpu/resources.h"
#include "engine/graph/graph_runner.h"
#include "gpu_fixture.h"
#include "passes/debug_view.h"
#include "passes/placement.h"
#include "passes/volume_renderer.h"
#include "test_scenes.h"

namespace strata {
namespace {

using test::quad;

template <typename T>
std::vector<T> as(const std::vector<std::byte>& bytes) {
  std::vector<T> out(bytes.size() / sizeof(T));
  std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
  return out;
}

std::vector<glm::vec4> from_halves(const std::vector<std::byte>& bytes) {
  std::vector<glm::vec4> out;
  for (const uint64_t h : as<uint64_t>(bytes)) out.push_back(glm::unpackHalf4x16(h));
  return out;
}

gpu::LabelGpu label(glm::vec2 anchor, glm::vec2 size, uint32_t flags = LABEL_ENABLED) {
  return test::label_at(anchor, size, 0, flags);
}

// Inserts a fragment as the HA-Buffer build does: the first free slot of the pixel's probes.
void insert_fragment(std::vector<uint64_t>& keys, uint32_t pixel, float depth) {
  const auto table = static_cast<uint32_t>(keys.size());
  for (uint32_t age = 1; age <= VR_MAX_AGE; ++age) {
    uint64_t& key = keys[gpu::debug_habuffer_slot(pixel, age, table)];
    if (key != 0) continue;
    uint32_t depth_bits;
    std::memcpy(&depth_bits, &depth, 4);
    key = (uint64_t{depth_bits} << 32) | (uint64_t{age} << 24) | pixel;
    return;
  }
  FAIL("no free slot for pixel " << pixel);
}

// Hand-made contents of every buffer the view reads.
struct ViewInputs {
  graph::Extent size{64, 48};
  uint32_t layer_count = 3;
  std::vector<float> saliency, costs;
  std::vector<glm::vec4> layers;  // premultiplied, half-representable
  std::vector<gpu::LabelGpu> labels;
  std::vector<gpu::PlacementGpu> placements;
  std::vector<uint32_t> order;
  float margin = 2.0f;
  std::vector<uint64_t> keys;
  std::vector<uint32_t> fragments;  // inserted per pixel

  size_t pixels() const { return size_t{size.width} * size.height; }
  DebugViewData data() const {
    return {size, layer_count, saliency, costs, layers, labels, placements, order, margin, keys};
  }
};

// Fragment count (x * 7 + y * 3) mod 5 per pixel, inserted in a scrambled pixel order into a
// table at two-thirds load, so probe sequences cross; six labels: shown ones (one internal), a
// hidden one in the order, a disabled one outside it.
ViewInputs make_inputs() {
  ViewInputs in;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (size_t p = 0; p < in.pixels(); ++p) in.saliency.push_back(1.2f * unit(rng));
  for (size_t i = 0; i < in.pixels() * in.layer_count; ++i) in.costs.push_back(2.5f * unit(rng));
  for (size_t i = 0; i < in.pixels() * in.layer_count; ++i) {
    const float a = unit(rng);
    const glm::vec4 c(unit(rng) * a, unit(rng) * a, unit(rng) * a, a);
    in.layers.push_back(glm::unpackHalf4x16(glm::packHalf4x16(c)));
  }
  in.labels = {label({12.3f, 10.7f}, {14.0f, 6.0f}),
               label({40.6f, 30.2f}, {12.0f, 5.0f}),
               label({30.4f, 24.5f}, {10.0f, 4.0f}, LABEL_ENABLED | LABEL_INTERNAL),
               label({22.5f, 38.2f}, {16.0f, 6.0f}),
               label({5.5f, 40.5f}, {8.0f, 4.0f}, 0u),
               label({48.2f, 9.6f}, {12.0f, 6.0f})};
  in.placements = {
      {{20.0f, 18.0f}, 0.0f, PLACEMENT_SHOWN}, {{50.0f, 22.0f}, 0.0f, PLACEMENT_SHOWN},
      {{30.0f, 24.0f}, 0.0f, PLACEMENT_SHOWN}, {{22.5f, 38.2f}, 0.0f, PLACEMENT_HIDDEN},
      {{5.5f, 40.5f}, 0.0f, PLACEMENT_HIDDEN}, {{40.0f, 12.0f}, 0.0f, PLACEMENT_SHOWN}};
  in.order = {0, 1, 2, 3, 5};
  in.keys.assign(in.pixels() * 3, 0);
  in.fragments.resize(in.pixels());
  for (uint32_t y = 0; y < in.size.height; ++y) {
    for (uint32_t x = 0; x < in.size.width; ++x)
      in.fragments[y * in.size.width + x] = (x * 7 + y * 3) % 5;
  }
  const auto pixels = static_cast<uint32_t>(in.pixels());
  for (uint32_t i = 0; i < pixels; ++i) {
    const uint32_t pixel = i * 37 % pixels;
    for (uint32_t f = 0; f < in.fragments[pixel]; ++f)
      insert_fragment(in.keys, pixel, 1.0f + float(f));
  }
  return in;
}

Buffer filled_buffer(Context& ctx, std::span<const std::byte> bytes, VkBufferUsageFlags usage) {
  Buffer buffer(ctx, std::max<VkDeviceSize>(bytes.size(), 16), usage, MemoryKind::device_local);
  if (!bytes.empty()) upload(ctx, buffer, bytes);
  return buffer;
}

// Each choice of views on the GPU from one graph: the choice changes between runs only.
std::vector<std::vector<uint8_t>> views_on_gpu(Context& ctx, const ViewInputs& in,
                                               const std::vector<DebugViewChoice>& choices) {
  constexpr VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  const Buffer saliency = filled_buffer(ctx, as_bytes(in.saliency), storage);
  const Buffer costs = filled_buffer(ctx, as_bytes(in.costs), storage);
  const Buffer labels = filled_buffer(ctx, as_bytes(in.labels), storage);
  const Buffer placements = filled_buffer(ctx, as_bytes(in.placements), storage);
  // (the placement's order buffer holds a slot per label; past the order it is undefined)
  std::vector<uint32_t> order = in.order;
  order.resize(in.labels.size(), 0xDEADBEEFu);
  const Buffer order_buffer = filled_buffer(ctx, as_bytes(order), storage);
  const Buffer keys = filled_buffer(ctx, as_bytes(in.keys), storage);
  gpu::FrameGpu frame{};
  frame.width = in.size.width;
  frame.height = in.size.height;
  frame.table_size = static_cast<uint32_t>(in.keys.size());
  const Buffer frame_buffer =
      filled_buffer(ctx, std::as_bytes(std::span(&frame, 1)), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  const Image layers = test::layer_image(ctx, in.size, in.layer_count, in.layers);

  graph::Graph g;
  const auto filled = [&g](const char* name, const Buffer& buffer) {
    return g.import_buffer(name, {.buffer = buffer.handle(), .has_content = true});
  };
  DebugView view(ctx);
  const graph::ResourceId image = view.add_to(
      g, {.saliency = filled("saliency", saliency),
          .costs = filled("costs", costs),
          .labels = filled("labels", labels),
          .placements = filled("placements", placements),
          .order = filled("order", order_buffer),
          .layers = g.import_image("layers", {.image = layers.handle(),
                                              .view = layers.view(),
                                              .format = layers.desc().format,
                                              .has_content = true,
                                              .initial_layout = VK_IMAGE_LAYOUT_GENERAL}),
          .frame = filled("frame", frame_buffer),
          .keys = filled("keys", keys),
          .layer_count = in.layer_count,
          .label_count = static_cast<uint32_t>(in.labels.size())});
  graph::GraphRunner runner(ctx, std::move(g));
  runner.set_viewport(in.size);
  view.set_placement(static_cast<uint32_t>(in.order.size()), in.margin);
  std::vector<std::vector<uint8_t>> out;
  for (const DebugViewChoice& choice : choices) {
    view.set(choice);
    runner.run_now();
    out.push_back(as<uint8_t>(runner.download_image(image)));
  }
  return out;
}

const char* name_of(DebugBuffer buffer) {
  static const char* names[] = {"saliency", "costs", "constraints", "layer", "fragments"};
  return names[static_cast<uint32_t>(buffer)];
}

// Whether a pixel of the reference within one pixel of p has exactly `gpu`'s colour at p.
bool colour_next_to(const std::vector<uint8_t>& gpu, const std::vector<uint8_t>& cpu,
                    graph::Extent size, size_t p) {
  const int x = int(p % size.width), y = int(p / size.width);
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const int nx = x + dx, ny = y + dy;
      if (nx < 0 || ny < 0 || nx >= int(size.width) || ny >= int(size.height)) continue;
      const size_t n = size_t(ny) * size.width + size_t(nx);
      if (std::equal(&gpu[4 * p], &gpu[4 * p + 4], &cpu[4 * n])) return true;
    }
  }
  return false;
}

// GPU and reference agree within 1/255 per channel; reports the first few pixels that do not.
// Constraint images are bits of plane tests: a GPU may fuse a multiply-add that the CPU rounds
// twice, so a pixel on a region's edge may take its neighbour's side; elsewhere they agree.
void check_view(const std::vector<uint8_t>& gpu, const std::vector<uint8_t>& cpu,
                graph::Extent size, const DebugViewChoice& choice) {
  const std::string mode = name_of(choice.buffer);
  CAPTURE(mode);
  CAPTURE(choice.layer);
  CAPTURE(choice.label);
  REQUIRE(gpu.size() == cpu.size());
  size_t bad = 0, edge = 0;
  for (size_t i = 0; i < cpu.size(); ++i) {
    if (std::abs(int(gpu[i]) - int(cpu[i])) <= 1) continue;
    const size_t p = i / 4;
    if (choice.buffer == DebugBuffer::constraints && colour_next_to(gpu, cpu, size, p)) {
      ++edge;
      continue;
    }
    if (bad++ < 3) {
      MESSAGE("pixel " << p % size.width << "," << p / size.width << " channel " << i % 4
                       << ": gpu " << int(gpu[i]) << " cpu " << int(cpu[i]));
    }
  }
  CHECK_MESSAGE(bad == 0, bad << " channels differ by more than 1/255");
  CHECK(edge * 200 <= cpu.size());  // a few edge pixels at most (0.5%)
}

// How many pixels of an rgba8 view have exactly this colour.
size_t count_colour(const std::vector<uint8_t>& view, glm::u8vec3 colour) {
  size_t n = 0;
  for (size_t i = 0; i + 3 < view.size(); i += 4) {
    n += view[i] == colour.r && view[i + 1] == colour.g && view[i + 2] == colour.b;
  }
  return n;
}

// A cube of voxels whose value falls off from the centre, under a ramp transfer function.
void add_ball(Scene& scene, uint32_t n, glm::vec3 origin) {
  Volume v;
  v.name = "ball";
  v.dims = glm::uvec3(n);
  v.origin = origin;
  v.voxels.resize(v.voxel_count());
  const glm::vec3 centre(float(n - 1) * 0.5f);
  for (uint32_t k = 0; k < n; ++k) {
    for (uint32_t j = 0; j < n; ++j) {
      for (uint32_t i = 0; i < n; ++i) {
        const float r = glm::length(glm::vec3(i, j, k) - centre) / (float(n) * 0.5f);
        v.voxels[(size_t(k) * n + j) * n + i] =
            std::byte(uint8_t(255.0f * glm::clamp(1.0f - r, 0.0f, 1.0f)));
      }
    }
  }
  v.value_range = {0.0f, 255.0f};
  v.transfer_function = int(scene.transfer_functions.size());
  TransferFunction tf;
  tf.name = "ramp";
  tf.stops = {{0.0f, glm::vec4(1.0f, 0.6f, 0.3f, 0.0f)},
              {0.2f, glm::vec4(1.0f, 0.6f, 0.3f, 0.0f)},
              {1.0f, glm::vec4(1.0f, 1.0f, 1.0f, 0.6f)}};
  scene.transfer_functions.push_back(tf);
  scene.volumes.push_back(std::move(v));
}

}  // namespace

TEST_SUITE("gpu") {
  TEST_CASE_FIXTURE(test::GpuTest, "debug_view_matches_cpu_reference_in_every_mode") {
    const ViewInputs in = make_inputs();
    std::vector<DebugViewChoice> choices = {
        {.buffer = DebugBuffer::saliency, .scale = 1.0f},
        {.buffer = DebugBuffer::saliency, .scale = 3.0f},
        {.buffer = DebugBuffer::costs, .layer = 0, .scale = 0.5f},
        {.buffer = DebugBuffer::costs, .layer = 2, .scale = 0.3f},
        {.buffer = DebugBuffer::costs, .layer = 9, .scale = 1.0f},  // past the last: the last
        {.buffer = DebugBuffer::layer, .layer = 1},
        {.buffer = DebugBuffer::layer, .layer = 2},
        {.buffer = DebugBuffer::fragments, .scale = 0.25f},
    };
    for (uint32_t l = 0; l <= in.labels.size(); ++l) {  // (one past the labels: black)
      choices.push_back({.buffer = DebugBuffer::constraints, .label = l});
    }
    const std::vector<std::vector<uint8_t>> gpu = views_on_gpu(ctx, in, choices);
    for (size_t i = 0; i < choices.size(); ++i) {
      check_view(gpu[i], debug_view_reference(in.data(), choices[i]), in.size, choices[i]);
    }
    // Not trivially equal: the layer view is neither black nor the checkerboard alone, the
    // fragment view shows none, one and four.
    CHECK(count_colour(gpu[5], {0, 0, 0}) < in.pixels() / 100);
    CHECK(count_colour(gpu[7], {0, 0, 0}) > 100);        // none
    CHECK(count_colour(gpu[7], {191, 0, 0}) > 100);      // one
    CHECK(count_colour(gpu[7], {255, 255, 255}) > 100);  // four
  }

  TEST_CASE_FIXTURE(test::GpuTest,
                    "debug_view_fragment_counts_are_the_fragments_inserted_per_pixel") {
    const ViewInputs in = make_inputs();
    CHECK(habuffer_fragment_counts(in.data()) == in.fragments);
  }

  TEST_CASE_FIXTURE(test::GpuTest,
                    "debug_view_constraints_show_the_shadows_of_the_labels_before_the_picked_one") {
    const ViewInputs in = make_inputs();
    const DebugViewData data = in.data();
    const auto bits_of = [&](uint32_t label) { return constraint_image_reference(data, label); };
    const auto count = [](const std::vector<uint32_t>& image, uint32_t bit) {
      size_t n = 0;
      for (const uint32_t b : image) n += b != DEBUG_NOT_CANDIDATE && (b & bit) != 0;
      return n;
    };
    // The first label in the order has no labels before it: anchors only.
    const std::vector<uint32_t> first = bits_of(0);
    CHECK(count(first, CONSTRAINT_LABEL) == 0);
    CHECK(count(first, CONSTRAINT_CONNECTOR) == 0);
    CHECK(count(first, CONSTRAINT_ANCHOR) > 0);
    // The last one meets the boxes and connectors of those placed (not the hidden one's, nor an
    // internal label's connector).
    const std::vector<uint32_t> last = bits_of(5);
    CHECK(count(last, CONSTRAINT_LABEL) > 20);
    CHECK(count(last, CONSTRAINT_CONNECTOR) > 20);
    // An internal label may only sit on its anchor; a disabled one is nowhere.
    size_t internal = 0;
    for (const uint32_t b : bits_of(2)) internal += b != DEBUG_NOT_CANDIDATE;
    CHECK(internal == 1);
    for (const uint32_t b : bits_of(4)) REQUIRE(b == DEBUG_NOT_CANDIDATE);
  }

  // The renderer and the placement make the buffers: a volume and two transparent quads, three
  // labels, two layers. Every view matches the reference on what they made; the fragment counts
  // add up to what the resolve counted, and the last label's constraint view holds exactly the
  // placement's own constraint image.
  TEST_CASE_FIXTURE(test::GpuTest,
                    "debug_views_of_a_rendered_and_placed_frame_match_the_reference") {
    Scene scene;
    add_ball(scene, 16, glm::vec3(-8.0f));
    scene.meshes = {quad(-4.0f, {0.2f, 0.9f, 0.3f, 0.6f}, 7.0f, {-4.0f, 2.0f}),
                    quad(5.0f, {0.9f, 0.2f, 0.6f, 0.5f}, 5.0f, {5.0f, -3.0f})};
    RenderSettings render_settings;
    render_settings.layer_count = 2;
    const graph::Extent size{64, 48};
    VolumeRenderer renderer(ctx, scene, render_settings);
    renderer.set_camera(
        {glm::lookAt(glm::vec3(0.0f, 0.0f, 50.0f), glm::vec3(0.0f), glm::vec3(0.0f, 1.0f, 0.0f)),
         40.0f, 1.0f, 300.0f});
    const std::vector<gpu::LabelGpu> labels = {label({30.3f, 20.6f}, {14.0f, 5.0f}),
                                               label({38.7f, 28.2f}, {12.0f, 5.0f}),
                                               label({24.4f, 30.5f}, {10.0f, 4.0f})};
    const std::vector<uint32_t> order = {1, 0, 2};
    Placement placement(ctx, static_cast<uint32_t>(labels.size()));
    DebugView view(ctx);

    graph::Graph g;
    const VolumeRenderer::Outputs rendered = renderer.add_to(g);
    const Placement::Outputs placed = placement.add_to(
        g, {.final_image = rendered.final, .layers = rendered.layers, .layer_count = 2});
    const DebugView::Inputs inputs{.saliency = placed.saliency,
                                   .costs = placed.costs,
                                   .labels = placed.labels,
                                   .placements = placed.placements,
                                   .order = placed.order,
                                   .layers = rendered.layers,
                                   .frame = rendered.frame,
                                   .keys = rendered.keys,
                                   .layer_count = 2,
                                   .label_count = static_cast<uint32_t>(labels.size())};
    const graph::ResourceId image = view.add_to(g, inputs);
    graph::GraphRunner runner(ctx, std::move(g));
    runner.set_viewport(size);
    PlacementSettings settings;
    settings.write_constraints = true;
    settings.method = PlacementMethod::sequential;  // (its constraint image)
    settings.margin_em = 2.0f / settings.text_pixels;
    placement.set_frame(labels, order, settings);
    view.set_placement(static_cast<uint32_t>(order.size()), margin_pixels(settings));

    const std::vector<DebugViewChoice> choices = {
        {.buffer = DebugBuffer::fragments, .scale = 0.25f},
        {.buffer = DebugBuffer::saliency, .scale = 2.0f},
        {.buffer = DebugBuffer::costs, .layer = 0, .scale = 0.5f},
        {.buffer = DebugBuffer::costs, .layer = 1, .scale = 0.5f},
        {.buffer = DebugBuffer::layer, .layer = 0},
        {.buffer = DebugBuffer::layer, .layer = 1},
        {.buffer = DebugBuffer::constraints, .label = 0},
        {.buffer = DebugBuffer::constraints, .label = 2},
    };
    for (const DebugViewChoice& choice : choices) {
      view.set(choice);
      runner.run_now();
      const auto saliency = as<float>(runner.download_buffer(inputs.saliency));
      const auto costs = as<float>(runner.download_buffer(inputs.costs));
      const auto layers = from_halves(runner.download_image(inputs.layers));
      const auto label_data = as<gpu::LabelGpu>(runner.download_buffer(inputs.labels));
      const auto placements = as<gpu::PlacementGpu>(runner.download_buffer(inputs.placements));
      const auto keys = as<uint64_t>(runner.download_buffer(inputs.keys));
      const auto frame = as<gpu::FrameGpu>(runner.download_buffer(inputs.frame));
      REQUIRE(frame.size() == 1);
      REQUIRE(frame[0].table_size == keys.size());
      const DebugViewData data{
          size, 2, saliency, costs, layers, label_data, placements, order, margin_pixels(settings),
          keys};
      const std::vector<uint8_t> shown = as<uint8_t>(runner.download_image(image));
      check_view(shown, debug_view_reference(data, choice), size, choice);
      if (std::getenv("STRATA_KEEP_IMAGES")) {
        write_png(test::output_dir() + "/debug-view-" + name_of(choice.buffer) + "-" +
                      std::to_string(choice.layer) + "-" + std::to_string(choice.label) + ".png",
                  size.width, size.height, shown);
      }

      if (choice.buffer == DebugBuffer::fragments) {
        const std::vector<uint32_t> counts = habuffer_fragment_counts(data);
        uint32_t total = 0, most = 0;
        for (const uint32_t c : counts) {
          total += c;
          most = std::max(most, c);
        }
        const RenderStats stats = renderer.collect(runner);
        CHECK(stats.overflow == 0);
        CHECK(total == stats.fragments);
        CHECK(most == 2);  // both quads (volume boxes are not in the table)
      }
      if (choice.buffer == DebugBuffer::constraints && choice.label == order.back()) {
        for (const auto& p : placements) REQUIRE(p.shown == PLACEMENT_SHOWN);
        const auto placed_bits = as<uint32_t>(runner.download_buffer(placed.constraints));
        const std::vector<uint32_t> bits = constraint_image_reference(data, choice.label);
        size_t candidates = 0, shadowed = 0, differ = 0;
        for (size_t p = 0; p < bits.size(); ++p) {
          if (bits[p] == DEBUG_NOT_CANDIDATE) continue;
          ++candidates;
          shadowed += (bits[p] & (CONSTRAINT_LABEL | CONSTRAINT_CONNECTOR)) != 0;
          differ += bits[p] != placed_bits[p];
        }
        CHECK(candidates > 1000);
        CHECK(shadowed > 20);
        CHECK(differ == 0);
      }
    }
  }
}

}  // namespace strata
