// The strata program: builds the command line from the commands (commands.h), runs the one
// given and prints its error.
#include <cstdio>
#include <exception>

#include "app/commands.h"

int main(int argc, char** argv) {
  using namespace strata::app;
  CLI::App app{"strata: label placement in volume-rendered medical scenes (Vulkan)"};
  app.require_subcommand(1);
  DeviceOptions device;
  app.add_option(
      "--device", device.device,
      "Vulkan device by index or part of its name (default: STRATA_DEVICE, else the best)");
  app.add_flag("--validate", device.validate,
               "Khronos validation with synchronization validation (always on in debug builds)");
  add_devices_command(app, device);
  add_render_command(app, device);
  add_view_command(app, device);
  add_bench_command(app, device);
  add_info_command(app);
  add_eval_command(app);
  add_video_command(app, device);
  add_pick_command(app, device);
  refuse_empty_values(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version end here too (exit code 0); anything else is a usage error: 2.
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
    std::fprintf(stderr, "strata: error: %s (see strata --help or strata COMMAND --help)\n",
                 e.what());
    return 2;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "strata: error: %s (see strata --help or strata COMMAND --help)\n",
                 e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "strata: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
