#include <cstdio>
#include <filesystem>

#include "app/annotation_options.h"
#include "app/commands.h"
#include "app/output_files.h"
#include "app/progress.h"
#include "engine/core/image.h"
#include "engine/core/text_file.h"
#include "engine/graph/graph_runner.h"
#include "engine/graph/headless_target.h"
#include "engine/scene/io/scene_loader.h"
#include "frame/labelled_render.h"
#include "frame/vector_picture.h"
#include "labeling/camera_path.h"
#include "passes/test_pattern.h"
#include "passes/volume_renderer.h"

namespace strata::app {
namespace {

struct RenderOptions {
  SceneInput scene;
  std::string output = "strata.png";
  std::string size = "512x512";
  std::string camera;
  uint32_t tidy_rounds = PlacementSettings{}.tidy_rounds;
  std::string dump_layers;
  bool no_skipping = false;
  uint32_t blur = 12;
  bool no_labels = false;
  bool hard = false;
  PlacementMethod greedy = PlacementMethod::sequential;
  bool internal = false;
  LabelLookOptions look;
  Background background;
  AnnotationOptions notes;
  bool decoret = false;
  std::string order = "scene";
  std::string layout;
  bool dump_graph = false;
};

// --dump-graph: the frame's compiled graph (passes, their uses and barriers) on stdout.
void print_graph(const RenderOptions& o, graph::GraphRunner& runner) {
  if (o.dump_graph) std::fputs(graph::describe(runner.graph(), runner.compiled()).c_str(), stdout);
}

// --dump-layers: layer l's file in the folder.
std::filesystem::path layer_file(const std::string& folder, uint32_t l) {
  return std::filesystem::path(folder) / ("layer-" + std::to_string(l) + ".png");
}

// Layer images (premultiplied) written as straight-alpha PNGs.
void dump_layers(const std::vector<glm::vec4>& layers, graph::Extent size, uint32_t count,
                 const std::string& folder) {
  const size_t pixels = size_t{size.width} * size.height;
  for (uint32_t l = 0; l < count; ++l) {
    std::vector<uint8_t> rgba(pixels * 4);
    for (size_t p = 0; p < pixels; ++p) {
      const glm::vec4 c = layers[l * pixels + p];
      const glm::vec3 straight = c.a > 0.0f ? glm::vec3(c) / c.a : glm::vec3(0.0f);
      for (int ch = 0; ch < 3; ++ch)
        rgba[p * 4 + ch] = uint8_t(std::clamp(straight[ch], 0.0f, 1.0f) * 255.0f + 0.5f);
      rgba[p * 4 + 3] = uint8_t(std::clamp(c.a, 0.0f, 1.0f) * 255.0f + 0.5f);
    }
    const std::string path = layer_file(folder, l).string();
    write_png(path, size.width, size.height, rgba);
    std::printf("wrote %s\n", path.c_str());
  }
}

RenderSettings render_settings(const RenderOptions& o, const Scene& scene) {
  RenderSettings settings;
  settings.layer_count = o.scene.layer_count(scene);
  settings.skip_empty = !o.no_skipping;
  return settings;
}

// One image of the scene: its camera, and the files it goes to (layout and layers if asked for).
struct Still {
  Camera camera;
  std::string image;
  std::string layout;
  std::string layers;
};

// A file with the position's name before its extension: out.png and front give out-front.png.
std::string named_for(const std::string& path, const std::string& position) {
  if (path.empty()) return path;
  const std::filesystem::path p(path);
  return (p.parent_path() / (p.stem().string() + "-" + position + p.extension().string())).string();
}

// --camera front,left: one still per position, each file named after it (the thesis program's
// screenshots). One position, or none, writes the files as given. Every name is looked up before
// anything renders, so a typo costs no time and leaves no partial set of files.
std::vector<Still> stills(const Scene& scene, const RenderOptions& o) {
  const std::vector<std::string> names = split_camera_list(o.camera);
  if (names.size() == 1)
    return {{option_camera(scene, o.camera), o.output, o.layout, o.dump_layers}};
  std::vector<Still> out;
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i].empty()) {
      throw UsageError("--camera '" + o.camera + "': part " + std::to_string(i + 1) + " is empty");
    }
    std::string layers = o.dump_layers;
    while (layers.size() > 1 && layers.back() == '/') layers.pop_back();
    out.push_back({option_camera(scene, names[i]), named_for(o.output, names[i]),
                   named_for(o.layout, names[i]), layers.empty() ? "" : layers + "-" + names[i]});
  }
  return out;
}

