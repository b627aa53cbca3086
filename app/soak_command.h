// `strata bench soak`: the viewer's whole frame loop for many frames, headless, with the camera
// moving and the panel's settings changing on a schedule, while host memory, device memory and
// the HA-Buffer are measured; growth is an error (app/soak_command.cpp).
#pragma once

#include <CLI/CLI.hpp>

#include "app/commands.h"

namespace strata::app {

// Adds `soak` to the `bench` command.
void add_soak_command(CLI::App* bench, DeviceOptions& device);

}  // namespace strata::app
