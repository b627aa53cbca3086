#include "passes/label_drawing.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/packing.hpp>

#include "engine/core/error.h"
#include "shared/label_draw_pixel_access.h"
#include "shared/volume_shading.h"  // split_depth

namespace strata {

using graph::ResourceId;
using graph::Use;

namespace gpu {
namespace {

using glm::ivec2;  // the software sampler's texel coordinates, by their GLSL name like the rest

// labels.draw's pixel on the CPU: the shared loop is included inside this struct, so its
// functions see the buffer accessors and the software sampler below as members.
struct LabelDrawReference {
  const LabelDrawData& data;
  const FontAtlas& font;
  const ImageAtlas& images;

  uint label_count() const {
    return static_cast<uint>(std::min(data.labels.size(), data.placements.size()));
  }
  LabelGpu label_at(uint i) const { return data.labels[i]; }
  bool layer_frames() const { return data.layer_frames; }
  bool connector_halos() const { return data.connector_halos; }
  float anchor_hidden_at(uint i) const {
    return i < data.covers.size() ? data.covers[i].hidden : 0.0f;
  }
  PlacementGpu placement_at(uint i) const { return data.placements[i]; }
  GlyphGpu glyph_at(uint i) const { return data.glyphs[i]; }

  float texel(ivec2 p) const {
    const ivec2 top = ivec2(font.width, font.height) - 1;
    const ivec2 c = clamp(p, ivec2(0), top);
    return float(font.coverage[size_t(c.y) * font.width + size_t(c.x)]) / 255.0f;
  }
  // Linear filtering with clamp-to-edge addressing (the texel reads clamp), as the graph's
  // sampler does.
  template <typename Texel>
  static auto bilinear(Texel texel_at, vec2 size, vec2 uv) {
    const vec2 x = uv * size - 0.5f;
    const vec2 base = floor(x);
    const vec2 f = x - base;
    const ivec2 i = ivec2(base);
    const auto top = mix(texel_at(i), texel_at(i + ivec2(1, 0)), f.x);
    const auto bottom = mix(texel_at(i + ivec2(0, 1)), texel_at(i + ivec2(1, 1)), f.x);
    return mix(top, bottom, f.y);
  }
  float atlas_coverage(vec2 uv) const {
    return bilinear([this](ivec2 p) { return texel(p); }, vec2(font.width, font.height), uv);
  }

