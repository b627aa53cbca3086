// A planned video: the frames each label may be shown in, chosen over the whole camera path before
// the frames are drawn (`strata video`), so that every label is drawn in one steady range per
// visible stretch of its anchor and no range is short. The plan is made from rehearsals, the path
// drawn without writing a frame: a free one gives each label's longest run per stretch; each
// next one, drawn with the plan, drops the ranges it found short, until none is. The same plan
// gives the same frames, so the video is its last rehearsal. Terms as in layout_metrics.h; no GPU
// here.
#pragma once

#include <cstddef>
#include <map>
#include <vector>

#include "labeling/layout_metrics.h"

namespace strata {

// Frames first..last of a sequence, both included.
struct FrameRange {
  size_t first = 0;
  size_t last = 0;
  bool operator==(const FrameRange&) const = default;
};

// Per label id, the frames in which the placement may show the label: ascending, disjoint, at
// most one range per visible stretch. A label without an entry is never shown.
using ActiveRanges = std::map<int, std::vector<FrameRange>>;

// The first plan, from a free rehearsal (every label allowed in every frame): for each label and
// visible stretch, its longest run of drawn frames (placed, with opacity >= opaque_opacity; the
// earliest of equals) if that lasts short_range_seconds or touches the first or last frame; its
// range from `lead_seconds` before the run (not before the stretch: the label's fade in) to the
// stretch's end, since a PlanFollower ends it where the label stops being drawn.
ActiveRanges first_plan(const std::vector<Layout>& rehearsal, double lead_seconds);

// The ranges of `plan` in which the rehearsal drawn with it (and a PlanFollower) drew its label
// for less than short_range_seconds without touching the first or last frame, removed; returns
// how many were.
size_t drop_short_ranges(ActiveRanges& plan, const std::vector<Layout>& rehearsal);

// The label-seconds a sequence draws its labels in (placed, opacity >= opaque_opacity).
double drawn_label_seconds(const std::vector<Layout>& frames);

// The most readable label-seconds a sequence can have whose labels sit where the stills put them
// (`stills`: one still layout per frame, each weighing `weight`, frame_weights of the frames):
// one range per visible stretch,
// none shorter than short_range_seconds unless it touches an end, a label readable in every frame
// of its range. Any subset of a still's shown labels is still free of overlaps and cuts, so the
// labels do not constrain each other, and a stretch's best is its longest readable run: exact.
double best_consistent_seconds(const std::vector<Layout>& stills,
                               const std::vector<double>& weight);

// Follows a plan while a sequence is drawn: which labels the placement must leave out of the next
// frame. Those outside their ranges, and those whose range has ended in this stretch (drawn, then
// not), so that however a frame turns out no label is drawn twice in one stretch. Drawn, not
// readable: legibility is measured only where a layout is written, and a plan must give the same
// frames either way.
class PlanFollower {
 public:
  // `ids`: the scene's label ids, by label index.
  PlanFollower(ActiveRanges ranges, std::vector<int> ids);
  // By label index: true for a label left out of frame `frame`.
  std::vector<bool> withheld(size_t frame) const;
  // The layout the last frame drew (its labels by id).
  void saw(const Layout& frame);

 private:
  ActiveRanges ranges_;
  std::vector<int> ids_;
  std::map<int, bool> seen_;   // readable in the current stretch
  std::map<int, bool> ended_;  // readable, then not, in the current stretch
};

}  // namespace strata
