#include "passes/picking.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "engine/core/error.h"
#include "engine/gpu/resources.h"
#include "engine/graph/graph_runner.h"

namespace strata {

using graph::ResourceId;
using graph::Use;

Picking::Picking(Context& ctx, Picking* from)
    : pipeline_(reuse_or_create(ctx, from ? &from->pipeline_ : nullptr, "pick.comp")) {}

void Picking::set_pixels(std::vector<glm::vec2> pixels) {
  if (pixels.size() > PICK_MAX) {
    throw Error("picking: " + std::to_string(pixels.size()) + " pixels in one frame, at most " +
                std::to_string(PICK_MAX));
  }
  pixels_ = std::move(pixels);
}

ResourceId Picking::add_to(graph::Graph& graph, const Inputs& in) {
  const auto fixed = [](VkDeviceSize bytes) {
    return graph::BufferInfo{[bytes](graph::Extent) { return bytes; }};
  };
  const ResourceId pixels = graph.add_buffer("picking.pixels", fixed(PICK_MAX * sizeof(glm::vec2)));
  const ResourceId points = graph.add_buffer("picking.points", fixed(PICK_MAX * sizeof(glm::vec4)));
  // (no labels: empty stand-ins for the shader's label bindings, cleared, never read)
  labels_ = in.labels != 0 && in.placements != 0;
  const ResourceId labels =
      labels_ ? in.labels : graph.add_buffer("picking.no_labels", fixed(sizeof(gpu::LabelGpu)));
  const ResourceId placements =
      labels_ ? in.placements
              : graph.add_buffer("picking.no_placements", fixed(sizeof(gpu::PlacementGpu)));
  std::vector<graph::ResourceUse> uploads{{pixels, Use::transfer_dst}};
  if (!labels_) {
    uploads.push_back({labels, Use::transfer_dst});
    uploads.push_back({placements, Use::transfer_dst});
  }
  graph.add_pass({"picking.upload", graph::PassKind::transfer, uploads,
                  [this, pixels, labels, placements](graph::PassContext& pc) {
                    if (!labels_) {
                      vkCmdFillBuffer(pc.cmd, pc.buffer(labels), 0, VK_WHOLE_SIZE, 0);
                      vkCmdFillBuffer(pc.cmd, pc.buffer(placements), 0, VK_WHOLE_SIZE, 0);
                    }
                    if (pixels_.empty()) return;
                    record_update(pc.cmd, pc.buffer(pixels), 0, as_bytes(pixels_));
                  },
                  "picking"});
  const VolumeRenderer::Outputs& r = in.rendered;
  const uint32_t label_count = labels_ ? in.label_count : 0u;
  graph.add_pass({"picking.points",
                  graph::PassKind::compute,
                  {{r.frame, Use::uniform, VR_BINDING_FRAME},
                   {r.volumes, Use::uniform, VR_BINDING_VOLUMES},
                   {r.keys, Use::storage_read, VR_BINDING_KEYS},
                   {r.payload, Use::storage_read, VR_BINDING_PAYLOAD},
                   {r.atlas, Use::sampled, VR_BINDING_ATLAS},
                   {r.transfer, Use::storage_read, VR_BINDING_TRANSFER},
                   {r.occupancy, Use::storage_read, VR_BINDING_OCCUPANCY},
                   {r.depth, Use::storage_read, PICK_BINDING_DEPTH},
                   {r.layers, Use::storage_read, PICK_BINDING_LAYERS},
                   {labels, Use::storage_read, PICK_BINDING_LABELS},
                   {placements, Use::storage_read, PICK_BINDING_PLACEMENTS},
                   {pixels, Use::storage_read, PICK_BINDING_PIXELS},
                   {points, Use::storage_write, PICK_BINDING_POINTS}},
                  [this, label_count](graph::PassContext& pc) {
                    if (pixels_.empty()) return;
                    const auto count = static_cast<uint32_t>(pixels_.size());
                    const gpu::PickParams params{
                        count, 0u, 0u, 0u, ghost_params(ghost_, pc.viewport, 0u, label_count)};
                    pc.dispatch(pipeline_, params, {count, 1, 1});
                  },
                  "picking"});
  return points;
}

std::vector<PickHit> Picking::hits(std::span<const std::byte> points) const {
  return pick_hits(points, pixels_.size());
}

std::vector<PickHit> pick_hits(std::span<const std::byte> points, size_t count) {
  std::vector<PickHit> out;
  for (size_t i = 0; i < count; ++i) {
    glm::vec4 p(0.0f);
    if ((i + 1) * sizeof p <= points.size())
      std::memcpy(&p, points.data() + i * sizeof p, sizeof p);
    out.push_back({p.w > 0.5f, glm::vec3(p)});
  }
  return out;
}

namespace {

// A device-local buffer holding `data` (at least one element's worth), imported into `graph`.
template <typename T>
ResourceId import_filled(Context& ctx, graph::Graph& graph, const char* name,
                         std::span<const T> data, std::vector<Buffer>& keep) {
  const std::vector<T> bytes =
      data.empty() ? std::vector<T>(1) : std::vector<T>(data.begin(), data.end());
  keep.emplace_back(ctx, bytes.size() * sizeof(T), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                    MemoryKind::device_local);
  upload(ctx, keep.back(), as_bytes(bytes));
  return graph.import_buffer(name, {.buffer = keep.back().handle(), .has_content = true});
}

}  // namespace

ScenePick pick_scene(Context& ctx, const Scene& scene, const Camera& camera,
                     const RenderSettings& settings, graph::Extent size,
                     std::vector<glm::vec2> pixels, uint32_t runs, const PickLabels& labels) {
  VolumeRenderer renderer(ctx, scene, settings);
  renderer.set_camera(camera);
  Picking picking(ctx);
  picking.set_pixels(std::move(pixels));
  picking.set_ghost(labels.ghost);
  graph::Graph graph;
  const VolumeRenderer::Outputs out = renderer.add_to(graph);
  Picking::Inputs in{.rendered = out};
  std::vector<Buffer> label_buffers;
  label_buffers.reserve(2);
  if (!labels.labels.empty() && !labels.placements.empty()) {
    in.labels = import_filled(ctx, graph, "pick.labels", labels.labels, label_buffers);
    in.placements = import_filled(ctx, graph, "pick.placements", labels.placements, label_buffers);
    in.label_count = uint32_t(std::min(labels.labels.size(), labels.placements.size()));
  }
  const ResourceId points = picking.add_to(graph, in);
  graph::GraphRunner runner(ctx, std::move(graph));
  runner.set_viewport(size);
  renderer.run_until_no_overflow(runner, [](const RenderStats&) {});
  ScenePick result;
  for (uint32_t run = 0; run < std::max(runs, 1u); ++run) {
    if (run > 0) runner.run_now();
    double ms = 0.0;
    for (const graph::PassTiming& t : runner.timings())
      if (t.group == "picking") ms += t.ms;
    result.gpu_ms.push_back(ms);
  }
  result.hits = picking.hits(runner.download_buffer(points));
  return result;
}

std::vector<PickHit> pick_reference(const RenderInputs& inputs, const gpu::FrameGpu& frame,
                                    graph::Extent size, std::span<const glm::vec2> pixels,
                                    const PickLabels& labels) {
  const size_t label_count =
      std::min({labels.labels.size(), labels.placements.size(), size_t{LABEL_MAX}});
  const gpu::GhostParams g = ghost_params(labels.ghost, size, 0u, uint32_t(label_count));
  const uint32_t layer_count = std::min(frame.layer_count, uint32_t{VR_MAX_LAYERS});
  std::vector<PickHit> out;
  for (const glm::vec2 pixel : pixels) {
    const glm::ivec2 t = gpu::pick_texel(pixel, size.width, size.height);
    const glm::ivec2 cast = gpu::pick_cast_pixel(frame, t, size.width, size.height);
    const glm::vec2 centre = glm::vec2(cast) + 0.5f;
    ReferencePixel walked = walk_reference_pixel(inputs, frame, centre);
    // (as pick.comp: the labels' lenses at the pixel, not their boxes', then the keeps from the
    // layers' alphas)
    gpu::GhostOpenings open = gpu::ghost_no_openings();
    bool any = false;
    for (size_t i = 0; i < label_count && g.strength > 0.0f; ++i) {
      const gpu::LabelGpu& label = labels.labels[i];
      if (label.layer >= layer_count) continue;
      const glm::vec2 opening(
          gpu::ghost_opening(label, labels.placements[i], glm::vec2(t) + 0.5f, g).x, 0.0f);
      open = gpu::ghost_with(open, label.layer, opening);
      any = any || opening.x > 0.0f;
    }
    if (any) {
      float alpha[VR_MAX_LAYERS] = {};
      for (uint32_t l = 0; l < layer_count; ++l)
        alpha[l] = gpu::pick_stored_alpha(walked.layers[l].a);
      const gpu::GhostKeeps keeps = gpu::ghost_keeps(open, alpha, layer_count, g.strength);
      if (std::any_of(std::begin(keeps.layer), std::end(keeps.layer),
                      [](float k) { return k < 1.0f; })) {
        const gpu::PickStart start = gpu::pick_start(keeps, alpha, layer_count, frame.depth_alpha);
        walked.depth = 0.0f;
        if (start.layer < layer_count)
          walked = walk_reference_pixel(inputs, frame, centre, keeps.layer, &start);
      }
    }
    const glm::vec4 p = gpu::pick_point(frame, cast, walked.depth);
    out.push_back({p.w > 0.5f, glm::vec3(p)});
  }
  return out;
}

}  // namespace strata
