#include "app/viewer/viewer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "app/viewer/frame_clock.h"
#include "app/viewer/script_run.h"
#include "engine/core/error.h"
#include "engine/gpu/context.h"
#include "engine/gpu/vulkan_check.h"

namespace strata::app {
namespace {

constexpr double kMaxStep = 0.25;          // a frame's time step at most (slow devices)
constexpr double kPlotSeconds = 5.0;       // the timing plots' span
// Label slots beyond the scene's: this many labels of one's own are placed without a new graph.
constexpr uint32_t kSpareLabelSlots = 64;

}  // namespace

bool HeadlessOutput::draw(const WindowTarget::Prepare& prepare) {
  const uint32_t slot = slots_.next();
  graph::GraphRunner& runner = prepare(slot, size_);
  runner.set_viewport(size_);
  const VkCommandBuffer cmd = slots_.begin(slot);
  runner.record(cmd, slot);
  const graph::FrameSubmission& extra = runner.submission();
  slots_.submit(slot, extra.wait, extra.signal);
  if (extra.submitted) extra.submitted();
  return true;
}

graph::Extent WindowOutput::extent() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  return {uint32_t(std::max(w, 0)), uint32_t(std::max(h, 0))};
}

Viewer::Viewer(Context& ctx, Scene& scene, const Camera& camera, const LabellingSettings& settings,
               const ViewerOptions& options, ViewerOutput& output, GLFWwindow* window)
    : ctx_(ctx),
      scene_(scene),
      options_(options),
      output_(output),
      ui_(ctx, window, options.ui_scale, output.frames_in_flight()),
      control_(scene, camera),
      debug_(ctx),
      applied_camera_(camera),
      last_change_(Clock::now()),
      last_frame_(Clock::now()),
      slots_(output.frames_in_flight()),
      recorder_(ctx, output.frames_in_flight()) {
  graph::Extent size = output.extent();
  if (size.width == 0 || size.height == 0) size = {64, 64};  // (a minimised window: resized later)
  LabellingSettings labelling = settings;
  labelling.render.interactive = options.frame_budget_ms > 0.0;
  labelling.spare_label_slots = kSpareLabelSlots;
  labelled_ = std::make_unique<LabelledRenderer>(ctx, scene, camera, size, labelling);
  labelled_->set_extension([this](graph::Graph& graph, const LabelledRenderer::GraphIds& ids) {
    extend_graph(graph, ids);
  });
  labelled_->set_frames_in_flight(output.frames_in_flight());
  for (const Volume& v : scene.volumes) {
    original_tfs_.push_back(v.transfer_function >= 0 ? scene.transfer_functions[v.transfer_function]
                                                     : TransferFunction{});
  }
  for (const Volume& v : scene.volumes) looks_.push_back(default_look(v));
  const size_t own = scene.labels.size() - std::min(scene.added_labels, scene.labels.size());
  for (size_t i = 0; i < own; ++i) {
    scene_labels_.push_back(
        {.id = scene.labels[i].id, .text = scene.labels[i].text, .anchor = scene.labels[i].anchor});
  }
  for (const Volume& v : scene.volumes) scene_cuts_.push_back(v.cut);
}

Viewer::~Viewer() {
  try {
    output_.wait_idle();
    if (recording()) stop_recording();
  } catch (const std::exception&) {
    // (a lost or hung device, a full disk: the error that ended the run is being reported)
  }
}

// The viewer's end of the frame's graph: the picture (or a debug view) copied into the display
// image, the UI drawn onto it, then the output (the window's present).
void Viewer::extend_graph(graph::Graph& graph, const LabelledRenderer::GraphIds& ids) {
  ++generation_;
  // (beside the frames, the placement's buffers are not in the frame's graph: no debug view)
  const graph::ResourceId debug_image =
      !ids.placement_in_frame ? ids.labelled
                              : debug_.add_to(graph, {.saliency = ids.placed.saliency,
                                                      .costs = ids.placed.costs,
                                                      .labels = ids.placed.labels,
                                                      .placements = ids.placed.placements,
                                                      .order = ids.placed.order,
                                                      .layers = ids.rendered.layers,
                                                      .frame = ids.rendered.frame,
                                                      .keys = ids.rendered.keys,
                                                      .layer_count = ids.layer_count,
                                                      .label_count = ids.label_slots});
  display_id_ = graph.add_image("view.display", {VK_FORMAT_R8G8B8A8_UNORM});
  const graph::ResourceId labelled = ids.labelled, display = display_id_;
  graph.add_pass({"view.copy",
                  graph::PassKind::transfer,
                  {{labelled, graph::Use::transfer_src},
                   {debug_image, graph::Use::transfer_src},
                   {display, graph::Use::transfer_dst}},
                  [this, labelled, debug_image, display](graph::PassContext& pc) {
                    VkImageCopy region{};
                    region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                    region.dstSubresource = region.srcSubresource;
                    region.extent = {pc.viewport.width, pc.viewport.height, 1};
                    const graph::ResourceId from = debug_choice_ ? debug_image : labelled;
                    vkCmdCopyImage(pc.cmd, pc.image(from), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                   pc.image(display), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                                   &region);
                  },
                  "ui"});
  recorder_.add_to(graph, labelled);
  ui_.add_to(graph, display);
  output_.add_to(graph, display);
}