  vec4 image_texel(ivec2 p) const {
    const ivec2 c = clamp(p, ivec2(0), ivec2(images.width, images.height) - 1);
    const size_t at = (size_t(c.y) * images.width + size_t(c.x)) * 4;
    return vec4(images.texels[at], images.texels[at + 1], images.texels[at + 2],
                images.texels[at + 3]) /
           255.0f;
  }
  vec4 image_texel(vec2 uv) const {
    return bilinear([this](ivec2 p) { return image_texel(p); }, vec2(images.width, images.height),
                    uv);
  }

#include "shared/label_draw_pixel.h"
};
static_assert(LabelDrawPixelAccess<LabelDrawReference>);

}  // namespace
}  // namespace gpu

namespace {

Image atlas_image(Context& ctx, VkFormat format, uint32_t width, uint32_t height,
                  std::span<const std::byte> texels, Uploads* uploads) {
  Image image(ctx, {format, {width, height, 1}, VK_IMAGE_TYPE_2D, VK_IMAGE_USAGE_SAMPLED_BIT});
  if (uploads) {
    uploads->add(ctx, image, texels, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  } else {
    upload(ctx, image, texels, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  }
  return image;
}

}  // namespace

LabelDrawing::LabelDrawing(Context& ctx, const FontAtlas& font, const ImageAtlas& images,
                           LabelDrawing* from)
    : ghost_pipeline_(
          reuse_or_create(ctx, from ? &from->ghost_pipeline_ : nullptr, "labels_ghost.comp")),
      anchor_cover_(
          reuse_or_create(ctx, from ? &from->anchor_cover_ : nullptr, "labels_anchor_cover.comp")),
      draw_(reuse_or_create(ctx, from ? &from->draw_ : nullptr, "label_draw.comp")),
      composite_(reuse_or_create(ctx, from ? &from->composite_ : nullptr, "label_composite.comp")) {
  set_atlases(ctx, font, images);
}

std::vector<Image> LabelDrawing::set_atlases(Context& ctx, const FontAtlas& font,
                                             const ImageAtlas& images, Uploads* uploads) {
  std::vector<Image> old;
  if (atlas_) old.push_back(std::move(*atlas_));
  if (images_) old.push_back(std::move(*images_));
  atlas_.emplace(atlas_image(ctx, VK_FORMAT_R8_UNORM, font.width, font.height,
                             as_bytes(font.coverage), uploads));
  images_.emplace(atlas_image(ctx, VK_FORMAT_R8G8B8A8_UNORM, images.width, images.height,
                              as_bytes(images.texels), uploads));
  return old;
}

void LabelDrawing::bind(graph::GraphRunner& runner) const {
  if (atlas_id_ != 0) {
    runner.bind_image(atlas_id_, atlas_->handle(), atlas_->view(), VK_FORMAT_R8_UNORM);
    runner.bind_image(images_id_, images_->handle(), images_->view(), VK_FORMAT_R8G8B8A8_UNORM);
  }
}

gpu::LabelDrawParams LabelDrawing::params(graph::Extent viewport) const {
  return {viewport.width,
          viewport.height,
          layer_count_,
          label_count_,
          background_rgba(background_),
          layer_frames_ ? 1u : 0u,
          connector_halos(background_) ? 1u : 0u,
          0u,
          0u};
}

void LabelDrawing::add_to(graph::Graph& graph, const Inputs& in) {
  layer_count_ = in.layer_count;
  background_ = in.background;
  const ResourceId atlas = graph.import_image(
      "labels.font_atlas", {.image = atlas_->handle(),
                            .view = atlas_->view(),
                            .format = VK_FORMAT_R8_UNORM,
                            .has_content = true,
                            .initial_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
  const ResourceId images = graph.import_image(
      "labels.image_atlas", {.image = images_->handle(),
                             .view = images_->view(),
                             .format = VK_FORMAT_R8G8B8A8_UNORM,
                             .has_content = true,
                             .initial_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
  atlas_id_ = atlas;
  images_id_ = images;
  if (in.ghost) {
    graph.add_pass({"labels.ghost",
                    graph::PassKind::compute,
                    {{in.layers, Use::storage_read_write, GHOST_BINDING_LAYERS},
                     {in.labels, Use::storage_read, GHOST_BINDING_LABELS},
                     {in.placements, Use::storage_read, GHOST_BINDING_PLACEMENTS}},
                    [this](graph::PassContext& pc) {
                      if (ghost_.strength <= 0.0f) return;
                      pc.dispatch(ghost_pipeline_,
                                  ghost_params(ghost_, pc.viewport, layer_count_, label_count_),
                                  {pc.viewport.width, pc.viewport.height, 1});
                    },
                    "labels"});
  }
  graph.add_pass({"labels.anchor_cover",
                  graph::PassKind::compute,
                  {{in.layers, Use::storage_read, ANCHOR_COVER_BINDING_LAYERS},
                   {in.labels, Use::storage_read, ANCHOR_COVER_BINDING_LABELS},
                   {in.depth, Use::storage_read, ANCHOR_COVER_BINDING_DEPTH},
                   {in.frame, Use::uniform, ANCHOR_COVER_BINDING_FRAME},
                   {in.covers, Use::storage_write, ANCHOR_COVER_BINDING_COVERS}},
                  [this](graph::PassContext& pc) {
                    pc.dispatch(anchor_cover_, params(pc.viewport), {label_count_, 1, 1});
                  },
                  "labels"});
  graph.add_pass(
      {"labels.draw",
       graph::PassKind::compute,
       {{in.layers, Use::storage_read_write, LABEL_DRAW_BINDING_LAYERS},
        {in.labels, Use::storage_read, LABEL_DRAW_BINDING_LABELS},
        {in.placements, Use::storage_read, LABEL_DRAW_BINDING_PLACEMENTS},
        {in.glyphs, Use::storage_read, LABEL_DRAW_BINDING_GLYPHS},
        {in.covers, Use::storage_read, LABEL_DRAW_BINDING_COVERS},
        {atlas, Use::sampled, LABEL_DRAW_BINDING_ATLAS},
        {images, Use::sampled, LABEL_DRAW_BINDING_IMAGES}},
       [this](graph::PassContext& pc) {
         if (!marks_) return;
         pc.dispatch(draw_, params(pc.viewport), {pc.viewport.width, pc.viewport.height, 1});
       },
       "labels"});
  graph.add_pass(
      {"labels.composite",
       graph::PassKind::compute,
       {{in.layers, Use::storage_read, LABEL_DRAW_BINDING_LAYERS},
        {in.labels, Use::storage_read, LABEL_DRAW_BINDING_LABELS},
        {in.placements, Use::storage_read, LABEL_DRAW_BINDING_PLACEMENTS},
        {in.covers, Use::storage_read, LABEL_DRAW_BINDING_COVERS},
        {in.output, Use::storage_write, LABEL_DRAW_BINDING_FINAL}},
       [this](graph::PassContext& pc) {
         gpu::LabelDrawParams p = params(pc.viewport);
         if (!marks_) p.label_count = 0;  // (no rear label's leader drawn on top either)
         pc.dispatch(composite_, p, {pc.viewport.width, pc.viewport.height, 1});
       },
       "labels"});
}

namespace {

glm::vec4 to_half_precision(glm::vec4 c) {
  return glm::unpackHalf4x16(glm::packHalf4x16(c));
}

void check_layers(std::span<const glm::vec4> layers, graph::Extent size, uint32_t layer_count) {
  if (layers.size() != size_t{size.width} * size.height * layer_count) {
    throw Error("labels: " + std::to_string(layers.size()) + " layer pixels for " +
                std::to_string(layer_count) + " layers of " + std::to_string(size.width) + "x" +
                std::to_string(size.height));
  }
}

}  // namespace

std::vector<glm::vec4> draw_labels_reference(std::span<const glm::vec4> layers, graph::Extent size,
                                             uint32_t layer_count, const LabelDrawData& data,
                                             const FontAtlas& font, const ImageAtlas& images) {
  check_layers(layers, size, layer_count);
  gpu::LabelDrawReference reference{data, font, images};
  std::vector<glm::vec4> out(layers.size());
  size_t i = 0;
  for (uint32_t l = 0; l < layer_count; ++l) {
    for (uint32_t y = 0; y < size.height; ++y) {
      for (uint32_t x = 0; x < size.width; ++x, ++i) {
        const glm::vec2 p = glm::vec2(float(x), float(y)) + 0.5f;
        out[i] = to_half_precision(reference.draw_labels_at(p, l, layers[i]));
      }
    }
  }
  return out;
}

gpu::GhostParams ghost_params(const GhostSettings& ghost, graph::Extent size, uint32_t layer_count,
                              uint32_t label_count) {
  return {size.width,     size.height,  layer_count,         label_count,
          ghost.strength, ghost.radius, ghost.leader_radius, GHOST_BOX_SHARE * ghost.radius};
}

std::vector<glm::vec4> ghost_reference(std::span<const glm::vec4> layers, graph::Extent size,
                                       uint32_t layer_count, const LabelDrawData& data,
                                       const GhostSettings& ghost) {
  check_layers(layers, size, layer_count);
  const size_t pixels = size_t{size.width} * size.height;
  const size_t count = std::min(data.labels.size(), data.placements.size());
  const gpu::GhostParams g = ghost_params(ghost, size, layer_count, uint32_t(count));
  std::vector<glm::vec4> out(layers.begin(), layers.end());
  if (ghost.strength <= 0.0f) return out;
  for (size_t q = 0; q < pixels; ++q) {
    const glm::vec2 p(float(q % size.width) + 0.5f, float(q / size.width) + 0.5f);
    gpu::GhostOpenings open = gpu::ghost_no_openings();
    float alpha[VR_MAX_LAYERS] = {};
    for (size_t i = 0; i < count; ++i) {
      const gpu::LabelGpu& label = data.labels[i];
      if (label.layer >= std::min(layer_count, uint32_t(VR_MAX_LAYERS))) continue;
      open =
          gpu::ghost_with(open, label.layer, gpu::ghost_opening(label, data.placements[i], p, g));
    }
    for (uint32_t k = 0; k < std::min(layer_count, uint32_t(VR_MAX_LAYERS)); ++k)
      alpha[k] = out[size_t(k) * pixels + q].a;
    const gpu::GhostKeeps keeps = gpu::ghost_keeps(open, alpha, layer_count, g.strength);
    for (uint32_t k = 0; k < std::min(layer_count, uint32_t(VR_MAX_LAYERS)); ++k) {
      glm::vec4& c = out[size_t(k) * pixels + q];
      if (keeps.layer[k] < 1.0f) c = to_half_precision(c * keeps.layer[k]);
    }
  }
  return out;
}

std::vector<gpu::AnchorCoverGpu> anchor_cover_reference(std::span<const glm::vec4> layers,
                                                        std::span<const float> depth,
                                                        graph::Extent size, uint32_t layer_count,
                                                        const gpu::FrameGpu& frame,
                                                        std::span<const gpu::LabelGpu> labels) {
  check_layers(layers, size, layer_count);
  const size_t pixels = size_t{size.width} * size.height;
  if (depth.size() != pixels) throw Error("labels: the depth image is not the layers' size");
  std::vector<gpu::AnchorCoverGpu> out;
  for (const gpu::LabelGpu& l : labels) {
    const glm::vec2 a = glm::floor(l.anchor);
    if (a.x < 0.0f || a.y < 0.0f || a.x >= float(size.width) || a.y >= float(size.height)) {
      out.push_back({0.0f, 0.0f});
      continue;
    }
    const size_t p = size_t(a.y) * size.width + size_t(a.x);
    const uint32_t layer = std::min({l.layer, layer_count, uint32_t(VR_MAX_LAYERS)});
    float front = 0.0f;
    for (uint32_t k = 0; k < layer; ++k) front += (1.0f - front) * layers[k * pixels + p].a;
    glm::vec4 splits[2] = {frame.splits[0], frame.splits[1]};
    const float near = layer > 0 ? gpu::split_depth(splits, layer - 1) : frame.near_depth;
    out.push_back({front, gpu::anchor_hidden(front, depth[p], l.anchor_depth, near,
                                             frame.depth_alpha, frame.step)});
  }
  return out;
}

std::vector<uint8_t> composite_reference(std::span<const glm::vec4> layers, graph::Extent size,
                                         uint32_t layer_count, const Background& background,
                                         const LabelDrawData& data) {
  check_layers(layers, size, layer_count);
  const size_t pixels = size_t{size.width} * size.height;
  const size_t count = std::min(data.labels.size(), data.placements.size());
  std::vector<uint8_t> out;
  out.reserve(4 * pixels);
  std::vector<float> front(layer_count);
  for (size_t p = 0; p < pixels; ++p) {
    glm::vec4 accumulated(0.0f);
    for (uint32_t l = 0; l < layer_count; ++l) {
      front[l] = accumulated.a;
      accumulated = gpu::label_over(accumulated, layers[l * pixels + p]);
    }
    glm::vec4 c = gpu::over_background(accumulated, background_rgba(background));
    const glm::vec2 centre(float(p % size.width) + 0.5f, float(p / size.width) + 0.5f);
    for (size_t i = 0; i < count; ++i) {
      const gpu::LabelGpu& label = data.labels[i];
      if (label.layer >= layer_count) continue;
      const float hidden = i < data.covers.size() ? data.covers[i].hidden : 0.0f;
      const glm::vec4 behind =
          gpu::label_behind(label, data.placements[i], centre, front[label.layer], hidden);
      c = gpu::label_over_composite(behind, c);
    }
    c = gpu::straight_alpha(c);
    for (int ch = 0; ch < 4; ++ch) {
      out.push_back(static_cast<uint8_t>(std::lround(glm::clamp(c[ch], 0.0f, 1.0f) * 255.0f)));
    }
  }
  return out;
}

}  // namespace strata
