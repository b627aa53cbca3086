// Whether the view has settled, what keeps it busy, the optimisation on idle and the
// interactive resolution while the camera moves.
#include "app/viewer/viewer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "app/viewer/frame_clock.h"

namespace strata::app {

// --- frames ------------------------------------------------------------------------------------

void Viewer::changed() {
  ++serial_;
  change_frame_ = labelled_->frame_number() + 1;
  labelled_->placement_due();
  settled_ = false;
  last_change_ = Clock::now();
  optimisation_.restart();
}

void Viewer::apply_camera() {
  const Camera& camera = control_.camera();
  if (same_view(camera, applied_camera_)) return;
  applied_camera_ = camera;
  labelled_->set_camera(camera);  // (the order goes back to the scene's)
  last_move_ = Clock::now();
  changed();
}

bool Viewer::busy() const {
  if (quit_) return false;
  if (ui_frames_ > 0 || !settled_ || control_.animating() || !submitted_.empty()) return true;
  if (!same_view(control_.camera(), applied_camera_)) return true;  // moved since the last frame
  if (drag_button_ >= 0) return false;  // a still mouse button: nothing moves
  if (!optimisation_due()) return false;
  // (trial frames; beside the frames, a frame starts each trial placement and takes it up)
  return !labelled_->placement_beside() || optimisation_.in_flight < 0 ||
         labelled_->trial_finished();
}

// (not while recording: a video's frames are a fixed time step apart, trials would be in them)
bool Viewer::optimisation_pending() const {
  return options_.optimize_on_idle && !optimisation_.done() && scene_.labels.size() >= 2 &&
         !recording();
}

// (baseline: a settled normal frame's cost)
bool Viewer::optimisation_due() const {
  return optimisation_pending() && optimisation_.has_baseline() &&
         seconds_between(last_change_, Clock::now()) >= options_.idle_seconds;
}

std::string Viewer::unsettled() const {
  std::vector<std::string> parts;
  if (ui_frames_ > 0) parts.push_back("the panel's frames");
  if (control_.animating()) parts.push_back("the camera's animation");
  if (!same_view(control_.camera(), applied_camera_)) parts.push_back("the camera's last move");
  if (!settled_ && checked_serial_ != serial_) {
    parts.push_back("the first frames after the last change");
  } else if (!settled_ && placement_due_) {
    parts.push_back("the placement beside the frames since the last change");
  } else if (!settled_) {
    std::string text = std::to_string(moving_labels_.size()) + " label" +
                       (moving_labels_.size() == 1 ? "" : "s") + " moving or fading (";
    for (size_t k = 0; k < moving_labels_.size() && k < 3; ++k) {
      text += (k ? ", " : "") + scene_.labels[moving_labels_[k]].text;
    }
    parts.push_back(text + (moving_labels_.size() > 3 ? ", ...)" : ")"));
  }
  if (settled_ && optimisation_pending()) {
    parts.push_back("the optimisation on idle (" + std::to_string(optimisation_.trials_back()) +
                    " of " + std::to_string(options_.optimize_tries) + " trials back)");
  }
  std::string out;
  for (size_t k = 0; k < parts.size(); ++k) out += (k ? ", " : "") + parts[k];
  return out.empty() ? "nothing" : out;
}

std::optional<double> Viewer::wake_in() const {
  if (!optimisation_pending()) return {};
  constexpr double kTrialPoll = 0.01;  // (a trial placement beside the frames: is it back?)
  if (optimisation_.in_flight >= 0) return kTrialPoll;
  return std::max(0.0, options_.idle_seconds - seconds_between(last_change_, Clock::now()));
}

int Viewer::next_trial() {
  if (!optimisation_due() || drag_button_ >= 0 || control_.animating()) return -1;
  const int trial =
      optimisation_.next(uint32_t(scene_.labels.size()), options_.optimize_tries, serial_);
  if (trial >= 0) ++summary_.trials;
  return trial;
}

void Viewer::trial_back(int trial, double cost) {
  const std::optional<IdleOptimisation::Better> better = optimisation_.back(trial, cost);
  if (!better) return;
  labelled_->set_order(*better->order);
  // (beside the frames, a placement in the new order: not settled before it is taken up)
  labelled_->placement_due();
  change_frame_ = labelled_->frame_number() + 1;
  ++summary_.adopted;
  settled_ = false;  // the labels move to the cheaper layout
  char text[96];
  std::snprintf(text, sizeof text, "optimised on idle: cost %.6g -> %.6g", better->from,
                better->to);
  message_ = text;
}

// The results of the frame that last used `slot` (it has finished).
void Viewer::read_slot(uint32_t slot) {
  const SlotFrame done = slots_[slot];
  const bool ours = done.generation == generation_;  // (else never used, or another graph's)
  labelled_->use_slot(slot, ours);
  if (!ours) return;
  last_timings_ = labelled_->runner().timings(slot);
  double gpu = 0.0;
  for (const graph::PassTiming& t : last_timings_) {
    summary_.gpu_ms[t.name] += t.ms;
    gpu += t.ms;
  }
  ++summary_.timed_frames;
  if (options_.keep_frame_spans && !last_timings_.empty()) {
    summary_.gpu_span_ms.push_back(last_timings_.back().end_ms - last_timings_.front().begin_ms);
  }
  gpu_times_.push_back(float(gpu));
  if (done.serial != serial_) return;  // made before the last change

  if (done.trial >= 0) return trial_back(done.trial, labelled_->total_cost());
  // Beside the frames, the labels head for a placement made before the last change: not settled.
  placement_due_ = labelled_->placed_frame_number() < change_frame_;
  if (placement_due_) {
    checked_serial_ = serial_;
    return;
  }
  if (refining_ && done.divisor == 1 && !camera_moving()) {
    refining_ = false;
    summary_.refine_seconds.push_back(seconds_between(last_move_, Clock::now()));
  }
  // A normal frame: settled when every label is on its target and fully faded in or out.
  const auto targets = labelled_->placement_results();
  const auto drawn = labelled_->drawn();
  const auto& labels = labelled_->labels();
  moving_labels_.clear();
  checked_serial_ = serial_;
  for (size_t i = 0; i < drawn.size(); ++i) {
    if ((labels[i].flags & LABEL_ENABLED) == 0u && drawn[i].opacity == 0.0f) continue;
    // (a held label keeps its exact offset from its anchor: within half a pixel per axis of
    // the placement's pixel-centred position)
    const bool on_target = glm::length(drawn[i].position - targets[i].position) < 0.75f ||
                           (drawn[i].opacity == 0.0f && targets[i].shown != PLACEMENT_SHOWN);
    // (a label kept apart that may soon appear again is not settled: PLACEMENT_PENDING)
    const bool still = on_target && (drawn[i].opacity == 0.0f || drawn[i].opacity == 1.0f) &&
                       (drawn[i].pad & PLACEMENT_PENDING) == 0u;
    if (!still) moving_labels_.push_back(uint32_t(i));
  }
  if (moving_labels_.empty()) {
    settled_ = true;
    optimisation_.settled(labelled_->total_cost());  // the kept order's cost
  }
}

// The camera moves: an animation, a drag in progress, or a move in the last quarter second (the
// frames between a drag's events keep the interactive resolution).
bool Viewer::camera_moving() const {
  return control_.animating() || drag_button_ >= 0 ||
         seconds_between(last_move_, Clock::now()) < 0.25;
}

// While the camera moves, the divisor that keeps a frame within the budget; at rest, 1 (and the
// placement beside the frames, paused while moving, places the resting view).
void Viewer::choose_divisor(bool moving) {
  if (options_.frame_budget_ms <= 0.0) return;
  uint32_t d = 1;
  if (moving && full_frame_ms_ > options_.frame_budget_ms) {
    d = uint32_t(std::ceil(std::sqrt(full_frame_ms_ / options_.frame_budget_ms)));
  }
  divisor_ = std::clamp(d, 1u, 8u);
  summary_.largest_divisor = std::max(summary_.largest_divisor, divisor_);
  labelled_->renderer().settings().divisor = debug_choice_ ? 1u : divisor_;
  labelled_->pause_placement(moving);
  if (moving) refining_ = true;
}

// The placements beside the frames taken up since the last frame: their GPU time and latency.
void Viewer::count_placements() {
  const PlacementBeside* beside = labelled_->beside();
  if (beside && beside->stats().adopted < beside_counted_) beside_counted_ = 0;  // (a new one)
  if (!beside || beside->stats().adopted == beside_counted_) return;
  summary_.placements += beside->stats().adopted - beside_counted_;
  beside_counted_ = beside->stats().adopted;
  summary_.placement_latency_frames.push_back(beside->stats().latency_frames.back());
  const auto& timings = beside->placement_timings();
  if (!timings.empty())
    summary_.placement_gpu_ms += timings.back().end_ms - timings.front().begin_ms;
}

}  // namespace strata::app