LabellingSettings labelling_settings(const RenderOptions& o, const Scene& scene) {
  LabellingSettings settings;
  settings.layer_count = o.scene.layer_count(scene);
  settings.render = render_settings(o, scene);
  settings.placement.weights = scene.settings.weights;
  settings.placement.hard = o.hard;
  settings.placement.method = o.greedy;
  settings.placement.tidy_rounds = o.tidy_rounds;
  settings.internal = o.internal;
  settings.label_scale = o.look.label_scale;
  settings.layer_colors = o.look.layer_colors;
  settings.ghost = look_ghosting(o.look, scene);
  settings.background = o.background;
  if (o.order == "apollonius") settings.order = InsertionOrder::apollonius;
  if (o.order == "optimized") settings.order = InsertionOrder::optimized;
  if (o.decoret) {  // Stein & Decoret's setting, as the thesis compares against it
    settings.layer_count = 1;
    settings.order = InsertionOrder::apollonius;
    settings.placement.hard = true;
  }
  return settings;
}

// -o: a raster image (engine/core/image.h) or a vector file (frame/vector_picture.h).
void check_picture_extension(const std::string& path) {
  if (vector_format(path)) return;
  try {
    check_image_extension(path);
  } catch (const Error&) {
    throw Error(path + ": cannot write images as '" +
                std::filesystem::path(path).extension().string() +
                "' (the extension must be .png, .jpg, .jpeg, .svg or .pdf)");
  }
}

void write_picture(const std::string& path, graph::Extent size, std::span<const uint8_t> rgba) {
  if (vector_format(path)) {
    write_vector_picture(path, image_picture(size.width, size.height, rgba));
  } else {
    write_image(path, size.width, size.height, rgba);
  }
}

void write_layout(const std::string& path, const LabelledFrame& frame) {
  write_text_file(path, layout_json(frame));
  std::printf("wrote %s\n", path.c_str());
}

void render_labelled_still(Context& ctx, const Scene& scene, const RenderOptions& o,
                           graph::Extent size, const Still& still) {
  LabellingSettings settings = labelling_settings(o, scene);
  const bool vector = vector_format(still.image).has_value();
  settings.marks = !vector;  // (a vector file draws the labels itself)
  LabelledRenderer renderer(ctx, scene, still.camera, size, settings);
  print_graph(o, renderer.runner());
  const auto run = [&] {
    if (settings.order == InsertionOrder::optimized) {
      Progress progress("insertion order", settings.optimize_tries);
      renderer.run([&](uint32_t done, uint32_t) { progress.step_done(done); });
    } else {
      renderer.run();
    }
  };
  AnnotatedStill annotated;
  std::optional<Annotations> notes;
  if (o.notes.any()) {
    notes.emplace(o.notes, settings, glm::uvec2(size.width, size.height));
    annotated = annotated_still(renderer, *notes, scene, run);
  } else {
    run();
    annotated.frame = renderer.result();
  }
  LabelledFrame& frame = annotated.frame;
  if (vector) {
    VectorPicture picture = labelled_picture(frame, scene, settings, renderer.download_layers());
    add_annotations(picture, annotated.layout);
    write_vector_picture(still.image, picture);
  } else {
    if (notes) notes->draw(frame.image, annotated.layout);
    write_image(still.image, size.width, size.height, frame.image);
  }
  uint32_t shown = 0, placed = 0;
  for (const LabelLayout& l : frame.labels) {
    shown += l.shown;
    placed += l.placed;
  }
  // Shown: placed and legible (at least kLegibleShare of the box visible).
  std::printf("wrote %s (%ux%u, %u layers): %u of %zu labels shown", still.image.c_str(),
              size.width, size.height, frame.layering.layer_count, shown, frame.labels.size());
  if (placed > shown) std::printf(" (%u more placed but not legible)", placed - shown);
  std::printf("\n");
  if (!still.layout.empty()) write_layout(still.layout, frame);
  if (!still.layers.empty()) {
    dump_layers(renderer.download_layers(), size, frame.layering.layer_count, still.layers);
  }
}

