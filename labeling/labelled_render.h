// strata's main job: a scene rendered into depth layers, its labels layered (k-means++ on anchor
// depth), placed on the GPU layer by layer in insertion order, drawn on their layers, and the
// layers composited into the labelled image. One frame, one command buffer, no CPU round trip
// inside it; the placements come back after the frame.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engine/core/font.h"
#include "engine/scene/scene.h"
#include "labeling/layering.h"
#include "passes/label_forces.h"
#include "passes/placement.h"
#include "passes/volume_renderer.h"

namespace strata {

// The order labels are placed in within a layer (thesis 3.2.3).
enum class InsertionOrder {
  scene,       // the scene's order
  apollonius,  // Stein & Decoret: innermost first (needs the label-free image: a first frame)
  optimized,   // random orders, each kept when its total cost is lower (offline, several frames)
};

struct LabellingSettings {
  uint32_t layer_count = 4;  // asked for; fewer when the anchors have fewer distinct depths
  InsertionOrder order = InsertionOrder::scene;
  uint32_t optimize_tries = 8;  // InsertionOrder::optimized: random orders tried
  PlacementSettings placement;
  ForceSettings forces;        // how drawn positions follow the placement from frame to frame
  LayerHysteresis hysteresis;  // how labels keep their layers while the camera moves
  bool internal = false;       // internal labelling: every label drawn on its anchor
  float font_pixels = 14.0f;
  uint64_t seed = 1;      // k-means++
  RenderSettings render;  // its layer_count and splits come from the layering
};

// One label of the result, for --layout and for tests.
struct LabelLayout {
  int id = 0;
  std::string text;
  uint32_t layer = 0;
  glm::vec2 anchor{0.0f};  // pixels
  glm::vec2 box_origin{0.0f};
  glm::vec2 box_size{0.0f};
  bool shown = false;
  float cost = 0.0f;
};

struct LabelledFrame {
  graph::Extent size;
  std::vector<uint8_t> image;  // rgba8, the labelled picture
  std::vector<LabelLayout> labels;
  Layering layering;
  RenderStats render_stats;
  std::vector<graph::PassTiming> timings;
};

// Each label's anchor in the image (a label is enabled when its anchor is visible).
std::vector<ProjectedPoint> project_anchors(const Scene& scene, const Camera& camera,
                                            graph::Extent size);

// Everything one labelled frame needs, set up once: renderer, placement, drawing, their graph.
class LabelledRenderer {
 public:
  LabelledRenderer(Context& ctx, const Scene& scene, const Camera& camera, graph::Extent size,
                   const LabellingSettings& settings);
  ~LabelledRenderer();

  // A still, waited for: the labels put on their placement; re-rendered while the HA-Buffer
  // overflows (it grows each time). The Apollonius and optimised orders take more frames: they
  // need a frame's image or costs, read between frames, never inside one.
  void run();
  // Moves the camera: anchors, layering and the renderer's layers follow; the labels' drawn
  // positions stay on the GPU for the forces of the next frames.
  void set_camera(const Camera& camera);
  // One frame of an animation, `seconds` after the last: placement, then the forces move the
  // drawn positions toward it (a label seen for the first time starts on its placement).
  void advance(double seconds);
  graph::GraphRunner& runner() { return *runner_; }
  // The placement's resources and its label loop's pass: the baseline benchmark reads the
  // per-label results after each label, and the buckets give its tile statistics.
  const Placement::Outputs& placement() const { return placed_; }
  // The placement's pipelines and what the driver reports of each (benchmark output).
  std::vector<PipelineReport> placement_pipelines() const;
  // The picture and layout of the last run.
  LabelledFrame result() const;
  // Eq. 3.2 of the last frame's placement: the sum of the shown labels' costs (without the hold),
  // a hidden label counting as much as an anchor-constraint violation.
  double total_cost() const;

 private:
  struct Parts;
  Context& ctx_;
  const Scene& scene_;
  graph::Extent size_;
  Layering layering_;
  std::vector<gpu::LabelGpu> labels_;
  std::unique_ptr<Parts> parts_;
  std::unique_ptr<graph::GraphRunner> runner_;
  void run_frame();
  void project_and_layer(const Camera& camera);
  void build_graph();
  void set_order(const std::vector<uint32_t>& within);
  void set_placement_frame(bool moving);
  std::vector<uint32_t> within_;  // the order inside each layer set_order() was last given
  std::vector<uint32_t> apollonius_layers_order();

  RenderStats stats_;
  Placement::Outputs placed_{};
  graph::ResourceId layers_id_ = 0;
  uint32_t graph_layers_ = 0;  // the layer count the graph was built for
  LabellingSettings settings_;
};

// Renders and labels one frame offline.
LabelledFrame render_labelled(Context& ctx, const Scene& scene, const Camera& camera,
                              graph::Extent size, const LabellingSettings& settings);

// The layout as JSON: per label id, text, layer, anchor, box (x, y, width, height), shown, cost.
std::string layout_json(const LabelledFrame& frame);

}  // namespace strata