graph::GraphRunner& Viewer::prepare(uint32_t slot, graph::Extent extent, double seconds) {
  if (!(extent == labelled_->size())) {
    labelled_->set_size(extent);
    changed();
  }
  recorder_.slot_free(slot);
  read_slot(slot);
  apply_picks();
  // Stein & Decoret's order needs the picture: computed once the camera rests (a wait for the
  // frames in flight, once per rest).
  if (insertion_order_ == 1 && settled_ && apollonius_serial_ != serial_ && !control_.animating()) {
    output_.wait_idle();
    labelled_->set_order(labelled_->apollonius_layers_order());
    apollonius_serial_ = serial_;
    settled_ = false;
  }
  const bool interactive = options_.frame_budget_ms > 0.0;
  labelled_->set_placement_beside((options_.placement_beside || interactive) && !debug_choice_);
  // (beside the frames, trials are placements of their own, one at a time; those in flight when
  // the placement moves are lost, and the trials start again)
  const bool beside = labelled_->placement_beside();
  if (beside != trials_beside_) optimisation_.restart();
  trials_beside_ = beside;
  const int trial = !beside || labelled_->trial_ready() ? next_trial() : -1;
  if (trial >= 0) labelled_->set_trial_order(optimisation_.order(trial));
  labelled_->prepare_frame(seconds, trial >= 0);
  if (beside) {
    if (const std::optional<double> cost = labelled_->take_trial_cost())
      trial_back(std::exchange(optimisation_.in_flight, -1), *cost);
    if (trial >= 0) optimisation_.in_flight = trial;
  }
  count_placements();
  debug_.set_enabled(debug_choice_.has_value());
  if (debug_choice_) {
    debug_.set(*debug_choice_);
    debug_.set_placement(uint32_t(labelled_->placement_order_count()),
                         labelled_->settings().placement.margin_em * labelled_->units().em);
  }
  slots_[slot] = {generation_, serial_, beside ? -1 : trial,
                  labelled_->renderer().settings().divisor};
  last_slot_ = slot;
  recorder_.frame_in(labelled_->runner(), slot);
  return labelled_->runner();
}

void Viewer::set_habuffer_slots(uint32_t slots) {
  output_.wait_idle();
  labelled_->renderer().set_table_size(slots);
  labelled_->runner().reallocate();
  changed();
}

void Viewer::frame(std::optional<double> step) {
  try {
    draw_frame(step);
  } catch (const DeviceLost& lost) {
    throw DeviceLost("during frame " + std::to_string(summary_.frames + 1) + " (" + lost.when() +
                     ")");
  }
}

void Viewer::apply_submitted() {
  ScriptRun run{.viewer = this};
  for (const ScriptCommand& command : std::exchange(submitted_, {})) {
    try {
      apply_script_command(run, command);
    } catch (const Error& e) {
      message_ = e.what();
      ui_event();
    }
  }
}

void Viewer::draw_frame(std::optional<double> step) {
  const Clock::time_point now = Clock::now();
  double seconds = std::min(seconds_between(last_frame_, now), kMaxStep);
  if (recording()) seconds = 1.0 / options_.record_fps;
  if (step) seconds = *step;
  frame_times_.push_back(float(seconds_between(last_frame_, now) * 1e3));
  last_frame_ = now;
  const size_t plot = size_t(kPlotSeconds * 60.0);
  while (frame_times_.size() > plot) frame_times_.pop_front();
  while (gpu_times_.size() > plot) gpu_times_.pop_front();

  // The UI first: what it changes applies to this frame.
  graph::Extent extent = output_.extent();
  if (extent.width == 0 || extent.height == 0) return;  // minimised
  ui_.begin_frame(extent, seconds);
  panel_ = glm::uvec4(0u);
  if (options_.show_panel) build_panel();
  draw_cut_aways();
  update_annotations(extent);
  draw_annotations();
  ui_.end_frame();
  apply_submitted();
  std::vector<glm::uvec4> keep_out{panel_};
  keep_out.insert(keep_out.end(), annotation_layout_.keep_out.begin(),
                  annotation_layout_.keep_out.end());
  if (keep_out != labelled_->settings().placement.keep_out) {
    // (the panel moved, or was shown or hidden; the title or legend changed)
    labelled_->settings().placement.keep_out = keep_out;
    labelled_->settings().annotations = annotation_layout_.boxes();
    changed();
  }
  if (ui_frames_ > 0) --ui_frames_;

  control_.update(seconds);
  apply_camera();
  const bool moving = camera_moving();
  choose_divisor(moving);
  const bool drawn =
      output_.draw([this, seconds](uint32_t slot, graph::Extent e) -> graph::GraphRunner& {
        return prepare(slot, e, seconds);
      });
  if (!drawn) return;
  ++summary_.frames;
  const double busy = seconds_between(now, Clock::now());
  summary_.busy_seconds += busy;
  if (moving) {
    ++summary_.moving_frames;
    summary_.moving_seconds += busy;
  }
  if (options_.frame_budget_ms > 0.0) {
    // (a frame of d-th pixels costs about 1 / d^2 of a full one, and a little more)
    const double full = 1e3 * busy * double(divisor_) * double(divisor_);
    full_frame_ms_ = full_frame_ms_ > 0.0 ? 0.5 * (full_frame_ms_ + full) : full;
  }
}

}  // namespace strata::app
