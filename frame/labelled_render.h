// strata's main job: a scene rendered into depth layers, its labels layered (k-means++ on anchor
// depth), placed on the GPU layer by layer in insertion order, drawn on their layers, and the
// layers composited into the labelled image. One frame, one command buffer, no CPU round trip
// inside it; the placements come back after the frame.
#pragma once

#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "engine/core/font.h"
#include "engine/scene/scene.h"
#include "frame/label_slots.h"
#include "frame/placement_beside.h"
#include "labeling/annotations.h"
#include "labeling/layering.h"
#include "labeling/text_layout.h"
#include "passes/label_forces.h"
#include "passes/picking.h"
#include "passes/placement.h"
#include "passes/volume_renderer.h"

namespace strata {

// The order labels are placed in within a layer (thesis 3.2.3).
enum class InsertionOrder {
  scene,       // the scene's order
  apollonius,  // Stein & Decoret: innermost first (needs the label-free image: a first frame)
  optimized,   // random orders, each kept when its total cost is lower (offline, several frames)
};

// Ghosting (shared/ghost.h): the layers in front of each shown rear label opened around its
// anchor; sizes are shares of the picture's shorter side.
struct Ghosting {
  float strength = 1.0f;  // 0: off, 1: fully open at an anchor (the default)
  float radius = 0.1f;    // the lens around an anchor
  float leader = 0.0f;    // the lens along a connector (0: none)
};

struct LabellingSettings {
  uint32_t layer_count = 4;  // asked for; fewer when the anchors have fewer distinct depths
  InsertionOrder order = InsertionOrder::scene;
  uint32_t optimize_tries = 8;  // InsertionOrder::optimized: random orders tried
  PlacementSettings placement;
  // How the placement is dispatched (speed and benchmarks only).
  PlacementLayout placement_layout;
  ForceSettings forces;        // how drawn positions follow the placement from frame to frame
  LayerHysteresis hysteresis;  // how labels keep their layers while the camera moves
  bool internal = false;       // internal labelling: every label drawn on its anchor
  float font_pixels = 14.0f;
  float label_scale = 1.0f;  // text and box sizes times this (--label-scale; HiDPI displays)
  // Pixels (before the scale) past which a line of label text wraps at a space; 0: never.
  float wrap_width = 240.0f;
  bool layer_colors = false;  // label borders in their layer's colour (the thesis's depth cue)
  Ghosting ghost;
  // false: the labels are placed, ghost the layers and are measured, but not drawn into the
  // picture (a vector file draws them over it: frame/vector_picture.h).
  bool marks = true;
  // Label slots kept free beyond the scene's labels (frame/label_slots.h): labels added later
  // (labels_changed) fill them without new buffers or a new graph; the viewer keeps some.
  uint32_t spare_label_slots = 0;
  uint64_t seed = 1;      // k-means++
  RenderSettings render;  // its layer_count and splits come from the layering
  // The picture's, under the labels' composite; the placement reads the scene over
  // render.background (black), so a layout is the same on any picture background.
  Background background;
  // A title's and a legend's boxes drawn over the picture after the frame
  // (labeling/annotation_drawing.h), recorded in every frame's layout; the labels keep off them
  // through placement.keep_out.
  std::vector<NamedBox> annotations;
};

// A layer image array (rgba16f, premultiplied) read back after the frame: layer after layer.
std::vector<glm::vec4> download_layer_images(graph::GraphRunner& runner, graph::ResourceId layers);

// One label of the result, for --layout and for tests.
struct LabelLayout {
  int id = 0;
  std::string text;
  std::string image;  // the picture's file, as the scene resolved it; empty: none
  uint32_t layer = 0;
  glm::vec2 anchor{0.0f};  // pixels
  glm::vec2 box_origin{0.0f};
  glm::vec2 box_size{0.0f};
  bool placed = false;  // the placement shows it (a position was found)
  // Share of its box a viewer sees: inside the image, not behind content (label_visibility);
  // NaN where it was not measured (the viewer's frames, result(false)).
  float visible = std::numeric_limits<float>::quiet_NaN();
  bool shown = false;  // placed and legible: visible >= kLegibleShare (placed, when not measured)
  float cost = 0.0f;
  float opacity = 0.0f;  // as drawn: the forces fade it from 0 (hidden) to 1 (fully drawn)
  // The alpha the volume's layers in front of the label's own composite to at its anchor (what
  // hides the anchor; ghosting lowers it; labels drawn over it do not count): labels.anchor_cover;
  // NaN where it was not measured, 0 on the front layer.
  float front_alpha = std::numeric_limits<float>::quiet_NaN();
  // Whether its anchor is hidden (the picture as drawn is opaque in front of it: anchor_hidden in
  // shaders/shared/label_drawing.h); the connector is then drawn dashed, the anchor's mark
  // hollow. None where it was not measured, as front_alpha.
  std::optional<bool> anchor_hidden;
  // The same as the drawing mixes it, 0 (seen) to 1 (hidden): AnchorCoverGpu::hidden; NaN where
  // it was not measured.
  float hidden = std::numeric_limits<float>::quiet_NaN();
  // The top-left corner of the placement's box this frame, where the label is heading (its size
  // is box_size); none where the placement did not place it.
  std::optional<glm::vec2> target_origin;
};

// A label counts as shown when at least this share of its box is visible (label_visibility).
inline constexpr float kLegibleShare = LEGIBLE_SHARE;
// A box pixel is hidden when the layers in front of the label's composite to at least this alpha.
inline constexpr float kHidingAlpha = HIDING_ALPHA;

// The visible share of each label's box: its pixels inside the image where the layers in front
// of the label's own (drawn labels included) composite to less than kHidingAlpha. `layers`:
// layer_count premultiplied images of `size`, layer after layer, as the labelled frame leaves
// them. Labels not placed get 0.
std::vector<float> label_visibility(std::span<const glm::vec4> layers, graph::Extent size,
                                    uint32_t layer_count, std::span<const LabelLayout> labels);

struct LabelledFrame {
  graph::Extent size;
  // The time step since the last frame of an animation (LabelledRenderer::advance,
  // prepare_frame); none for a still (run).
  std::optional<double> seconds;
  std::vector<uint8_t> image;  // rgba8, the labelled picture
  std::vector<LabelLayout> labels;
  std::vector<NamedBox> annotations;  // LabellingSettings::annotations
  Layering layering;
  RenderStats render_stats;
  std::vector<graph::PassTiming> timings;
};

// Labels in placement order: by priority, highest first (labels[i]'s is priorities[i]; none
// given: all equal), then layer by layer front to back, inside a layer by `within` (a
// permutation of all label indices). Disabled labels are left out.
std::vector<uint32_t> insertion_order(const std::vector<gpu::LabelGpu>& labels,
                                      const Layering& layering, const std::vector<uint32_t>& within,
                                      std::span<const float> priorities = {});

// Each label's anchor in the image (a label is enabled when its anchor is visible).
std::vector<ProjectedPoint> project_anchors(const Scene& scene, const Camera& camera,
                                            graph::Extent size);

// Everything one labelled frame needs, set up once: renderer, placement, drawing, their graph.
class LabelledRenderer {
 public:
  // What the frame's graph made, for passes that an extension adds after the label drawing.
  struct GraphIds {
    graph::ResourceId labelled;  // rgba8: the labelled picture
    VolumeRenderer::Outputs rendered;
    Placement::Outputs placed;
    graph::ResourceId drawn;  // PlacementGpu[]: where the labels are drawn
    uint32_t layer_count = 1;
    uint32_t label_slots = 1;  // the per-label buffers' length (LabelSlots::count)
    // The placement is in the frame's graph (`placed` is valid), not beside it.
    bool placement_in_frame = true;
  };
  using Extension = std::function<void(graph::Graph&, const GraphIds&)>;

