// Active ranges and visible stretches, declared in layout_metrics.h.
#include "labeling/layout_metrics.h"
#include "labeling/video_plan.h"

#include <map>

namespace strata {

bool readable(const LayoutLabel& label) {
  return label.shown && label.opacity >= opaque_opacity;
}

using State = FrameState;

// In view: the anchor in the closed image rectangle, or the label readable (so a range lies in
// one stretch). The files do not say whether an anchor is cut away (its label is then hidden),
// so a cut-away does not end a stretch; nor does anchor_hidden: such a label is still drawn, with
// a dashed leader.
FrameState frame_state(const LayoutLabel& label, const Layout& frame) {
  if (readable(label)) return State::readable;
  const bool in_image = label.anchor.x >= 0.0 && label.anchor.y >= 0.0 &&
                        label.anchor.x <= double(frame.width) &&
                        label.anchor.y <= double(frame.height);
  return in_image ? State::visible : State::out_of_view;
}

namespace {

bool in_view(State s) {
  return s == State::visible || s == State::readable;
}

// Each label's state in every frame, by id.
std::map<int, std::vector<State>> label_timelines(const std::vector<Layout>& frames) {
  std::map<int, std::vector<State>> out;
  for (size_t k = 0; k < frames.size(); ++k) {
    for (const LayoutLabel& l : frames[k].labels) {
      auto [it, added] = out.try_emplace(l.id, frames.size(), State::absent);
      it->second[k] = frame_state(l, frames[k]);
    }
  }
  return out;
}

}  // namespace

std::vector<double> frame_weights(const std::vector<Layout>& frames) {
  std::vector<double> weight(frames.size(), 0.0);
  for (size_t k = 1; k < frames.size(); ++k) weight[k] = frames[k].seconds.value_or(0.0);
  return weight;
}

namespace {

double readable_seconds(const std::vector<Layout>& layouts, const std::vector<double>& weight) {
  double sum = 0.0;
  for (size_t k = 0; k < layouts.size(); ++k) {
    for (const LayoutLabel& l : layouts[k].labels) sum += readable(l) ? weight[k] : 0.0;
  }
  return sum;
}

struct Counts {
  size_t stretches = 0, ranges = 0, extra = 0, short_ranges = 0, short_inside = 0;
  double label_seconds = 0.0;
};

// One label's stretches and ranges.
void count_ranges(const std::vector<State>& states, const std::vector<double>& weight, Counts& c) {
  const size_t n = states.size();
  size_t ranges_in_stretch = 0;
  for (size_t k = 0; k < n; ++k) {
    const bool before_in_view = k > 0 && in_view(states[k - 1]);
    if (k > 0 && states[k - 1] != State::absent && states[k] != State::absent)
      c.label_seconds += weight[k];
    if (in_view(states[k]) && !before_in_view) {
      ++c.stretches;
      ranges_in_stretch = 0;
    }
    if (states[k] != State::readable || (k > 0 && states[k - 1] == State::readable)) continue;
    size_t end = k;
    double seconds = 0.0;
    while (end < n && states[end] == State::readable) seconds += weight[end++];
    ++c.ranges;
    if (++ranges_in_stretch > 1) ++c.extra;
    if (seconds < short_range_seconds - 1e-9) {
      ++c.short_ranges;
      if (k > 0 && end < n) ++c.short_inside;
    }
  }
}

}  // namespace

ActiveRangeMetrics active_range_metrics(const std::vector<Layout>& frames,
                                        const std::vector<Layout>& stills) {
  ActiveRangeMetrics m;
  bool timed = frames.size() > 1;
  for (size_t k = 1; k < frames.size(); ++k) timed = timed && frames[k].seconds.has_value();
  const std::vector<double> weight = frame_weights(frames);
  Counts c;
  for (const auto& [id, states] : label_timelines(frames)) count_ranges(states, weight, c);
  for (const Layout& frame : frames) {
    for (const LayoutLabel& l : frame.labels) m.readable_label_frames += readable(l) ? 1 : 0;
  }
  m.visible_stretches = c.stretches;
  m.active_ranges = c.ranges;
  m.extra_ranges = c.extra;
  if (!timed) return m;
  m.readable_label_seconds = readable_seconds(frames, weight);
  m.extra_ranges_per_label_per_second =
      c.label_seconds > 0.0 ? double(c.extra) / c.label_seconds : 0.0;
  m.short_ranges = c.short_ranges;
  m.short_ranges_inside = c.short_inside;
  if (stills.size() == frames.size()) {
    m.still_readable_label_seconds = readable_seconds(stills, weight);
    if (*m.still_readable_label_seconds > 0.0)
      m.readable_of_stills = *m.readable_label_seconds / *m.still_readable_label_seconds;
    m.bound_label_seconds = best_consistent_seconds(stills, weight);
    if (*m.bound_label_seconds > 0.0)
      m.readable_of_bound = *m.readable_label_seconds / *m.bound_label_seconds;
  }
  return m;
}

}  // namespace strata
