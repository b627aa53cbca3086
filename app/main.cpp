#include <cstdio>
#include <cstdlib>
#include <exception>

#include "app/commands.h"
#include "engine/core/error.h"
#include "engine/scene/io/scene_loader.h"

namespace strata::app {

ContextOptions DeviceOptions::context() const {
  ContextOptions options;
  options.device_selector = device;
  const char* env = std::getenv("STRATA_VALIDATE");
#ifdef NDEBUG
  options.validation = validate || (env && std::string(env) == "1");
#else
  options.validation = !(env && std::string(env) == "0");
#endif
  return options;
}

Scene load_scene_reporting(const std::string& path) {
  Scene scene = load_scene(path);
  for (const std::string& warning : scene.warnings)
    std::fprintf(stderr, "strata: warning: %s\n", warning.c_str());
  return scene;
}

graph::Extent parse_size(const std::string& text, const char* option) {
  unsigned w = 0, h = 0;
  char x = 0, extra = 0;
  const int n = std::sscanf(text.c_str(), "%u%c%u%c", &w, &x, &h, &extra);
  if (n == 1) h = w;
  if ((n != 1 && !(n == 3 && x == 'x')) || w == 0 || h == 0 || w > 16384 || h > 16384) {
    throw strata::Error(std::string(option) + ": '" + text +
                        "' is not a size (N or WxH, 1 to 16384)");
  }
  return {w, h};
}

void add_label_look_options(CLI::App* cmd, LabelLookOptions& o) {
  cmd->add_option("--label-scale", o.label_scale, "label text and boxes times this (0.25 to 4)")
      ->check(CLI::Range(0.25f, 4.0f))
      ->capture_default_str();
  cmd->add_flag("--layer-colors", o.layer_colors,
                "label borders in their depth layer's colour (front to back: orange, blue, green, "
                "pink, ...)");
}

}  // namespace strata::app

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
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "strata: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