  LabelledRenderer(Context& ctx, const Scene& scene, const Camera& camera, graph::Extent size,
                   const LabellingSettings& settings);
  ~LabelledRenderer();

  // A still, waited for: the labels put on their placement; re-rendered while the HA-Buffer
  // overflows (it grows each time). The Apollonius and optimised orders take more frames: they
  // need a frame's image or costs, read between frames, never inside one; `progress` hears of
  // each order tried (done, total) when there are several.
  void run(const std::function<void(uint32_t done, uint32_t total)>& progress = {});
  // Moves the camera: anchors, layering and the renderer's layers follow; the labels' drawn
  // positions stay on the GPU for the forces of the next frames.
  void set_camera(const Camera& camera);
  // One frame of an animation, `seconds` after the last: placement, then the forces move the
  // drawn positions toward it (a label seen for the first time starts on its placement).
  void advance(double seconds);
  graph::GraphRunner& runner() { return *runner_; }

  // The interactive viewer's frames (app/view_command.cpp). `extend` ends the graph instead of
  // the headless readback of the picture (the viewer adds its UI and presents); it is called
  // again whenever the graph is rebuilt (the layer count changed). result() then has no image.
  void set_extension(Extension extend);
  // A new image size (a resized window): the anchors are projected again.
  void set_size(graph::Extent size);
  graph::Extent size() const { return size_; }
  // What the relative lengths of the forces and the placement are in pixels now: the image's
  // width and the label text's size.
  LabelUnits units() const {
    return {float(size_.width), settings_.font_pixels * settings_.label_scale, float(size_.height)};
  }
  const Camera& camera() const { return camera_; }
  // Frames recorded before the earlier ones finished: a readback per frame slot.
  void set_frames_in_flight(uint32_t frames);
  // Frame slot `slot` is free (its last frame finished): the results read from now on are that
  // frame's (a frame or two old), the next frame writes its own into the slot. Reads the
  // renderer's counters (and grows its table when it overflowed); with `read` false (the slot's
  // last frame was another graph's) only the slot is chosen.
  void use_slot(uint32_t slot, bool read = true);
  // Sets the next frame up, `seconds` after the last, without running it (the caller records
  // runner() into its own command buffer). A trial frame places the labels (in the order given
  // to set_trial_order) but leaves the forces' state as it was (optimisation on idle); beside the
  // frames it starts a trial placement instead (trial_ready() must hold), which the frames never
  // adopt, and the frame is a normal one.
  void prepare_frame(double seconds, bool trial = false);
  // Beside the frames: whether the next frame may start a trial placement (none due or in
  // flight), and whether the one in flight has finished (the next frame takes it up).
  bool trial_ready() const { return beside_ && beside_->idle(); }
  bool trial_finished() const { return beside_ && beside_->trial_finished(); }
  // Beside the frames: the total cost (total_cost()) of the trial placement the last frame
  // prepared took up, once; none where it took none.
  std::optional<double> take_trial_cost() { return std::exchange(trial_cost_, std::nullopt); }
  // The placement beside the frames (frame/placement_beside.h): the viewer's frames render
  // and move the labels toward the newest finished placement without waiting for one; stills,
  // trial frames and run() need it off (the default). Rebuilds the graph.
  void set_placement_beside(bool beside);
  bool placement_beside() const { return beside_ != nullptr; }
  // Beside the frames: the placement's own GPU time of the placement adopted last, and what the
  // frames saw of the placements (started, adopted, frames from a start to its adoption).
  const PlacementBeside* beside() const { return beside_.get(); }
  // Beside the frames: no new placement starts while paused (the interactive viewer's camera
  // moves); the labels keep heading for the last one's targets, which follow their anchors.
  void pause_placement(bool paused) {
    if (beside_) beside_->set_paused(paused);
  }
  // Beside the frames: a change the next placement must see (set_camera says it itself).
  void placement_due() {
    if (beside_) beside_->set_due();
  }
  // The frames prepared so far (from 1), and the one whose placement the labels head for now
  // (each frame's own without the placement beside).
  uint64_t frame_number() const { return frame_number_; }
  uint64_t placed_frame_number() const;
  // The order inside each layer (a permutation of the label indices): trial frames place the
  // labels in the trial order, the other frames in the one set last (the scene's after
  // set_camera).
  void set_trial_order(const std::vector<uint32_t>& within) { trial_within_ = within; }
  void set_order(const std::vector<uint32_t>& within) { within_ = within; }
  // The next frame places the labels afresh: no hold, no eta toward the last targets (after a
  // change of the settings); the forces still move them there.
  void place_afresh() { afresh_ = true; }

