#include <cstdio>

#include "app/commands.h"
#include "engine/graph_runner.h"
#include "engine/headless_target.h"
#include "engine/png.h"
#include "passes/test_pattern.h"

namespace strata::app {

void add_render_command(CLI::App& app, DeviceOptions& device) {
  CLI::App* cmd = app.add_subcommand("render", "Render an image offline and write it as PNG");
  struct Options {
    std::string output = "strata.png";
    std::string size = "512x512";
    uint32_t blur = 12;
  };
  auto options = std::make_shared<Options>();
  cmd->add_option("-o,--output", options->output, "PNG file to write")->capture_default_str();
  cmd->add_option("--size", options->size, "image size, N or WxH")->capture_default_str();
  cmd->add_option("--blur", options->blur, "box-filter radius of the demo's right half, in pixels")
      ->capture_default_str();
  cmd->callback([&device, options] {
    const graph::Extent size = parse_size(options->size, "--size");
    Context ctx(device.context());
    TestPattern pattern(ctx);
    HeadlessTarget target(ctx);
    graph::Graph graph;
    target.add_output(graph, pattern.add_to(graph, options->blur));
    graph::GraphRunner runner(ctx, std::move(graph));
    runner.set_viewport(size);
    target.bind(runner);
    runner.run_now();
    write_png(options->output, size.width, size.height, target.pixels());
    std::printf("wrote %s (%ux%u)\n", options->output.c_str(), size.width, size.height);
  });
}

}  // namespace strata::app
