// Labels drawn into the depth layers, then the layers composited into the final image (the
// thesis's depth cue: a label on a rear layer is partly covered by what lies in front of it).
//   labels.ghost         with ghosting on: the layers in front of each shown rear label made more
//                        transparent around its anchor and connector, in place (shared/ghost.h)
//   labels.anchor_cover  per label: what hides its anchor (AnchorCoverGpu: the layers in front
//                        as the lenses leave them, and whether the anchor is hidden)
//   labels.draw          per pixel of each layer: its shown labels (connector, box, text, anchor
//                        mark; dashed and hollow where the anchor is hidden) over the layer's
//                        content, in place
//   labels.composite     the layers front to back over the background into an rgba8 image
//                        (straight alpha: opaque unless the background is none)
// The shapes and the per-pixel loop are shared with the CPU reference below
// (shaders/shared/label_drawing.h, label_draw_pixel.h).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "engine/core/background.h"
#include "engine/core/font.h"
#include "engine/core/image_atlas.h"
#include "engine/gpu/resources.h"
#include "engine/gpu/shader_library.h"
#include "engine/graph/graph_runner.h"
#include "engine/graph/render_graph.h"
#include "shared/ghost.h"
#include "shared/label_drawing.h"

namespace strata {

// Ghosting's settings: how much the layers in front open (0 off, 1 fully at an anchor), the
// lens's radius around an anchor and along a connector (0: none), in pixels.
struct GhostSettings {
  float strength = 0.0f;
  float radius = 0.0f;
  float leader_radius = 0.0f;
};

gpu::GhostParams ghost_params(const GhostSettings& ghost, graph::Extent size, uint32_t layer_count,
                              uint32_t label_count);

class LabelDrawing {
 public:
  // Uploads the font's atlas and the labels' pictures once.
  // (with `pipelines_from`: that one's pipelines, moved out; new labels or a new font)
  LabelDrawing(Context& ctx, const FontAtlas& font, const ImageAtlas& images = {},
               LabelDrawing* pipelines_from = nullptr);

  struct Inputs {
    graph::ResourceId layers;  // the renderer's rgba16f array image, read and written in place
    uint32_t layer_count = 1;
    graph::ResourceId labels;      // LabelGpu[], with content
    graph::ResourceId placements;  // PlacementGpu[], one per label, with content
    graph::ResourceId glyphs;      // GlyphGpu[], with content
    graph::ResourceId output;      // a viewport-sized rgba8 image the composite overwrites
    Background background;    // under the composite (the placement never sees it)
    bool ghost = false;       // with the ghosting pass (its settings: set_ghost)
    graph::ResourceId depth;  // the renderer's r32f depth image (VolumeRenderer::Outputs)
    graph::ResourceId frame;  // the renderer's FrameGpu: layer splits, ray step, depth_alpha
    // An AnchorCoverGpu per label, written after the ghosting (labels_anchor_cover.comp) and read
    // by the drawing; the caller sizes it and may read it back.
    graph::ResourceId covers;
  };
  // Adds the passes; the font and image atlases are imported with their handles.
  void add_to(graph::Graph& graph, const Inputs& in);

  // New font and image atlases (new label texts): uploaded into new images, which bind() hands
  // to a graph built before (the copies waited for, or added to `uploads`: a frame's); the old
  // images are returned, for the caller to keep until the frames in flight that read them have
  // finished.
  std::vector<Image> set_atlases(Context& ctx, const FontAtlas& font, const ImageAtlas& images,
                                 Uploads* uploads = nullptr);
  void bind(graph::GraphRunner& runner) const;

  // How many labels of the labels buffer to draw (read when the graph is recorded); the shader
  // never reads past the end of the labels or placements buffer either way.
  void set_label_count(uint32_t count) { label_count_ = count; }
  void set_background(const Background& background) { background_ = background; }
  // Borders in their layer's colour (LABEL_LAYER_COLORS), read when the graph is recorded.
  void set_layer_frames(bool on) { layer_frames_ = on; }
  // Ghosting's settings, read when the graph is recorded (strength 0: the pass records nothing).
  void set_ghost(const GhostSettings& ghost) { ghost_ = ghost; }
  // Whether labels.draw and the composite draw the labels (read when the graph is recorded); off,
  // the ghosting and anchor covers are still made (a vector file draws the labels over it).
  void set_marks(bool on) { marks_ = on; }

 private:
  gpu::LabelDrawParams params(graph::Extent viewport) const;

  std::optional<Image> atlas_;
  std::optional<Image> images_;
  graph::ResourceId atlas_id_ = 0, images_id_ = 0;  // as imported into the graph last built
  ComputePipeline ghost_pipeline_;
  ComputePipeline anchor_cover_;
  ComputePipeline draw_;
  ComputePipeline composite_;
  GhostSettings ghost_;
  uint32_t layer_count_ = 0;
  uint32_t label_count_ = LABEL_MAX;
  Background background_;
  bool layer_frames_ = false;
  bool marks_ = true;
};

// What the CPU reference draws: the contents of the three buffers.
struct LabelDrawData {
  std::span<const gpu::LabelGpu> labels;
  std::span<const gpu::PlacementGpu> placements;
  std::span<const gpu::GlyphGpu> glyphs;
  bool layer_frames = false;  // as LabelDrawing::set_layer_frames
  // What hides each label's anchor (anchor_cover_reference); none: every anchor is seen.
  std::span<const gpu::AnchorCoverGpu> covers = {};
  bool connector_halos = false;  // as connector_halos() of LabelDrawing's background
};

// labels.draw on the CPU. `layers` holds layer_count images of `size`, layer after layer, rows
// top to bottom (as the array image downloads); the result has the same shape, rounded to half
// precision as the GPU's rgba16f layers store it.
std::vector<glm::vec4> draw_labels_reference(std::span<const glm::vec4> layers, graph::Extent size,
                                             uint32_t layer_count, const LabelDrawData& data,
                                             const FontAtlas& font, const ImageAtlas& images = {});

// labels.anchor_cover on the CPU: for each label, the composited alpha of the layers in front of
// its own at the pixel of its anchor and how hidden the anchor is (0 outside the image). `depth`:
// the depth image, a float per pixel; `frame`: the layer splits, near plane, step and depth_alpha.
std::vector<gpu::AnchorCoverGpu> anchor_cover_reference(std::span<const glm::vec4> layers,
                                                        std::span<const float> depth,
                                                        graph::Extent size, uint32_t layer_count,
                                                        const gpu::FrameGpu& frame,
                                                        std::span<const gpu::LabelGpu> labels);

// labels.ghost on the CPU: the layers (shaped as for draw_labels_reference) with ghosting
// applied, rounded to half precision.
std::vector<glm::vec4> ghost_reference(std::span<const glm::vec4> layers, graph::Extent size,
                                       uint32_t layer_count, const LabelDrawData& data,
                                       const GhostSettings& ghost);

// labels.composite on the CPU: rgba8 (straight alpha), rows top to bottom, with the rear labels'
// connectors and anchors drawn again where the layers in front hide them (label_behind).
std::vector<uint8_t> composite_reference(std::span<const glm::vec4> layers, graph::Extent size,
                                         uint32_t layer_count, const Background& background,
                                         const LabelDrawData& data);

}  // namespace strata