  // Live settings: placement weights, forces, internal labelling and the layer count take effect
  // with the next set_camera(); the renderer's own settings through renderer().
  LabellingSettings& settings() { return settings_; }
  VolumeRenderer& renderer();
  // The scene's labels changed (added, removed, moved or given new text: the viewer's own
  // labels). Where they fit the label slots, the next frame takes them without waiting: new
  // glyphs are bound into the graph, the labels kept keep where they are drawn, a new one
  // appears on its placement. Else the placement, forces and drawing are made again for them
  // around the uploaded volumes (a wait for the frames in flight, a new graph) and every label
  // starts on its new placement.
  void labels_changed();
  // Hides label `index` (of the scene's labels) from the layering, placement and drawing (the
  // anchors are layered again, as by set_camera).
  void set_label_hidden(size_t index, bool hidden);
  bool label_hidden(size_t index) const { return hidden_.at(index); }
  // Labels (by scene index; true: withheld) the placement leaves out from the next frame on, as
  // if it found no place for them: drawn ones fade out where they are (a planned video's ranges,
  // labeling/video_plan.h).
  void set_withheld(std::vector<bool> withheld) { withheld_ = std::move(withheld); }
  // The label font's size in pixels, and the scale of text and boxes (HiDPI, --label-scale):
  // rebuild the glyphs, box sizes and the graph.
  void set_font_pixels(float pixels);
  void set_label_scale(float scale);
  const Layering& layering() const { return layering_; }
  const std::vector<gpu::LabelGpu>& labels() const { return labels_; }
  const RenderStats& stats() const { return stats_; }
  graph::ResourceId labelled_image() const { return labelled_id_; }
  // The last completed frame's (of the current slot) placements and drawn positions, per label.
  std::vector<gpu::PlacementGpu> placement_results() const;
  std::vector<gpu::PlacementGpu> drawn() const;
  // The per-label buffers' slots (frame/label_slots.h): the graph was built for count().
  const LabelSlots& label_slots() const { return slots_; }
  // Stein & Decoret's order inside each layer, from the last frame's layers (downloads them:
  // nothing may be in flight).
  std::vector<uint32_t> apollonius_layers_order();
  // Labels the next frame places (the enabled ones).
  size_t placement_order_count() const;

