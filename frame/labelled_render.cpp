#include "frame/labelled_render.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <future>
#include <optional>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>
#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "engine/core/json_field.h"
#include "engine/gpu/context.h"
#include "engine/graph/graph_runner.h"
#include "engine/graph/headless_target.h"
#include "labeling/insertion_order.h"
#include "labeling/text_layout.h"
#include "passes/label_drawing.h"
#include "passes/label_forces.h"
#include "passes/picking.h"

namespace strata {

std::vector<uint32_t> insertion_order(const std::vector<gpu::LabelGpu>& labels,
                                      const Layering& layering, const std::vector<uint32_t>& within,
                                      std::span<const float> priorities) {
  std::vector<uint32_t> result;
  for (uint32_t layer = 0; layer < layering.layer_count; ++layer) {
    for (uint32_t i : within) {
      if ((labels[i].flags & LABEL_ENABLED) && labels[i].layer == layer) result.push_back(i);
    }
  }
  if (!priorities.empty()) {
    std::stable_sort(result.begin(), result.end(),
                     [&](uint32_t a, uint32_t b) { return priorities[a] > priorities[b]; });
  }
  return result;
}

std::vector<ProjectedPoint> project_anchors(const Scene& scene, const Camera& camera,
                                            graph::Extent size) {
  std::vector<ProjectedPoint> out;
  for (const Label& label : scene.labels) {
    out.push_back(project(camera, label.anchor, {size.width, size.height}));
  }
  return out;
}

struct LabelledRenderer::Parts {
  Parts(Context& ctx, const Scene& scene, const LabellingSettings& settings, uint32_t label_count)
      : Parts(ctx, scene, settings, label_count,
              std::async(std::launch::async, [&ctx, label_count] {
                return Placement::create_pipelines(ctx, label_count);
              })) {}
  // (the placement's pipelines compile while the renderer prepares the volumes)
  Parts(Context& ctx, const Scene& scene, const LabellingSettings& settings, uint32_t label_count,
        std::future<std::vector<ComputePipeline>> placement_pipelines)
      : renderer(ctx, scene, settings.render),
        placement(ctx, label_count, settings.placement_layout, placement_pipelines.get()),
        forces(ctx, label_count),
        picking(ctx),
        pick_points(ctx, PICK_MAX * sizeof(glm::vec4)),
        target(ctx) {}
  // (the scene's labels changed: a placement, forces and drawing for them around the volumes
  // already uploaded)
  Parts(Context& ctx, Parts& old, const LabellingSettings& settings, uint32_t label_count)
      : renderer(std::move(old.renderer)),
        placement(ctx, label_count, settings.placement_layout,
                  old.placement.take_pipelines(label_count)),
        forces(ctx, label_count, &old.forces),
        picking(ctx, &old.picking),
        pick_points(ctx, PICK_MAX * sizeof(glm::vec4)),
        drawing(std::move(old.drawing)),  // (build_labels gives it new atlases)
        target(ctx) {}
  VolumeRenderer renderer;
  Placement placement;
  LabelForces forces;
  Picking picking;
  graph::Readback pick_points;          // the picked points, per frame slot (request_pick)
  std::optional<LabelDrawing> drawing;  // with the font of its size
  HeadlessTarget target;
  Buffer glyphs;
};

LabelledRenderer::LabelledRenderer(Context& ctx, const Scene& scene, const Camera& camera,
                                   graph::Extent size, const LabellingSettings& settings)
    : ctx_(ctx), scene_(scene), size_(size), camera_(camera), settings_(settings) {
  check_label_text(settings.font_pixels, settings.label_scale);
  take_scene_labels();
  slots_.reset(label_ids_, settings.spare_label_slots, LABEL_MAX);
  project_and_layer(camera);
  parts_ = std::make_unique<Parts>(ctx, scene, settings, slots_.count());
  parts_->renderer.set_camera(camera);
  build_labels();
  set_order(scene_order(uint32_t(labels_.size())));
  build_graph();
}

// The scene's labels as the next frames see them: sizes and priorities; a label keeps being
// hidden by hand while its id is in the scene.
void LabelledRenderer::take_scene_labels() {
  std::vector<int> hidden_ids;
  for (size_t i = 0; i < hidden_.size() && i < label_ids_.size(); ++i)
    if (hidden_[i]) hidden_ids.push_back(label_ids_[i]);
  labels_.assign(scene_.labels.size(), gpu::LabelGpu{});
  priorities_.clear();
  label_ids_.clear();
  hidden_.clear();
  for (size_t i = 0; i < scene_.labels.size(); ++i) {
    const Label& label = scene_.labels[i];
    labels_[i].size = label.size;
    priorities_.push_back(label.priority);
    label_ids_.push_back(label.id);
    hidden_.push_back(std::find(hidden_ids.begin(), hidden_ids.end(), label.id) !=
                      hidden_ids.end());
  }
}

void LabelledRenderer::labels_changed() {
  take_scene_labels();
  if (slots_.assign(label_ids_)) {
    project_and_layer(camera_);
    build_labels();
    set_order(scene_order(uint32_t(labels_.size())));
    placement_due();
    if (layering_.layer_count != graph_layers_) build_graph();
    return;
  }
  ctx_.wait_idle("the scene's labels changed");
  const bool beside = beside_ != nullptr;
  drop_runner();
  beside_.reset();
  release_retired(true);
  slots_.reset(label_ids_, settings_.spare_label_slots, LABEL_MAX);
  parts_ = std::make_unique<Parts>(ctx_, *parts_, settings_, slots_.count());
  parts_->renderer.set_camera(camera_);
  project_and_layer(camera_);
  build_labels();
  set_order(scene_order(uint32_t(labels_.size())));
  build_graph();
  if (frames_in_flight_ > 1) set_frames_in_flight(frames_in_flight_);
  if (beside) set_placement_beside(true);
}

// The graph goes (once its frames in flight are done); the copies its next frame would have
// made are made now.
void LabelledRenderer::drop_runner() {
  if (!runner_) return;
  const Uploads uploads = runner_->take_uploads();
  runner_.reset();
  if (!uploads.empty()) ctx_.run_now([&](VkCommandBuffer cmd) { uploads.record(cmd); });
}

TextStyle label_text_style(const LabellingSettings& settings) {
  TextStyle style;
  style.max_width = settings.wrap_width;
  return style.scaled(settings.label_scale);
}

void check_label_text(float font_pixels, float label_scale) {
  if (!(font_pixels >= 4.0f && font_pixels <= 128.0f)) {
    throw Error("label font size must be 4 to 128 px, not " + std::to_string(font_pixels));
  }
  if (!(label_scale >= 0.25f && label_scale <= 4.0f)) {
    throw Error("label scale must be 0.25 to 4, not " + std::to_string(label_scale));
  }
}

// Boxes from the texts: sizes and glyph ranges stay; anchors and layers follow the camera. A
// graph already built is handed the new glyphs, and new atlases where the old ones lack a glyph
// or picture; what it read before stays until the frames in flight that read it are done.
void LabelledRenderer::build_labels() {
  const float scale = settings_.label_scale;
  if (!font_) font_.emplace(settings_.font_pixels * scale);
  const Font& font = *font_;
  const TextStyle style = label_text_style(settings_);
  std::vector<std::string> texts;
  for (const Label& label : scene_.labels) texts.push_back(label.text);
  Parts& p = *parts_;
  const std::vector<GlyphKey> keys = label_glyph_keys(font, texts, style, &shaped_);
  const bool glyphs_kept = p.drawing && std::all_of(keys.begin(), keys.end(), [&](GlyphKey k) {
                             return font_atlas_.glyphs.contains(k);
                           });
  if (!glyphs_kept) font_atlas_ = font.bake(keys);
  LabelImages images = bake_label_images(scene_.labels, scale);
  const bool images_kept = p.drawing && images.atlas.width == image_atlas_.width &&
                           images.atlas.height == image_atlas_.height &&
                           images.atlas.texels == image_atlas_.texels;
  if (!images_kept) image_atlas_ = std::move(images.atlas);
  const std::vector<gpu::GlyphGpu> glyphs =
      build_glyph_buffer(font, font_atlas_, texts, labels_, style, images.blocks, &shaped_);
  Buffer glyph_buffer(ctx_, std::max<size_t>(1, glyphs.size()) * sizeof(gpu::GlyphGpu),
                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::device_local);
  // (a built graph's next frame copies what is new before its passes: no wait here; what is
  // replaced is kept one frame more than the frames in flight, for a copy recorded into the next)
  Uploads uploads;
  Uploads* in_frame = runner_ ? &uploads : nullptr;
  if (in_frame) {
    uploads.add(ctx_, glyph_buffer, as_bytes(glyphs));
  } else if (!glyphs.empty()) {
    upload(ctx_, glyph_buffer, as_bytes(glyphs));
  }
  Retired old{frame_number_ + frames_in_flight_ + 1, std::move(p.glyphs), {}};
  p.glyphs = std::move(glyph_buffer);
  if (!p.drawing) {
    p.drawing.emplace(ctx_, font_atlas_, image_atlas_);
  } else if (!glyphs_kept || !images_kept) {
    old.images = p.drawing->set_atlases(ctx_, font_atlas_, image_atlas_, in_frame);
  }
  retired_.push_back(std::move(old));
  if (in_frame) runner_->upload_in_next_frame(std::move(uploads));
  p.drawing->set_label_count(slots_.used());
  if (runner_) {
    runner_->bind_buffer(glyphs_id_, p.glyphs.handle());
    p.drawing->bind(*runner_);
  }
}

void LabelledRenderer::release_retired(bool all) {
  std::erase_if(retired_, [&](const Retired& r) { return all || r.until <= frame_number_; });
}

std::vector<gpu::LabelGpu> LabelledRenderer::slot_labels() const {
  return slots_.scatter<gpu::LabelGpu>(labels_, gpu::LabelGpu{});
}

void LabelledRenderer::set_font_pixels(float pixels) {
  set_label_text(pixels, settings_.label_scale);
}

void LabelledRenderer::set_label_scale(float scale) {
  set_label_text(settings_.font_pixels, scale);
}

void LabelledRenderer::set_label_text(float pixels, float scale) {
  check_label_text(pixels, scale);
  ctx_.wait_idle("a new label font");  // the glyphs and the drawing's atlas are replaced
  settings_.font_pixels = pixels;
  settings_.label_scale = scale;
  for (size_t i = 0; i < labels_.size(); ++i) labels_[i].size = scene_.labels[i].size;
  drop_runner();
  release_retired(true);
  font_.reset();
  font_atlas_ = {};  // (glyphs of the new size)
  shaped_.clear();
  build_labels();
  build_graph();
}

void LabelledRenderer::set_size(graph::Extent size) {
  if (size == size_) return;
  size_ = size;
  runner_->set_viewport(size);
  set_camera(camera_);
  if (beside_) beside_->build(layering_.layer_count, size_);
}

std::vector<gpu::PlacementGpu> LabelledRenderer::placement_results() const {
  return slots_.gather(parts_->placement.results());
}

std::vector<gpu::PlacementGpu> LabelledRenderer::drawn() const {
  return slots_.gather(parts_->forces.drawn());
}

size_t LabelledRenderer::placement_order_count() const {
  return size_t(std::count_if(labels_.begin(), labels_.end(), [](const gpu::LabelGpu& l) {
    return (l.flags & LABEL_ENABLED) != 0u;
  }));
}

VolumeRenderer& LabelledRenderer::renderer() {
  return parts_->renderer;
}

void LabelledRenderer::set_label_hidden(size_t index, bool hidden) {
  hidden_.at(index) = hidden;
  set_camera(camera_);  // (layering and flags from the anchors again)
}

void LabelledRenderer::set_extension(Extension extend) {
  extension_ = std::move(extend);
  build_graph();
}

void LabelledRenderer::set_frames_in_flight(uint32_t frames) {
  frames_in_flight_ = frames;
  runner_->set_frames_in_flight(frames);
  parts_->renderer.readback().set_slots(frames);
  if (!beside_) parts_->placement.readback().set_slots(frames);
  parts_->forces.readback().set_slots(frames);
  parts_->pick_points.set_slots(frames);
  picks_in_slot_.assign(frames, {});
  use_slot(0);
}

void LabelledRenderer::use_slot(uint32_t slot, bool read) {
  slot_ = slot;
  if (extension_) {
    parts_->pick_points.use_slot(*runner_, slot);
    if (slot < picks_in_slot_.size() && !picks_in_slot_[slot].empty()) {
      for (const PickHit& hit : pick_hits(parts_->pick_points.data(), picks_in_slot_[slot].size()))
        picks_done_.push_back(hit);
      picks_in_slot_[slot].clear();
    }
  }
  parts_->renderer.readback().use_slot(*runner_, slot);
  if (!beside_) parts_->placement.readback().use_slot(*runner_, slot);
  parts_->forces.readback().use_slot(*runner_, slot);
  if (!read) return;
  stats_ = parts_->renderer.collect(*runner_);
  if (stats_.overflow > 0) placement_due();  // (the next frames show what this one missed)
}

void LabelledRenderer::prepare_frame(double seconds, bool trial) {
  const bool trial_order = trial && trial_within_.size() == labels_.size();
  set_placement_frame(true, trial_order ? trial_within_ : within_);
  ForceSettings forces = settings_.forces;
  if (afresh_) forces.hold_share = forces.hold_cost = 0.0f;
  ++frame_number_;
  release_retired(false);
  parts_->forces.set_frame(forces, units(), seconds, settings_.placement.hard,
                           parts_->placement.order_count());
  parts_->forces.set_keep_out(settings_.placement.keep_out);
  if (beside_) {
    beside_->take_trial([this] { trial_cost_ = total_cost(); });
    beside_->set_frame_number(frame_number_);
    // (a placement started now takes this frame's params)
    beside_->prepare(*runner_, slot_labels(), trial);
    parts_->forces.set_order_count(beside_->adopted_order_count());
  }
  parts_->forces.set_trial(trial && !beside_);
  if (extension_) {
    // (the frame picks what was asked since the last; PICK_MAX at a time)
    picks_in_slot_.resize(std::max<size_t>(picks_in_slot_.size(), slot_ + 1));
    const size_t n = std::min<size_t>(pick_requests_.size(), PICK_MAX);
    picks_in_slot_[slot_].assign(pick_requests_.begin(), pick_requests_.begin() + ptrdiff_t(n));
    pick_requests_.erase(pick_requests_.begin(), pick_requests_.begin() + ptrdiff_t(n));
    parts_->picking.set_pixels(picks_in_slot_[slot_]);
  }
  afresh_ = false;
  camera_moved_ = false;
  frame_seconds_ = seconds > 0.0 ? std::optional(seconds) : std::nullopt;  // (0 s: a still)
}

// Layering on the CPU, from the camera alone: k-means++ on the visible anchors' depths, after the
// first frame warm-started from the last one's planes and with hysteresis.
void LabelledRenderer::project_and_layer(const Camera& camera) {
  const std::vector<ProjectedPoint> anchors = project_anchors(scene_, camera, size_);
  // (a label whose anchor a cut-away removes is hidden with what it names)
  std::vector<glm::vec3> points;
  for (const Label& label : scene_.labels) points.push_back(label.anchor);
  const std::vector<bool> cut = anchors_cut_away(scene_, points);
  std::vector<bool> shown(anchors.size());
  for (size_t i = 0; i < anchors.size(); ++i)
    shown[i] = anchors[i].visible && !hidden_[i] && !cut[i];
  std::vector<float> depths;
  for (size_t i = 0; i < anchors.size(); ++i)
    depths.push_back(shown[i] ? anchors[i].eye_depth : std::nanf(""));
  layering_ = follow_layering(layering_, depths, settings_.layer_count, camera.near_plane,
                              camera.far_plane, settings_.hysteresis, settings_.seed);
  for (size_t i = 0; i < labels_.size(); ++i) {
    gpu::LabelGpu& l = labels_[i];
    l.anchor = anchors[i].pixel;
    l.previous = anchors[i].pixel;  // (the GPU's forces state replaces it once drawn)
    l.anchor_depth = anchors[i].eye_depth;
    l.layer = layering_.label_layer[i];
    l.flags = (shown[i] ? LABEL_ENABLED : 0u) | (settings_.internal ? LABEL_INTERNAL : 0u);
  }
}

// The frame's graph: renderer, placement, forces, drawing, readback. Rebuilt only when the
// layering's layer count changes (the layer images are sized by it).
void LabelledRenderer::build_graph() {
  Parts& p = *parts_;
  RenderSettings& render = p.renderer.settings();
  render.layer_count = layering_.layer_count;
  render.splits = layering_.split_depths;
  graph_layers_ = layering_.layer_count;
  graph_ghost_ = settings_.ghost.strength > 0.0f;

  graph::Graph graph;
  const VolumeRenderer::Outputs rendered = p.renderer.add_to(graph);
  graph::ResourceId labels = 0;
  const LabelForces::Outputs moved = beside_ ? add_placement_beside(graph, rendered, labels)
                                             : add_placement_in_frame(graph, rendered, labels);
  // (picks walk the picture as drawn: through the lenses of the labels and their drawn places)
  picks_id_ =
      p.picking.add_to(graph, {.rendered = rendered, .labels = labels, .placements = moved.drawn});
  if (extension_) add_pick_readback(graph);
  layers_id_ = rendered.layers;
  const graph::ResourceId glyph_buffer =
      graph.import_buffer("labels.glyphs", {.buffer = p.glyphs.handle(), .has_content = true});
  glyphs_id_ = glyph_buffer;
  const graph::ResourceId labelled = graph.add_image("labels.final", {VK_FORMAT_R8G8B8A8_UNORM});
  labelled_id_ = labelled;
  // (what hides each anchor: drawn by every frame, read back by offline ones: LabelLayout)
  const uint32_t n = std::max(slots_.count(), 1u);
  covers_id_ = graph.add_buffer("labels.anchor_cover", {[n](graph::Extent) {
                                  return VkDeviceSize{n} * sizeof(gpu::AnchorCoverGpu);
                                }});
  p.drawing->add_to(graph, {.layers = rendered.layers,
                            .layer_count = render.layer_count,
                            .labels = labels,
                            .placements = moved.drawn,
                            .glyphs = glyph_buffer,
                            .output = labelled,
                            .background = settings_.background,
                            .ghost = graph_ghost_,
                            .depth = rendered.depth,
                            .frame = rendered.frame,
                            .covers = covers_id_});
  if (extension_) {
    extension_(graph, {labelled, rendered, placed_, moved.drawn, render.layer_count, slots_.count(),
                       beside_ == nullptr});
  } else {
    p.target.add_output(graph, labelled);
  }
  // (what the old graph's next frame would have copied, the new one copies)
  Uploads uploads = runner_ ? runner_->take_uploads() : Uploads{};
  runner_.reset();  // (waits for its frames in flight)
  // (picks asked in frames of the old graph are asked again)
  for (auto it = picks_in_slot_.rbegin(); it != picks_in_slot_.rend(); ++it) {
    pick_requests_.insert(pick_requests_.begin(), it->begin(), it->end());
    it->clear();
  }
  runner_ = std::make_unique<graph::GraphRunner>(ctx_, std::move(graph));
  runner_->set_viewport(size_);
  if (!extension_) p.target.bind(*runner_);
  if (frames_in_flight_ > 1) runner_->set_frames_in_flight(frames_in_flight_);
  runner_->upload_in_next_frame(std::move(uploads));
  if (beside_) beside_->build(render.layer_count, size_);
}

LabelForces::Outputs LabelledRenderer::add_placement_in_frame(
    graph::Graph& graph, const VolumeRenderer::Outputs& rendered, graph::ResourceId& labels) {
  Parts& p = *parts_;
  const graph::ResourceId state = p.forces.import_state(graph);
  placed_ = p.placement.add_to(
      graph, {.final_image = rendered.final,
              .layers = rendered.layers,
              .layer_count = p.renderer.settings().layer_count,
              .adjust_labels = [&p, state](graph::Graph& g, graph::ResourceId ids) {
                p.forces.add_previous(g, ids, state);
              }});
  labels = placed_.labels;
  return p.forces.add_to(graph, {.labels = placed_.labels,
                                 .targets = placed_.placements,
                                 .state = state,
                                 .order = placed_.order});
}

LabelForces::Outputs LabelledRenderer::add_placement_beside(graph::Graph& graph,
                                                            const VolumeRenderer::Outputs& rendered,
                                                            graph::ResourceId& labels) {
  Parts& p = *parts_;
  const graph::ResourceId state = p.forces.import_state(graph);
  const PlacementBeside::FrameIds ids = beside_->add_to_frame(graph, rendered, state);
  placed_ = {};
  labels = ids.labels;
  const LabelForces::Outputs moved = p.forces.add_to(
      graph, {.labels = ids.labels, .targets = ids.targets, .state = state, .order = ids.order});
  beside_->add_state_snapshot(graph, state);
  return moved;
}

void LabelledRenderer::set_placement_beside(bool beside) {
  if (beside == placement_beside()) return;
  ctx_.wait_idle("the placement moving beside the frames or back");
  drop_runner();
  beside_.reset();
  if (beside) {
    beside_ =
        std::make_unique<PlacementBeside>(ctx_, parts_->placement, parts_->forces, slots_.count());
  } else {
    parts_->placement.readback().set_slots(frames_in_flight_);
  }
  build_graph();
  if (!beside) use_slot(0);
}

uint64_t LabelledRenderer::placed_frame_number() const {
  return beside_ ? beside_->adopted_frame() : frame_number_;
}

// The labels and order of the next frame for the placement: a still with the scene's eta, a frame
// of an animation with the forces' (toward the last targets).
void LabelledRenderer::set_placement_frame(bool moving, const std::vector<uint32_t>& within) {
  PlacementSettings settings = settings_.placement;
  settings.text_pixels = units().em;
  const float side = float(std::min(size_.width, size_.height));
  settings.ghost_strength = settings_.ghost.strength;
  settings.ghost_radius = settings_.ghost.radius * side;
  if (moving && !afresh_) settings.weights.previous_position = settings_.forces.previous_weight;
  // While the camera moves, kept-apart labels keep room to slide along the image's edge.
  if (moving && camera_moved_ && settings_.forces.keep_apart) settings.edge_em = settings.margin_em;
  std::vector<uint32_t> order = insertion_order(labels_, layering_, within, priorities_);
  std::erase_if(order, [this](uint32_t i) { return i < withheld_.size() && withheld_[i]; });
  // (the rounds decide a priority's labels only once every higher priority's are decided)
  std::vector<uint32_t> group_first(order.size(), 0);
  const auto priority = [this](uint32_t i) {
    return i < priorities_.size() ? priorities_[i] : 0.0f;
  };
  for (uint32_t s = 1; s < order.size(); ++s) {
    group_first[s] = priority(order[s]) == priority(order[s - 1]) ? group_first[s - 1] : s;
  }
  parts_->placement.set_frame(slot_labels(), slots_.to_slots(order), settings, slots_.used(),
                              group_first);
  parts_->forces.set_active(slots_.used());
  parts_->drawing->set_layer_frames(settings_.layer_colors);
  parts_->drawing->set_marks(settings_.marks);
  const GhostSettings ghost{settings_.ghost.strength, settings_.ghost.radius * side,
                            settings_.ghost.leader * side};
  parts_->drawing->set_ghost(ghost);
  parts_->picking.set_ghost(ghost);  // (a pick sees through the lenses drawn)
}

void LabelledRenderer::set_camera(const Camera& camera) {
  camera_ = camera;
  camera_moved_ = true;
  placement_due();
  project_and_layer(camera);
  parts_->renderer.set_camera(camera);
  parts_->renderer.settings().splits = layering_.split_depths;
  set_order(scene_order(uint32_t(labels_.size())));
  if (layering_.layer_count != graph_layers_ || (settings_.ghost.strength > 0.0f) != graph_ghost_)
    build_graph();
}

void LabelledRenderer::advance(double seconds) {
  prepare_frame(seconds);
  run_frame();
}

void LabelledRenderer::add_pick_readback(graph::Graph& graph) {
  const graph::ResourceId readback = parts_->pick_points.import(graph, "picking.readback");
  const graph::ResourceId points = picks_id_;
  graph.add_pass({"picking.readback",
                  graph::PassKind::transfer,
                  {{points, graph::Use::transfer_src}, {readback, graph::Use::transfer_dst}},
                  [this, points, readback](graph::PassContext& pc) {
                    if (parts_->picking.pixels().empty()) return;
                    pc.copy_buffer(points, readback, parts_->pick_points.size());
                  },
                  "picking"});
}

void LabelledRenderer::request_pick(glm::vec2 pixel) {
  pick_requests_.push_back(pixel);
}

std::vector<PickHit> LabelledRenderer::take_picks() {
  return std::exchange(picks_done_, {});
}

size_t LabelledRenderer::picks_pending() const {
  size_t n = pick_requests_.size();
  for (const auto& slot : picks_in_slot_) n += slot.size();
  return n;
}

LabelledRenderer::~LabelledRenderer() = default;

std::vector<PipelineReport> LabelledRenderer::placement_pipelines() const {
  return parts_->placement.pipeline_statistics();
}

void LabelledRenderer::run_frame() {
  if (beside_) throw Error("a still needs the placement in the frame (set_placement_beside)");
  release_retired(true);  // (run_now: no frame is in flight)
  stats_ = parts_->renderer.run_until_no_overflow(*runner_);
}

// Stein & Decoret's order inside each layer, from the first frame's image: occupancy is the
// alpha of all layers composited (drawn labels are only added later in the frame).
std::vector<uint32_t> LabelledRenderer::apollonius_layers_order() {
  const std::vector<glm::vec4> layers = download_layers();
  const size_t pixels = size_t{size_.width} * size_.height;
  std::vector<float> occupancy(pixels, 0.0f);
  for (uint32_t l = 0; l < layering_.layer_count; ++l) {
    for (size_t p = 0; p < pixels; ++p) {
      occupancy[p] += (1.0f - occupancy[p]) * layers[l * pixels + p].a;
    }
  }
  std::vector<glm::vec2> anchors;
  for (const auto& l : labels_) anchors.push_back(l.anchor);
  return apollonius_order(anchors, occupancy, size_.width, size_.height);
}

double LabelledRenderer::total_cost() const {
  double total = 0.0;
  const std::vector<gpu::PlacementGpu> results = placement_results();
  for (size_t i = 0; i < labels_.size(); ++i) {
    if ((labels_[i].flags & LABEL_ENABLED) == 0u) continue;
    total += results[i].shown == PLACEMENT_SHOWN
                 ? double(results[i].cost)
                 : double(settings_.placement.weights.anchor_constraint);
  }
  return total;
}

void LabelledRenderer::run(const std::function<void(uint32_t done, uint32_t total)>& progress) {
  // A still: every frame puts the labels on their placement (the forces start afresh).
  const auto run_still = [this] {
    set_placement_frame(false, within_);
    parts_->forces.reset();
    parts_->forces.set_keep_out(settings_.placement.keep_out);
    parts_->forces.set_frame(settings_.forces, units(), 0.0, settings_.placement.hard);
    frame_seconds_.reset();
    run_frame();
  };
  set_order(scene_order(uint32_t(labels_.size())));
  run_still();
  if (settings_.order == InsertionOrder::apollonius) {
    set_order(apollonius_layers_order());
    run_still();
  } else if (settings_.order == InsertionOrder::optimized) {
    std::vector<uint32_t> best = scene_order(uint32_t(labels_.size()));
    double best_cost = total_cost();
    for (uint32_t t = 0; t < settings_.optimize_tries; ++t) {
      const std::vector<uint32_t> candidate =
          random_order(uint32_t(labels_.size()), settings_.seed + t + 1);
      set_order(candidate);
      run_still();
      const double cost = total_cost();
      if (cost < best_cost) {
        best_cost = cost;
        best = candidate;
      }
      if (progress) progress(t + 1, settings_.optimize_tries);
    }
    set_order(best);
    run_still();
  }
}

// The layer images of the last frame (rgba16f, layer after layer), waited for.
std::vector<glm::vec4> download_layer_images(graph::GraphRunner& runner, graph::ResourceId layers) {
  const std::vector<std::byte> bytes = runner.download_image(layers);
  std::vector<glm::vec4> out(bytes.size() / sizeof(uint64_t));
  for (size_t i = 0; i < out.size(); ++i) {
    uint64_t half4 = 0;
    std::memcpy(&half4, bytes.data() + i * sizeof(uint64_t), sizeof half4);
    out[i] = glm::unpackHalf4x16(half4);
  }
  return out;
}

std::vector<glm::vec4> LabelledRenderer::download_layers() const {
  return download_layer_images(*runner_, layers_id_);
}

LabelledFrame LabelledRenderer::result(bool measure_visibility) const {
  LabelledFrame frame;
  frame.size = size_;
  frame.seconds = frame_seconds_;
  frame.layering = layering_;
  frame.annotations = settings_.annotations;
  frame.render_stats = stats_;
  frame.timings = runner_->timings();
  if (!extension_) {
    const auto pixels = parts_->target.pixels();
    frame.image.assign(pixels.begin(), pixels.end());
  }
  const std::vector<gpu::PlacementGpu> results = placement_results();
  const std::vector<gpu::PlacementGpu> drawn = this->drawn();
  for (size_t i = 0; i < labels_.size(); ++i) {
    LabelLayout l;
    l.id = scene_.labels[i].id;
    l.text = scene_.labels[i].text;
    if (const auto& image = scene_.labels[i].image) l.image = image->file.string();
    l.layer = labels_[i].layer;
    l.anchor = labels_[i].anchor;
    l.box_size = labels_[i].size;
    l.box_origin = drawn[i].position - labels_[i].size * 0.5f;
    l.placed = drawn[i].shown == PLACEMENT_SHOWN;
    l.opacity = drawn[i].opacity;
    if ((labels_[i].flags & LABEL_ENABLED) != 0u && results[i].shown == PLACEMENT_SHOWN) {
      l.target_origin = results[i].position - labels_[i].size * 0.5f;
    }
    l.cost = results[i].cost;
    frame.labels.push_back(l);
  }
  // Offline (no extension, nothing in flight): what the picture really shows of each box.
  if (measure_visibility && !extension_) {
    const std::vector<glm::vec4> layers = download_layers();
    const std::vector<float> visible =
        label_visibility(layers, size_, layering_.layer_count, frame.labels);
    const std::vector<std::byte> covers = runner_->download_buffer(covers_id_);
    for (size_t i = 0; i < frame.labels.size(); ++i) {
      gpu::AnchorCoverGpu cover;
      std::memcpy(&cover, covers.data() + slots_.of(i) * sizeof(cover), sizeof(cover));
      frame.labels[i].visible = visible[i];
      frame.labels[i].front_alpha = cover.front_alpha;
      frame.labels[i].anchor_hidden = cover.hidden >= gpu::LABEL_HIDDEN_AT;
      frame.labels[i].hidden = cover.hidden;
    }
  }
  for (LabelLayout& l : frame.labels) {
    l.shown = l.placed && (std::isnan(l.visible) || l.visible >= kLegibleShare);
  }
  return frame;
}

std::vector<float> label_visibility(std::span<const glm::vec4> layers, graph::Extent size,
                                    uint32_t layer_count, std::span<const LabelLayout> labels) {
  const size_t pixels = size_t{size.width} * size.height;
  if (layers.size() != pixels * layer_count) {
    throw Error("label visibility: " + std::to_string(layers.size()) + " layer pixels for " +
                std::to_string(layer_count) + " layers of " + std::to_string(size.width) + "x" +
                std::to_string(size.height));
  }
  std::vector<float> out;
  for (const LabelLayout& l : labels) {
    const int x0 = int(std::floor(l.box_origin.x)), y0 = int(std::floor(l.box_origin.y));
    const int w = int(std::lround(l.box_size.x)), h = int(std::lround(l.box_size.y));
    if (!l.placed || w <= 0 || h <= 0) {
      out.push_back(0.0f);
      continue;
    }
    size_t seen = 0;
    for (int y = y0; y < y0 + h; ++y) {
      for (int x = x0; x < x0 + w; ++x) {
        if (x < 0 || y < 0 || x >= int(size.width) || y >= int(size.height)) continue;
        const size_t p = size_t(y) * size.width + size_t(x);
        float front = 0.0f;
        for (uint32_t k = 0; k < std::min(l.layer, layer_count); ++k) {
          front += (1.0f - front) * layers[k * pixels + p].a;
        }
        if (front < kHidingAlpha) ++seen;
      }
    }
    out.push_back(float(seen) / float(size_t(w) * size_t(h)));
  }
  return out;
}

LabelledFrame render_labelled(Context& ctx, const Scene& scene, const Camera& camera,
                              graph::Extent size, const LabellingSettings& settings) {
  LabelledRenderer renderer(ctx, scene, camera, size, settings);
  renderer.run();
  return renderer.result();
}

std::string layout_json(const LabelledFrame& frame) {
  using ordered_json = nlohmann::ordered_json;
  ordered_json labels = ordered_json::array();
  for (const LabelLayout& l : frame.labels) {
    const ordered_json anchor_hidden =
        l.anchor_hidden ? ordered_json(*l.anchor_hidden) : ordered_json();  // (null: not measured)
    ordered_json entry = {{"id", l.id},
                          {"text", l.text},
                          {"layer", l.layer},
                          {"anchor", {shortest_double(l.anchor.x), shortest_double(l.anchor.y)}},
                          {"box",
                           {shortest_double(l.box_origin.x), shortest_double(l.box_origin.y),
                            shortest_double(l.box_size.x), shortest_double(l.box_size.y)}},
                          {"shown", l.shown},
                          {"placed", l.placed},
                          {"visible", shortest_double(l.visible)},
                          {"cost", shortest_double(l.cost)},
                          {"opacity", shortest_double(l.opacity)},
                          {"front_alpha", shortest_double(l.front_alpha)},
                          {"anchor_hidden", anchor_hidden},
                          {"target", ordered_json()}};
    if (const auto& t = l.target_origin) {
      entry["target"] = {shortest_double(t->x), shortest_double(t->y),
                         shortest_double(l.box_size.x), shortest_double(l.box_size.y)};
    }
    if (!l.image.empty()) entry["image"] = l.image;
    labels.push_back(std::move(entry));
  }
  ordered_json seconds;  // (null: a still)
  if (frame.seconds) seconds = *frame.seconds;
  ordered_json layout = {{"width", frame.size.width},
                         {"height", frame.size.height},
                         {"seconds", seconds},
                         {"labels", labels}};
  if (!frame.annotations.empty()) {
    ordered_json annotations = ordered_json::array();
    for (const NamedBox& a : frame.annotations) {
      annotations.push_back(
          {{"name", a.name},
           {"box",
            {shortest_double(a.rect.x), shortest_double(a.rect.y),
             shortest_double(a.rect.z - a.rect.x), shortest_double(a.rect.w - a.rect.y)}}});
    }
    layout["annotations"] = std::move(annotations);
  }
  // Label texts come from scene files: bytes that are not UTF-8 are replaced, never thrown on.
  return layout.dump(2, ' ', false, ordered_json::error_handler_t::replace) + "\n";
}

}  // namespace strata