// Every output file is known, writable and none of the inputs before anything renders; then the
// layers' folders are made.
void prepare_outputs(const std::vector<Still>& all, uint32_t layer_count) {
  for (const Still& still : all) {
    check_picture_extension(still.image);
    check_output_file("-o", still.image);
    if (!still.layout.empty()) check_output_file("--layout", still.layout);
    std::vector<std::filesystem::path> layers;
    for (uint32_t l = 0; l < layer_count; ++l) layers.push_back(layer_file(still.layers, l));
    if (!still.layers.empty()) check_output_folder("--dump-layers", still.layers, layers);
  }
  for (const Still& still : all)
    if (!still.layers.empty()) create_output_folder("--dump-layers", still.layers);
}

// What a render of a scene opens before anything renders: the device, the scene, and its stills
// with every output file checked.
struct SceneRender {
  graph::Extent size;
  Context ctx;
  Scene scene;
  std::vector<Still> stills;

  SceneRender(DeviceOptions& device, const RenderOptions& o)
      : size(parse_size(o.size, "--size")), ctx(device.context()) {
    check_image_size(ctx, size, "--size");
    scene = load_scene_reporting(o.scene, ctx);
    stills = app::stills(scene, o);
    prepare_outputs(stills, o.scene.layer_count(scene));
  }
};

// strata's main job: the labelled image (frame/labelled_render.h), once per position.
void render_labelled_scene(DeviceOptions& device, const RenderOptions& o) {
  SceneRender job(device, o);
  for (const Still& still : job.stills) {
    render_labelled_still(job.ctx, job.scene, o, job.size, still);
  }
}

// The label-free image; the renderer and its graph are built once and run for each position.
void render_scene(DeviceOptions& device, const RenderOptions& o) {
  SceneRender job(device, o);
  Context& ctx = job.ctx;
  const graph::Extent size = job.size;
  RenderSettings settings = render_settings(o, job.scene);
  settings.background = o.background;  // (no placement reads this picture)
  VolumeRenderer renderer(ctx, job.scene, settings);
  HeadlessTarget target(ctx);
  graph::Graph graph;
  const VolumeRenderer::Outputs out = renderer.add_to(graph);
  target.add_output(graph, out.final);
  graph::GraphRunner runner(ctx, std::move(graph));
  runner.set_viewport(size);
  target.bind(runner);
  print_graph(o, runner);
  for (const Still& still : job.stills) {
    renderer.set_camera(still.camera);
    const RenderStats stats = renderer.run_until_no_overflow(runner, [&](const RenderStats& s) {
      std::fprintf(stderr, "strata: HA-Buffer overflow (%u fragments), table grows to %u slots\n",
                   s.overflow, renderer.table_slots(size));
    });
    write_picture(still.image, size, target.pixels());
    std::printf(
        "wrote %s (%ux%u, %u layers): %u fragments, load factor %.2f, %.1f samples per ray\n",
        still.image.c_str(), size.width, size.height, settings.layer_count, stats.fragments,
        stats.load_factor(), double(stats.samples) / (double(size.width) * size.height));
    if (!still.layers.empty()) {
      dump_layers(download_layer_images(runner, out.layers), size, settings.layer_count,
                  still.layers);
    }
  }
}