  // The placement's resources and its label loop's pass: the baseline benchmark reads the
  // per-label results after each label, and the buckets give its tile statistics.
  const Placement::Outputs& placement() const { return placed_; }
  // The placement's pipelines and what the driver reports of each (benchmark output).
  std::vector<PipelineReport> placement_pipelines() const;
  // The picture (none with an extension) and layout of the last run; without an extension also
  // each label's visible share (measure_visibility: the layers are downloaded and read).
  LabelledFrame result(bool measure_visibility = true) const;
  // Eq. 3.2 of the last frame's placement: the sum of the shown labels' costs (without the hold),
  // a hidden label counting as much as an anchor-constraint violation.
  double total_cost() const;

  // Picking (passes/picking.h) without waiting (the viewer's clicks; frames with an extension): the
  // pixels asked go into the next frame prepared and their points come back with that frame's slot
  // (use_slot); take_picks() hands over those come back since, in the order asked.
  void request_pick(glm::vec2 pixel);
  std::vector<PickHit> take_picks();
  size_t picks_pending() const;

  // The label-free layer images of the last frame (premultiplied rgba, layer after layer, each
  // size.width x size.height), waited for.
  std::vector<glm::vec4> download_layers() const;

 private:
  struct Parts;
  Context& ctx_;
  const Scene& scene_;
  graph::Extent size_;
  Layering layering_;
  std::vector<gpu::LabelGpu> labels_;
  std::unique_ptr<Parts> parts_;
  std::unique_ptr<graph::GraphRunner> runner_;
  std::unique_ptr<PlacementBeside> beside_;
  LabelSlots slots_;
  uint64_t frame_number_ = 0;
  // The labels as the GPU's buffers hold them: each in its slot, disabled ones in the others.
  std::vector<gpu::LabelGpu> slot_labels() const;
  // Glyphs and atlases replaced while frames in flight may still read them: kept until
  // frame `until` is prepared.
  struct Retired {
    uint64_t until = 0;
    Buffer glyphs;
    std::vector<Image> images;
  };
  std::vector<Retired> retired_;
  void release_retired(bool all);
  std::optional<Font> font_;  // the label font at settings_.font_pixels * label_scale
  FontAtlas font_atlas_;      // the glyphs the drawing has (kept while they cover the texts)
  ImageAtlas image_atlas_;    // the labels' pictures the drawing has
  ShapedTexts shaped_;        // the label texts shaped so far (font_ and the style)
  graph::ResourceId glyphs_id_ = 0;
  void run_frame();
  // The frame's placement and forces: in the frame's graph, or beside it.
  LabelForces::Outputs add_placement_in_frame(graph::Graph& graph,
                                              const VolumeRenderer::Outputs& rendered,
                                              graph::ResourceId& labels);
  LabelForces::Outputs add_placement_beside(graph::Graph& graph,
                                            const VolumeRenderer::Outputs& rendered,
                                            graph::ResourceId& labels);
  void project_and_layer(const Camera& camera);
  void build_graph();
  void add_pick_readback(graph::Graph& graph);
  void set_placement_frame(bool moving, const std::vector<uint32_t>& within);
  std::vector<uint32_t> within_;  // the order inside each layer set_order() was last given
  std::vector<uint32_t> trial_within_;
  std::optional<double> trial_cost_;  // take_trial_cost()
  bool afresh_ = false;
  // set_camera was called since the last frame: the placement keeps its edge margin (a camera at
  // rest lets the labels settle where a still would put them).
  bool camera_moved_ = false;
  std::optional<double> frame_seconds_;  // of the last frame set up; none: a still
  void drop_runner();
  void build_labels();  // glyphs and box sizes from the texts at settings_.font_pixels
  void set_label_text(float pixels, float scale);
  Extension extension_;
  uint32_t frames_in_flight_ = 1;
  std::vector<bool> hidden_;
  std::vector<bool> withheld_;
  std::vector<int> label_ids_;  // the scene's label ids when its labels were last taken
  void take_scene_labels();
  std::vector<float> priorities_;  // the scene's, per label
  Camera camera_;
  graph::ResourceId labelled_id_ = 0;

