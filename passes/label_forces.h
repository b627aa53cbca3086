// Forces (thesis 3.4): after the placement, each label's drawn position moves toward the
// position the placement chose (eq. 3.6-3.8: unit force, attenuated within epsilon, sub-stepped,
// snapped when close), so that labels glide while the camera moves instead of jumping. The drawn
// positions live on the GPU from frame to frame; nothing waits for the CPU.
//   labels.forces  per label: the state moves, and the placement drawing reads is written
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "engine/gpu/resources.h"
#include "engine/gpu/shader_library.h"
#include "engine/graph/graph_runner.h"
#include "engine/graph/readback.h"
#include "engine/graph/render_graph.h"
#include "shared/keep_apart.h"

namespace strata {

// What the settings' relative lengths are in pixels in one frame. Motion (the forces' speed and
// distances) is in image widths, so that a camera path moves labels the same share of the image
// at any image size; spacing (padding, margins) is in the label text's size, which is what keeps
// two labels apart legibly, and which does not follow the image's size.
struct LabelUnits {
  float width = 0.0f;   // the image's width
  float em = 0.0f;      // the label text's size: font pixels times the label scale
  float height = 0.0f;  // the image's height (keeping labels inside it)
};

struct ForceSettings {
  // Where a label lives between frames: as an offset from its anchor, so that it moves rigidly
  // with the anchor while the camera turns and the forces act on the offset; or, as in the
  // thesis, as a position on screen.
  bool anchor_relative = true;
  // (defaults: what were 90 px/s and 24 px at 1024 px wide)
  float speed_widths = 0.088f;     // image widths per second at full force
  float epsilon_widths = 0.0234f;  // image widths: within this the force shrinks (eq. 3.7)
  // Pixels: within this a label is put on its target. It rounds a sub-pixel remainder, which is
  // as invisible at one image size as at any other, so it stays in pixels.
  float snap = 0.5f;
  // A label gets up to full speed over this long (a smooth start; 0: at once). Its stop is smooth
  // already: within epsilon the force shrinks with the distance.
  float ease_in_seconds = 0.25f;
  // The hold (eq. 3.1 with hysteresis): a label keeps heading for last frame's target unless
  // another position costs less by more than this share of the target's cost plus hold_cost.
  float hold_share = 0.5f;
  float hold_cost = 2.0f;
  // Eq. 3.1's eta in the frames of an animation (a still uses the scene's): the distance to the
  // label's last target costs this much per pixel, so a label that must move goes nearby.
  float previous_weight = 2.0f;
  float fade_seconds = 0.3f;  // a label fades in or out over this long (0: it pops)
  // The drawn layout is a constraint (shaders/shared/keep_apart.h): drawn boxes never overlap or
  // leave the image; a label whose way is taken waits, and after `wait_seconds` fades out where
  // it is to fade in at its target. Off: each label moves on its own, as in the thesis.
  bool keep_apart = true;
  float wait_seconds = 0.4f;
  // Once it went, a label appears again not before `min_hidden_seconds` (so that one where room
  // is short does not flicker), and in motion only with this much room around its box (in ems:
  // label text sizes; 0: its box's own room, as the placement's soft margin may leave less).
  float appear_margin_em = 0.0f;
  float min_hidden_seconds = 0.5f;
  // Hard mode: extra clear zone a label hidden in the last frame needs to appear, in ems (label
  // text sizes; 8 px at the default 14 px font).
  float appear_padding_em = 8.0f / 14.0f;
};

// The forces integrate in sub-steps of at most this long, so that a frame moves a label as the
// same time in shorter frames would, whatever the frame rate.
inline constexpr double kForceStepSeconds = 1.0 / 120.0;

// The push constants of one frame of `seconds` at `units`: sub-steps of at most
// kForceStepSeconds, and enough that none moves a label by more than epsilon, so no step
// overshoots its target. A frame of 0 s is a still: labels fade at once (and where kept apart,
// each appears on its target if that is free of the boxes before it in the order). `hard`: the
// placement forbids violations (the appear padding applies). `order_count`: labels in the
// placement's insertion order.
gpu::ForcesParams forces_params(const ForceSettings& settings, LabelUnits units,
                                uint32_t label_count, double seconds, bool hard = false,
                                uint32_t order_count = 0);

// `rects` (x0, y0, x1, y1 in pixels; empty ones count for nothing) as the keep-out rectangles
// drawn boxes keep off (shared/keep_apart.h); more than PLACEMENT_KEEP_OUT_MAX is an Error.
void set_keep_out(gpu::ForcesParams& params, std::span<const glm::uvec4> rects);

class LabelForces {
 public:
  struct Inputs {
    graph::ResourceId labels;   // LabelGpu[]: this frame's anchors and flags
    graph::ResourceId targets;  // PlacementGpu[]: the placement's result
    graph::ResourceId state;    // import_state()'s
    graph::ResourceId order;  // uint[]: the placement's insertion order (keeping apart's priority)
  };
  struct Outputs {
    graph::ResourceId drawn;  // PlacementGpu[]: where the labels are drawn
  };

