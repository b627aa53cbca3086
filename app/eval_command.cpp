// `strata eval LAYOUT.json [LAYOUT.json ...]`: the layout-quality metrics of files written by
// `strata render --layout`, as JSON on stdout (definitions in docs/layout-metrics.md). Several
// files are a sequence of frames in the order given. Opens no device.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "app/commands.h"
#include "labeling/layout_metrics.h"

namespace strata::app {

namespace {

nlohmann::ordered_json evaluate(const std::vector<std::string>& files) {
  std::vector<Layout> layouts;
  for (const std::string& file : files) layouts.push_back(read_layout(file));
  if (layouts.size() == 1) return {{"frames", 1}, {"frame", to_json(frame_metrics(layouts[0]))}};
  return to_json(sequence_metrics(layouts));
}

}  // namespace

void add_eval_command(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand(
      "eval", "Layout-quality metrics of --layout files (overlaps, crossings, movement) as JSON");
  auto files = std::make_shared<std::vector<std::string>>();
  cmd->add_option("LAYOUT", *files, "layout files from `strata render --layout`, in frame order")
      ->required();
  cmd->callback([files] {
    // Every file is read before anything is printed: an error leaves stdout empty.
    const std::string report = evaluate(*files).dump(2);
    std::printf("%s\n", report.c_str());
  });
}

}  // namespace strata::app