  RenderStats stats_;
  Placement::Outputs placed_{};
  graph::ResourceId layers_id_ = 0;
  graph::ResourceId covers_id_ = 0;       // labels.anchor_cover
  graph::ResourceId picks_id_ = 0;        // picking.points
  std::vector<glm::vec2> pick_requests_;  // asked, in no frame yet
  // Per frame slot: the pixels its frame picks (request_pick), and the points come back.
  std::vector<std::vector<glm::vec2>> picks_in_slot_;
  std::vector<PickHit> picks_done_;
  uint32_t slot_ = 0;          // the frame slot use_slot() chose last
  uint32_t graph_layers_ = 0;  // the layer count the graph was built for
  bool graph_ghost_ = false;   // the graph has the ghosting pass (LabellingSettings::ghost)
  LabellingSettings settings_;
};

// The label text's style for `settings`: wrapped at its wrap width, every length times its scale.
TextStyle label_text_style(const LabellingSettings& settings);

// Throws Error unless the font size (4..128 px) and label scale (0.25..4) are in range.
void check_label_text(float font_pixels, float label_scale);

// Renders and labels one frame offline.
LabelledFrame render_labelled(Context& ctx, const Scene& scene, const Camera& camera,
                              graph::Extent size, const LabellingSettings& settings);

// The layout as JSON (docs/layout-metrics.md): the frame's size and seconds, and per label id,
// text, layer, anchor, box (x, y, width, height), shown, placed, visible, cost, opacity, target;
// and the annotations' boxes (name, box) where the frame has a title or legend.
std::string layout_json(const LabelledFrame& frame);

}  // namespace strata