  // (with `pipelines_from`: that one's pipelines, moved out; the scene's labels changed)
  LabelForces(Context& ctx, uint32_t label_count, LabelForces* pipelines_from = nullptr);

  // The state kept across frames (LabelStateGpu[]), imported into `graph`: before the placement,
  // which reads last frame's drawn positions from it.
  graph::ResourceId import_state(graph::Graph& graph) const;
  // What each label of this frame takes from the last (forces_previous: eq. 3.1's previous
  // position, the held position and its hold, hard mode's padding), written into `labels`
  // (LabelGpu[]) in place: the placement's Inputs::adjust_labels.
  void add_previous(graph::Graph& graph, graph::ResourceId labels, graph::ResourceId state) const;
  // The forces pass, and a copy of the drawn placements for the host.
  Outputs add_to(graph::Graph& graph, const Inputs& in);
  // The targets of a placement made beside the frames (PlacementGpu[] `targets` of the labels
  // `placed` as it saw them) moved into this frame of `labels` (follow_anchor): returns them.
  graph::ResourceId add_follow(graph::Graph& graph, graph::ResourceId labels,
                               graph::ResourceId placed, graph::ResourceId targets) const;

  // The next frame's settings, units and duration (a fixed 1 / fps offline, so videos are
  // repeatable).
  void set_frame(const ForceSettings& settings, LabelUnits units, double seconds, bool hard = false,
                 uint32_t order_count = 0);
  // Labels from `count` on are all disabled (spare label slots): the next frames set (set_frame)
  // leave them out.
  void set_active(uint32_t count) { active_ = std::min(count, label_count_); }
  // The frame's count of labels in the insertion order the forces read (a placement's older than
  // the frame: frame/placement_beside.h).
  void set_order_count(uint32_t count) { params_.order_count = std::min(count, label_count_); }
  // The keep-out rectangles of this frame and the next ones (the placement's).
  void set_keep_out(std::span<const glm::uvec4> rects);
  // Marks the frame set last as a trial (ForcesParams::trial): labels are drawn where they were
  // and the state is not written, so several trial placements start from the same state.
  void set_trial(bool trial) { params_.trial = trial ? 1u : 0u; }
  // The frame's push constants.
  const gpu::ForcesParams& params() const { return params_; }
  // Forgets every drawn position: the next frame puts each label on its target.
  void reset();
  // The state after the last completed frame (waits; tests and tools).
  std::vector<gpu::LabelStateGpu> state() const;
  // Where the labels were drawn in the last completed frame.
  std::span<const gpu::PlacementGpu> drawn() const;
  graph::Readback& readback() { return readback_; }

 private:
  Context& ctx_;
  uint32_t label_count_;
  uint32_t active_;  // labels the frames move (set_active)
  gpu::ForcesParams params_{};
  std::vector<glm::uvec4> keep_out_;
  ComputePipeline forces_, previous_, follow_;
  Buffer state_;
  graph::Readback readback_;
};

// The CPU reference of add_previous's pass: what each label takes from the state.
std::vector<gpu::LabelGpu> previous_reference(std::vector<gpu::LabelGpu> labels,
                                              const std::vector<gpu::LabelStateGpu>& state,
                                              const gpu::ForcesParams& params);

// The CPU reference of add_follow's pass.
std::vector<gpu::PlacementGpu> follow_reference(std::vector<gpu::PlacementGpu> targets,
                                                const std::vector<gpu::LabelGpu>& placed,
                                                const std::vector<gpu::LabelGpu>& labels,
                                                const gpu::ForcesParams& params);

// The CPU reference: one frame of forces over every label, kept apart in the placement's `order`
// (its first params.order_count entries) where params.keep_apart says. `state` is updated in
// place (kept in a trial frame); returns where each label is drawn.
std::vector<gpu::PlacementGpu> forces_reference(const std::vector<gpu::LabelGpu>& labels,
                                                const std::vector<gpu::PlacementGpu>& targets,
                                                std::vector<gpu::LabelStateGpu>& state,
                                                const gpu::ForcesParams& params,
                                                const std::vector<uint32_t>& order = {});

}  // namespace strata
