#include "labeling/video_plan.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

namespace strata {

namespace {

// A run of frames [first, last] and the seconds its frames weigh.
struct Run {
  size_t first = 0;
  size_t last = 0;
  double seconds = 0.0;
};

bool drawn(const LayoutLabel& label) {
  return label.placed && label.opacity >= opaque_opacity;
}

// Each label's frames by id: in view (`in`) and drawn or readable (`on`).
struct Timeline {
  std::vector<bool> in, on;
};

std::map<int, Timeline> timelines(const std::vector<Layout>& frames, bool readable_only) {
  std::map<int, Timeline> out;
  for (size_t k = 0; k < frames.size(); ++k) {
    for (const LayoutLabel& l : frames[k].labels) {
      auto [it, added] = out.try_emplace(
          l.id, Timeline{std::vector<bool>(frames.size()), std::vector<bool>(frames.size())});
      const bool on = readable_only ? readable(l) : drawn(l);
      it->second.on[k] = on;
      it->second.in[k] = on || frame_state(l, frames[k]) != FrameState::out_of_view;
    }
  }
  return out;
}

// The maximal runs of frames in view.
std::vector<FrameRange> stretches(const Timeline& t) {
  std::vector<FrameRange> out;
  for (size_t k = 0; k < t.in.size(); ++k) {
    if (!t.in[k]) continue;
    if (k == 0 || !t.in[k - 1]) out.push_back({k, k});
    out.back().last = k;
  }
  return out;
}

// The runs of `on` frames in [from, to].
std::vector<Run> runs(const Timeline& t, const std::vector<double>& weight, FrameRange within) {
  std::vector<Run> out;
  for (size_t k = within.first; k <= within.last; ++k) {
    if (!t.on[k]) continue;
    Run run{k, k, 0.0};
    while (run.last + 1 <= within.last && t.on[run.last + 1]) ++run.last;
    for (size_t j = run.first; j <= run.last; ++j) run.seconds += weight[j];
    out.push_back(run);
    k = run.last;
  }
  return out;
}

// The longest run (the earliest of equals); none if there is none.
std::optional<Run> longest(const std::vector<Run>& runs) {
  std::optional<Run> best;
  for (const Run& r : runs) {
    if (!best || r.seconds > best->seconds) best = r;
  }
  return best;
}

// A run that may stand: not short, or at an end of the sequence.
bool may_stand(const Run& run, size_t frames) {
  return run.seconds >= short_range_seconds - 1e-9 || run.first == 0 || run.last + 1 == frames;
}

bool holds(const std::vector<FrameRange>& ranges, size_t k) {
  return std::any_of(ranges.begin(), ranges.end(),
                     [k](const FrameRange& r) { return r.first <= k && k <= r.last; });
}

}  // namespace

ActiveRanges first_plan(const std::vector<Layout>& rehearsal, double lead_seconds) {
  const std::vector<double> weight = frame_weights(rehearsal);
  const double step = rehearsal.size() > 1 ? weight[1] : 0.0;
  const size_t lead = step > 0.0 ? size_t(std::ceil(lead_seconds / step - 1e-6)) : 0;
  ActiveRanges plan;
  for (const auto& [id, t] : timelines(rehearsal, false)) {
    for (const FrameRange& stretch : stretches(t)) {
      const std::optional<Run> run = longest(runs(t, weight, stretch));
      if (!run || !may_stand(*run, rehearsal.size())) continue;
      plan[id].push_back({run->first - std::min(lead, run->first - stretch.first), stretch.last});
    }
  }
  return plan;
}

size_t drop_short_ranges(ActiveRanges& plan, const std::vector<Layout>& rehearsal) {
  const std::vector<double> weight = frame_weights(rehearsal);
  const std::map<int, Timeline> drawn_frames = timelines(rehearsal, false);
  size_t dropped = 0;
  for (auto& [id, ranges] : plan) {
    const auto t = drawn_frames.find(id);
    std::erase_if(ranges, [&](const FrameRange& range) {
      if (t == drawn_frames.end()) return false;
      const std::vector<Run> in_range = runs(t->second, weight, range);
      const bool short_run = std::any_of(in_range.begin(), in_range.end(), [&](const Run& r) {
        return !may_stand(r, rehearsal.size());
      });
      dropped += short_run ? 1 : 0;
      return short_run;
    });
  }
  std::erase_if(plan, [](const auto& entry) { return entry.second.empty(); });
  return dropped;
}

double drawn_label_seconds(const std::vector<Layout>& frames) {
  const std::vector<double> weight = frame_weights(frames);
  double sum = 0.0;
  for (size_t k = 0; k < frames.size(); ++k) {
    for (const LayoutLabel& l : frames[k].labels) sum += drawn(l) ? weight[k] : 0.0;
  }
  return sum;
}

double best_consistent_seconds(const std::vector<Layout>& stills,
                               const std::vector<double>& weight) {
  double sum = 0.0;
  for (const auto& [id, t] : timelines(stills, true)) {
    for (const FrameRange& stretch : stretches(t)) {
      const std::optional<Run> run = longest(runs(t, weight, stretch));
      if (run && may_stand(*run, stills.size())) sum += run->seconds;
    }
  }
  return sum;
}

PlanFollower::PlanFollower(ActiveRanges ranges, std::vector<int> ids)
    : ranges_(std::move(ranges)), ids_(std::move(ids)) {}

std::vector<bool> PlanFollower::withheld(size_t frame) const {
  std::vector<bool> out(ids_.size(), true);
  for (size_t i = 0; i < ids_.size(); ++i) {
    const auto it = ranges_.find(ids_[i]);
    if (it == ranges_.end() || !holds(it->second, frame)) continue;
    const auto ended = ended_.find(ids_[i]);
    out[i] = ended != ended_.end() && ended->second;
  }
  return out;
}

void PlanFollower::saw(const Layout& frame) {
  for (const LayoutLabel& label : frame.labels) {
    bool& seen = seen_[label.id];
    bool& ended = ended_[label.id];
    if (!drawn(label) && frame_state(label, frame) == FrameState::out_of_view) {
      seen = ended = false;
    } else if (drawn(label)) {
      seen = true;
    } else if (seen) {
      ended = true;
    }
  }
}

}  // namespace strata
