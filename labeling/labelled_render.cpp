#include "labeling/labelled_render.h"

#include <cmath>
#include <cstdio>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/error.h"
#include "engine/graph_runner.h"
#include "engine/headless_target.h"
#include "labeling/insertion_order.h"
#include "labeling/text_layout.h"
#include "passes/label_drawing.h"

namespace strata {
namespace {

glm::mat4 projection_of(const CameraSetup& camera, graph::Extent size) {
  glm::mat4 p = glm::perspectiveRH_ZO(glm::radians(camera.fov_y_degrees),
                                      float(size.width) / float(size.height), camera.near_plane,
                                      camera.far_plane);
  p[1][1] *= -1.0f;  // as the renderer: Vulkan's clip space has y down
  return p;
}

// Labels in placement order: layer by layer front to back, inside a layer in scene order.
std::vector<uint32_t> insertion_order(const std::vector<gpu::LabelGpu>& labels,
                                      const Layering& layering) {
  std::vector<uint32_t> result;
  for (uint32_t layer = 0; layer < layering.layer_count; ++layer) {
    for (uint32_t i : scene_order(uint32_t(labels.size()))) {
      if ((labels[i].flags & LABEL_ENABLED) && labels[i].layer == layer) result.push_back(i);
    }
  }
  return result;
}

}  // namespace

std::vector<ProjectedAnchor> project_anchors(const Scene& scene, const CameraSetup& camera,
                                             graph::Extent size) {
  const glm::mat4 clip = projection_of(camera, size) * camera.view;
  std::vector<ProjectedAnchor> out;
  for (const Label& label : scene.labels) {
    ProjectedAnchor a;
    const glm::vec4 view = camera.view * glm::vec4(label.anchor, 1.0f);
    a.eye_depth = -view.z;
    const glm::vec4 c = clip * glm::vec4(label.anchor, 1.0f);
    if (c.w > 0.0f && a.eye_depth > camera.near_plane && a.eye_depth < camera.far_plane) {
      const glm::vec2 ndc = glm::vec2(c) / c.w;
      a.pixel = (ndc * 0.5f + 0.5f) * glm::vec2(size.width, size.height);
      a.visible = a.pixel.x >= 0.0f && a.pixel.y >= 0.0f && a.pixel.x < float(size.width) &&
                  a.pixel.y < float(size.height);
    }
    out.push_back(a);
  }
  return out;
}

LabelledFrame render_labelled(Context& ctx, const Scene& scene, const CameraSetup& camera,
                              graph::Extent size, const LabellingSettings& settings) {
  LabelledFrame frame;
  frame.size = size;
  // Layering on the CPU, from the camera alone: k-means++ on the visible anchors' depths.
  const std::vector<ProjectedAnchor> anchors = project_anchors(scene, camera, size);
  std::vector<float> depths;
  for (const auto& a : anchors) depths.push_back(a.visible ? a.eye_depth : std::nanf(""));
  frame.layering = layer_labels(depths, settings.layer_count, camera.near_plane, camera.far_plane,
                                settings.seed);
  RenderSettings render = settings.render;
  render.layer_count = frame.layering.layer_count;
  render.splits = frame.layering.split_depths;

  // Labels: anchors, boxes from their texts, layers.
  const FontAtlas font = load_font_atlas(settings.font_pixels);
  std::vector<gpu::LabelGpu> labels(scene.labels.size());
  std::vector<std::string> texts;
  for (size_t i = 0; i < scene.labels.size(); ++i) {
    gpu::LabelGpu& l = labels[i];
    l.anchor = anchors[i].pixel;
    l.size = scene.labels[i].size;
    l.previous = anchors[i].pixel;
    l.anchor_depth = anchors[i].eye_depth;
    l.layer = frame.layering.label_layer[i];
    l.flags = (anchors[i].visible ? LABEL_ENABLED : 0u) | (settings.internal ? LABEL_INTERNAL : 0u);
    texts.push_back(scene.labels[i].text);
  }
  const std::vector<gpu::GlyphGpu> glyphs = build_glyph_buffer(font, texts, labels);
  const std::vector<uint32_t> order = insertion_order(labels, frame.layering);

  VolumeRenderer renderer(ctx, scene, render);
  renderer.set_camera(camera);
  Placement placement(ctx, uint32_t(labels.size()));
  LabelDrawing drawing(ctx, font);
  drawing.set_label_count(uint32_t(labels.size()));
  HeadlessTarget target(ctx);
  Buffer glyph_buffer(ctx, std::max<size_t>(1, glyphs.size()) * sizeof(gpu::GlyphGpu),
                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::device_local);
  if (!glyphs.empty()) upload(ctx, glyph_buffer, as_bytes(glyphs));

  graph::Graph graph;
  const VolumeRenderer::Outputs rendered = renderer.add_to(graph);
  const Placement::Resources placed =
      placement.add_to(graph, rendered.final, rendered.layers, render.layer_count);
  const graph::ResourceId glyph_id = graph.import_resource("labels.glyphs", {false, true});
  const graph::ResourceId labelled = graph.add_image("labels.final", {VK_FORMAT_R8G8B8A8_UNORM});
  drawing.add_to(graph, rendered.layers, placed.labels, placed.placements, glyph_id,
                 render.layer_count, labelled, render.background);
  target.add_output(graph, labelled);
  graph::GraphRunner runner(ctx, std::move(graph));
  runner.set_viewport(size);
  placement.set_frame(labels, order, settings.placement);
  for (int attempt = 0; attempt < 4; ++attempt) {
    renderer.bind(runner);
    placement.bind(runner);
    drawing.bind(runner);
    runner.bind_buffer(glyph_id, glyph_buffer.handle());
    target.bind(runner);
    runner.run_now();
    frame.render_stats = renderer.collect(runner);
    if (frame.render_stats.overflow == 0) break;
  }
  frame.timings = runner.timings();
  frame.image.assign(target.pixels().begin(), target.pixels().end());
  const auto results = placement.results();
  for (size_t i = 0; i < labels.size(); ++i) {
    LabelLayout l;
    l.id = scene.labels[i].id;
    l.text = scene.labels[i].text;
    l.layer = labels[i].layer;
    l.anchor = labels[i].anchor;
    l.box_size = labels[i].size;
    l.box_origin = results[i].position - labels[i].size * 0.5f;
    l.shown = results[i].shown == PLACEMENT_SHOWN;
    l.cost = results[i].cost;
    frame.labels.push_back(l);
  }
  return frame;
}

std::string layout_json(const LabelledFrame& frame) {
  std::string out = "{\n  \"width\": " + std::to_string(frame.size.width) +
                    ",\n  \"height\": " + std::to_string(frame.size.height) + ",\n  \"labels\": [";
  char line[512];
  for (size_t i = 0; i < frame.labels.size(); ++i) {
    const LabelLayout& l = frame.labels[i];
    std::string text;
    for (char c : l.text) {
      if (c == '"' || c == '\\') text += '\\';
      if (static_cast<unsigned char>(c) >= 0x20) text += c;
    }
    std::snprintf(line, sizeof line,
                  "%s\n    {\"id\": %d, \"text\": \"%s\", \"layer\": %u, \"anchor\": [%.2f, %.2f], "
                  "\"box\": [%.2f, %.2f, %.0f, %.0f], \"shown\": %s, \"cost\": %.4f}",
                  i ? "," : "", l.id, text.c_str(), l.layer, double(l.anchor.x), double(l.anchor.y),
                  double(l.box_origin.x), double(l.box_origin.y), double(l.box_size.x),
                  double(l.box_size.y), l.shown ? "true" : "false", double(l.cost));
    out += line;
  }
  return out + "\n  ]\n}\n";
}

}  // namespace strata
