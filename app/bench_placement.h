// `strata bench placement`: the label placement's GPU time per pass and per group for one label
// count or a sweep of them, against the thesis program's readback after every label
// (app/bench_placement.cpp).
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "engine/scene/scene.h"

namespace strata::app {

// Adds `placement` to the `bench` command.
void add_placement_bench(CLI::App* bench, DeviceOptions& device);

namespace bench {

// A scene's labels cut to `count` or repeated up to it (each repeat's anchor moved by 2 mm so
// that no two coincide); 0 keeps them. An Error naming the scene file when it has none.
std::vector<Label> resized_labels(const std::vector<Label>& labels, uint32_t count,
                                  const std::string& scene_file);

}  // namespace bench
}  // namespace strata::app
