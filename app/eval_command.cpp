// `strata eval LAYOUT.json [LAYOUT.json ...]`: the layout-quality metrics of files written by
// `strata render --layout` or `strata video --layout-dir`, as JSON on stdout (definitions in
// docs/layout-metrics.md). Several files are a sequence of frames in the order given; --stills
// DIR compares each with the layout of the same name in DIR, a still of the same view. Opens no
// device.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "app/commands.h"
#include "labeling/layout_metrics.h"

namespace strata::app {

namespace {

struct EvalOptions {
  std::vector<std::string> files;
  std::string stills;  // a folder; empty: none
};

nlohmann::ordered_json evaluate(const EvalOptions& o) {
  std::vector<Layout> layouts, stills;
  for (const std::string& file : o.files) {
    layouts.push_back(read_layout(file));
    if (!o.stills.empty()) {
      stills.push_back(
          read_layout(std::filesystem::path(o.stills) / std::filesystem::path(file).filename()));
    }
  }
  const SequenceMetrics metrics = sequence_metrics(layouts, stills);
  if (layouts.size() > 1) return to_json(metrics);
  const FrameMetrics* still = stills.empty() ? nullptr : &metrics.stills[0];
  return {{"frames", 1}, {"frame", to_json(metrics.per_frame[0], still)}};
}

}  // namespace

void add_eval_command(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("eval",
                                     "Layout-quality metrics of --layout files (overlaps, "
                                     "crossings, movement, active ranges) as JSON");
  auto o = std::make_shared<EvalOptions>();
  cmd->add_option("LAYOUT", o->files,
                  "layout files from `strata render --layout` or `strata video --layout-dir`, "
                  "in frame order")
      ->required();
  cmd->add_option("--stills", o->stills,
                  "folder of the stills' layouts of the same views, by the same file names "
                  "(`strata video --still-layouts`)");
  cmd->callback([o] {
    // Every file is read before anything is printed: an error leaves stdout empty.
    const std::string report = evaluate(*o).dump(2);
    std::printf("%s\n", report.c_str());
  });
}

}  // namespace strata::app
