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
  graph.add_pass({"picking.upload",
                  graph::PassKind::transfer,
                  {{pixels, Use::transfer_dst}},
                  [this, pixels](graph::PassContext& pc) {
                    if (pixels_.empty()) return;
                    record_update(pc.cmd, pc.buffer(pixels), 0, as_bytes(pixels_));
                  },
                  "picking"});
  graph.add_pass({"picking.points",
                  graph::PassKind::compute,
                  {{in.frame, Use::uniform, PICK_BINDING_FRAME},
                   {in.depth, Use::storage_read, PICK_BINDING_DEPTH},
                   {pixels, Use::storage_read, PICK_BINDING_PIXELS},
                   {points, Use::storage_write, PICK_BINDING_POINTS}},
                  [this](graph::PassContext& pc) {
                    if (pixels_.empty()) return;
                    const auto count = static_cast<uint32_t>(pixels_.size());
                    pc.dispatch(pipeline_,
                                gpu::PickParams{count, pc.viewport.width, pc.viewport.height, 0u},
                                {count, 1, 1});
                  },
                  "picking"});
  return points;
}

std::vector<PickHit> Picking::hits(std::span<const std::byte> points) const {
  std::vector<PickHit> out;
  for (size_t i = 0; i < pixels_.size(); ++i) {
    glm::vec4 p(0.0f);
    if ((i + 1) * sizeof p <= points.size())
      std::memcpy(&p, points.data() + i * sizeof p, sizeof p);
    out.push_back({p.w > 0.5f, glm::vec3(p)});
  }
  return out;
}

ScenePick pick_scene(Context& ctx, const Scene& scene, const Camera& camera,
                     const RenderSettings& settings, graph::Extent size,
                     std::vector<glm::vec2> pixels, uint32_t runs) {
  VolumeRenderer renderer(ctx, scene, settings);
  renderer.set_camera(camera);
  Picking picking(ctx);
  picking.set_pixels(std::move(pixels));
  graph::Graph graph;
  const VolumeRenderer::Outputs out = renderer.add_to(graph);
  const ResourceId points = picking.add_to(graph, {.frame = out.frame, .depth = out.depth});
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

std::vector<PickHit> pick_reference(const ReferenceImage& image, const gpu::FrameGpu& frame,
                                    std::span<const glm::vec2> pixels) {
  std::vector<PickHit> out;
  for (const glm::vec2 pixel : pixels) {
    const glm::ivec2 t = gpu::pick_texel(pixel, image.size.width, image.size.height);
    const float depth = image.depth[size_t(t.y) * image.size.width + size_t(t.x)];
    const glm::vec4 p = gpu::pick_point(frame, t, depth, image.size.width, image.size.height);
    out.push_back({p.w > 0.5f, glm::vec3(p)});
  }
  return out;
}

}  // namespace strata