void render_test_pattern(DeviceOptions& device, const RenderOptions& o) {
  const graph::Extent size = parse_size(o.size, "--size");
  check_picture_extension(o.output);
  check_output_file("-o", o.output);
  Context ctx(device.context());
  check_image_size(ctx, size, "--size");
  TestPattern pattern(ctx);
  HeadlessTarget target(ctx);
  graph::Graph graph;
  target.add_output(graph, pattern.add_to(graph, o.blur));
  graph::GraphRunner runner(ctx, std::move(graph));
  runner.set_viewport(size);
  target.bind(runner);
  print_graph(o, runner);
  runner.run_now();
  write_picture(o.output, size, target.pixels());
  std::printf("wrote %s (%ux%u)\n", o.output.c_str(), size.width, size.height);
}

}  // namespace

void add_render_command(CLI::App& app, DeviceOptions& device) {
  CLI::App* cmd =
      app.add_subcommand("render", "Render a scene offline and write it as PNG, JPEG, SVG or PDF");
  auto o = std::make_shared<RenderOptions>();
  cmd->add_option("scene", o->scene.file,
                  "scene file (.json, or .xml of the thesis program), or a volume (.nii, .nii.gz, "
                  ".mhd, .mha, .nrrd, .nhdr, a DICOM file or folder); none: a test pattern");
  cmd->add_option(
         "-o,--output", o->output,
         "image to write: .png, .jpg, .jpeg, or .svg or .pdf (labels as vector shapes and text)")
      ->capture_default_str();
  add_scene_input_options(cmd, o->scene);
  cmd->add_option("--size", o->size, "image size, N or WxH")->capture_default_str();
  cmd->add_option("--camera", o->camera,
                  "named camera position of the scene, or several (front,left): one image each, "
                  "named after it (out-front.png, out-left.png)");
  add_tidy_rounds_option(cmd, o->tidy_rounds, "after the placement (0: none)");
  cmd->add_option("--dump-layers", o->dump_layers,
                  "folder to write each (label-free) layer image to, beside the -o image");
  cmd->add_flag("--no-skipping", o->no_skipping, "turn empty-space skipping off");
  cmd->add_flag("--no-labels", o->no_labels, "render the scene without its labels");
  add_hard_option(cmd, o->hard);
  add_greedy_option(cmd, o->greedy);
  cmd->add_flag("--internal", o->internal, "internal labelling: labels drawn on their anchors");
  add_label_look_options(cmd, o->look);
  add_background_option(cmd, o->background);
  add_annotation_options(cmd, o->notes);
  cmd->add_option("--order", o->order,
                  "insertion order: scene, apollonius (Stein & Decoret, innermost first) or "
                  "optimized (random orders, the best kept)")
      ->check(CLI::IsMember({"scene", "apollonius", "optimized"}))
      ->capture_default_str();
  cmd->add_flag("--decoret", o->decoret,
                "Stein & Decoret's setting: one layer, Apollonius order, hard constraints");
  cmd->add_option("--layout", o->layout,
                  "JSON file to write each label's layer, anchor, box, cost");
  cmd->add_flag("--dump-graph", o->dump_graph,
                "print the frame's render graph: passes, their uses and barriers");
  cmd->add_option("--blur", o->blur, "test pattern only: box-filter radius of its right half")
      ->check(whole_range(0, 16384))
      ->capture_default_str();
  cmd->callback([cmd, &device, o] {
    // An unknown image extension is a usage error, found before any work (and before -o exists).
    try {
      check_picture_extension(o->output);
    } catch (const Error& e) {
      throw UsageError(std::string("-o: ") + e.what());
    }
    if (o->background.transparent && !vector_format(o->output) && !image_keeps_alpha(o->output))
      throw UsageError("--background transparent: " + o->output +
                       ": JPEG has no alpha; write a PNG, SVG or PDF");
    check_options_apply(cmd, !o->scene.file.empty(), {"--output", "--size", "--dump-graph"},
                        {"--blur"});
    if (o->no_labels && o->notes.any()) {
      throw UsageError("--title and --legend: a picture without labels (--no-labels) has none");
    }
    if (o->scene.file.empty()) {
      render_test_pattern(device, *o);
    } else if (o->no_labels) {
      render_scene(device, *o);
    } else {
      render_labelled_scene(device, *o);
    }
  });
}

}  // namespace strata::app
