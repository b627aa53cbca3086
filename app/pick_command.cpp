// strata pick: the world point under pixels of a scene's picture (passes/picking.h), as a user
// would click on it, with the atlas region it lies in.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "app/commands.h"
#include "engine/scene/atlas.h"
#include "passes/picking.h"

namespace strata::app {
namespace {

struct PickOptions {
  SceneInput scene;
  std::string size = "512x512";
  std::string camera;
  std::vector<std::string> at;  // "X,Y" pixels
  uint32_t runs = 1;            // frames rendered and picked (the GPU time: their median)
};

// "X,Y": a pixel's column and row from the top-left corner (numbers; 12.5 lies in column 12),
// inside the image, else a usage error.
glm::vec2 parse_pixel(const std::string& text, graph::Extent size) {
  const size_t comma = text.find(',');
  float x = 0.0f, y = 0.0f;
  try {
    size_t used_x = 0, used_y = 0;
    if (comma == std::string::npos) throw std::invalid_argument("no comma");
    x = std::stof(text.substr(0, comma), &used_x);
    y = std::stof(text.substr(comma + 1), &used_y);
    if (used_x != comma || used_y != text.size() - comma - 1) throw std::invalid_argument("junk");
  } catch (const std::exception&) {
    throw UsageError("--at: '" + text + "' is not X,Y (a pixel's column and row, e.g. 256,200)");
  }
  if (!(x >= 0.0f && y >= 0.0f && x < float(size.width) && y < float(size.height))) {
    throw UsageError("--at: " + text + " lies outside the " + std::to_string(size.width) + "x" +
                     std::to_string(size.height) + " image");
  }
  return {x, y};
}

void pick(DeviceOptions& device, const PickOptions& o) {
  const graph::Extent size = parse_size(o.size, "--size");
  // (one frame picks at most PICK_MAX pixels: its buffers are sized for them)
  if (o.at.size() > PICK_MAX)
    throw UsageError("--at: " + std::to_string(o.at.size()) + " pixels, at most " +
                     std::to_string(PICK_MAX) + " in one run (pick the rest in another run)");
  std::vector<glm::vec2> pixels;
  for (const std::string& text : o.at) pixels.push_back(parse_pixel(text, size));
  Context ctx(device.context());
  check_image_size(ctx, size, "--size");
  const Scene scene = load_scene_reporting(o.scene, ctx);
  const Camera camera = option_camera(scene, o.camera);
  RenderSettings settings;
  settings.layer_count = o.scene.layer_count(scene);
  ScenePick picked = pick_scene(ctx, scene, camera, settings, size, pixels, o.runs);
  std::vector<double>& gpu_ms = picked.gpu_ms;
  std::sort(gpu_ms.begin(), gpu_ms.end());
  std::fprintf(stderr, "strata: picking %zu pixels took %.4f ms on the GPU (median of %u)\n",
               pixels.size(), gpu_ms[gpu_ms.size() / 2], o.runs);
  const std::vector<PickHit>& hits = picked.hits;
  for (size_t i = 0; i < hits.size(); ++i) {
    std::printf("%s: ", o.at[i].c_str());
    if (!hits[i].hit) {
      std::printf("nothing (the ray meets only background)\n");
      continue;
    }
    const glm::vec3 p = hits[i].point;
    const std::string region = atlas_region_at(scene, p);
    std::printf("LPS %.2f %.2f %.2f mm, RAS %.2f %.2f %.2f mm, region %s\n", double(p.x),
                double(p.y), double(p.z), double(-p.x), double(-p.y), double(p.z),
                region.empty() ? "none" : region.c_str());
  }
}

}  // namespace

void add_pick_command(CLI::App& app, DeviceOptions& device) {
  CLI::App* cmd = app.add_subcommand(
      "pick",
      "The world point under pixels of the scene's picture (where it first becomes "
      "opaque) and the atlas region there");
  auto o = std::make_shared<PickOptions>();
  cmd->add_option("scene", o->scene.file, "scene file, or a volume file or DICOM folder")
      ->required();
  add_scene_input_options(cmd, o->scene);
  cmd->add_option("--size", o->size, "the picture's size, N or WxH")->capture_default_str();
  cmd->add_option("--camera", o->camera, "named camera position of the scene (default: its own)");
  cmd->add_option("--at", o->at,
                  "X,Y: a pixel's column and row from the top-left corner; repeat for more, "
                  "up to " +
                      std::to_string(PICK_MAX))
      ->required()
      ->allow_extra_args(false);  // one pixel an --at: the next word is not a second pixel
  cmd->add_option("--runs", o->runs, "frames to render and pick (for the GPU time's median)")
      ->check(whole_range(1, 1000))
      ->capture_default_str();
  cmd->callback([&device, o] { pick(device, *o); });
}

}  // namespace strata::app
