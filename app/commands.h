// The strata program's subcommands; main.cpp parses the command line and prints errors.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "engine/core/error.h"
#include "engine/gpu/context.h"
#include "engine/graph/render_graph.h"
#include "engine/scene/scene.h"

namespace strata::app {

// Options every subcommand that opens a device shares.
struct DeviceOptions {
  std::string device;     // --device NAME|INDEX
  bool validate = false;  // --validate (also STRATA_VALIDATE=1; always on in debug builds)
  ContextOptions context() const;
};

// Loads a scene and prints its warnings (missing data files, ...) to stderr.
Scene load_scene_reporting(const std::string& path);

// How labels look (render and video): --label-scale and --layer-colors.
struct LabelLookOptions {
  float label_scale = 1.0f;
  bool layer_colors = false;
};
void add_label_look_options(CLI::App* cmd, LabelLookOptions& o);

// "1024" or "1024x768"; throws Error naming the option when it is neither.
graph::Extent parse_size(const std::string& text, const char* option);

void add_devices_command(CLI::App& app, DeviceOptions& device);
void add_render_command(CLI::App& app, DeviceOptions& device);
void add_view_command(CLI::App& app, DeviceOptions& device);
void add_bench_command(CLI::App& app, DeviceOptions& device);
void add_info_command(CLI::App& app);
void add_eval_command(CLI::App& app);
void add_video_command(CLI::App& app, DeviceOptions& device);

}  // namespace strata::app
