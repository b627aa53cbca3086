// `strata video`: the labelled scene along a camera path or a turntable, one frame every 1 / fps
// seconds, with the labels moved by the forces between frames (a fixed time step, so the same
// command gives the same frames). By default the path is first rehearsed without writing a frame
// and each label's active ranges planned over all of it (labeling/video_plan.h); `--plan off`
// places every frame as the viewer would. Frames go into an H.264 MP4 (-o NAME.mp4), a looping GIF
// (-o NAME.gif) or a folder as a numbered PNG sequence, and with --layout-dir each frame's layout
// as JSON (for `strata eval`), with --still-layouts a still placement's of the same camera, and
// with --report the layout-quality summary of `strata eval` over the frames at the end.
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>

#include "app/annotation_options.h"
#include "app/commands.h"
#include "app/output_files.h"
#include "app/progress.h"
#include "engine/core/frame_writer.h"
#include "engine/core/text_file.h"
#include "frame/labelled_render.h"
#include "labeling/camera_path.h"
#include "labeling/layout_metrics.h"
#include "labeling/video_plan.h"

namespace strata::app {
namespace {

struct VideoOptions {
  SceneInput scene;
  std::string path;
  double orbit = 0.0;    // degrees; 0: --path
  double seconds = 0.0;  // of the orbit; 0 (not given): 30 degrees a second
  std::string camera;    // where the orbit starts
  double fps = 30.0;
  std::string size = "512";
  std::string output;
  std::string layout_dir;
  std::string still_layouts;
  bool report = false;
  bool screen_space = false;
  bool no_forces = false;
  bool hard = false;
  PlacementMethod greedy = PlacementMethod::sequential;
  bool plan = true;  // --plan: the labels' ranges planned over the whole path first
  LabelLookOptions look;
  Background background;
  AnnotationOptions notes;
  ForceSettings forces;
  float layer_margin = LayerHysteresis{}.margin;
  uint32_t tidy_rounds = PlacementSettings{}.tidy_rounds;
  unsigned threads = 0;  // frames compressed at once (0: writer_threads decides)
};

CameraPath camera_path(const Scene& scene, const VideoOptions& o) {
  if (!o.path.empty() && o.orbit != 0.0)
    throw UsageError("video: give --path or --orbit, not both");
  if (!o.path.empty()) {
    try {
      return parse_camera_path(scene, o.path);
    } catch (const Error& e) {
      throw UsageError(std::string("--path: ") + e.what());
    }
  }
  if (o.orbit == 0.0)
    throw UsageError("video: give a camera path (--path) or a turntable (--orbit)");
  const double seconds = o.seconds > 0.0 ? o.seconds : std::abs(o.orbit) / 30.0;
  return orbit_path(scene, option_camera(scene, o.camera), o.orbit, seconds);
}

// -o: NAME.mp4, NAME.gif, or a folder for PNG frames (no extension, or one that exists). Anything
// else (x.avi) is a usage error, not a folder of PNGs nobody asked for; so is a transparent
// background in a video, which keeps no alpha.
FrameWriter::Format output_format(const std::filesystem::path& output,
                                  const Background& background) {
  std::string extension = output.extension().string();
  for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".mp4" || extension == ".gif") {
    if (background.transparent) {
      throw UsageError("--background transparent: " + output.string() +
                       " keeps no alpha; write PNG frames to a folder");
    }
    return extension == ".gif" ? FrameWriter::Format::gif : FrameWriter::Format::mp4;
  }
  std::error_code error;
  if (extension.empty() || std::filesystem::is_directory(output, error))
    return FrameWriter::Format::png_folder;
  throw UsageError("-o: '" + output.string() + "': cannot write a video as '" +
                   output.extension().string() +
                   "' (expected NAME.mp4, NAME.gif, or a folder without an extension for PNG "
                   "frames)");
}

// A frame's layout as `strata eval` reads it (the JSON parsed back, so that a plan and the report
// see exactly what the files say).
Layout measured_layout(const LabelledFrame& frame, size_t f) {
  return parse_layout(nlohmann::json::parse(layout_json(frame)), frame_file_name(f, "json"));
}

// A frame's layout: written into `folder` (empty: not written), and kept for the report.
void record_layout(const std::string& folder, size_t f, const LabelledFrame& frame,
                   const Layout& layout, std::vector<Layout>* kept) {
  if (!folder.empty())
    write_text_file(std::filesystem::path(folder) / frame_file_name(f, "json"), layout_json(frame));
  if (kept) kept->push_back(layout);
}

LabellingSettings labelling_settings(const Scene& scene, const VideoOptions& o) {
  LabellingSettings settings;
  settings.layer_count = o.scene.layer_count(scene);
  settings.placement.weights = scene.settings.weights;
  settings.placement.hard = o.hard;
  settings.placement.method = o.greedy;
  settings.placement.tidy_rounds = o.tidy_rounds;
  settings.label_scale = o.look.label_scale;
  settings.layer_colors = o.look.layer_colors;
  settings.ghost = look_ghosting(o.look, scene);
  settings.background = o.background;
  settings.forces = o.forces;
  settings.forces.anchor_relative = !o.screen_space;
  settings.hysteresis.margin = o.layer_margin;
  return settings;
}

// The cameras sampled along the path, a usage error past kMaxVideoFrames (checked before sample()
// allocates a camera a frame).
std::vector<Camera> sampled_cameras(const CameraPath& path, double fps) {
  if (const double frames = sampled_frames(path, fps); frames > double(kMaxVideoFrames)) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "--fps: %g frames a second for %g s is %.0f frames, more than %u", fps,
                  path.duration(), frames, kMaxVideoFrames);
    throw UsageError(text);
  }
  return sample(path, fps);
}

// Frames are compressed on a thread per core while a GPU renders the next one. A CPU device
// (lavapipe) renders on every core itself: there the frames are written one after another.
unsigned writer_threads(const Context& ctx, const VideoOptions& o) {
  if (o.threads) return o.threads;
  return ctx.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU ? 1 : default_frame_threads();
}

FrameWriter::Settings writer_settings(const Context& ctx, FrameWriter::Format format,
                                      graph::Extent size, const VideoOptions& o) {
  return {.format = format,
          .width = size.width,
          .height = size.height,
          .fps = o.fps,
          .threads = writer_threads(ctx, o)};
}

// Frame `f` of the sequence: the first is the still that run() placed, every other one a time
// step of the forces (or, with --no-forces, placed from scratch) at its camera.
LabelledFrame next_frame(LabelledRenderer& renderer, const Camera& camera, size_t f,
                         const VideoOptions& o, bool measured) {
  if (f > 0) {
    renderer.set_camera(camera);
    if (o.no_forces) {
      renderer.run();  // every frame placed from scratch: today's behaviour, for comparison
    } else {
      renderer.advance(1.0 / o.fps);
    }
  }
  LabelledFrame frame = renderer.result(measured);
  if (f > 0) frame.seconds = 1.0 / o.fps;  // (with --no-forces too: a frame of the sequence)
  return frame;
}

// "wrote 31 frames (1920x1080, 30 fps) to DIR in 1.2 s, 25.8 frames/s"
void print_written(const VideoOptions& o, graph::Extent size, size_t frames, double seconds) {
  const double rate = seconds > 0.0 ? double(frames) / seconds : 0.0;
  std::printf("wrote %zu frames (%ux%u, %g fps) to %s in %.1f s, %.*f frames/s\n", frames,
              size.width, size.height, o.fps, o.output.c_str(), seconds, rate < 10.0 ? 2 : 1, rate);
}

// The folders of numbered files the video writes: PNG frames (-o FOLDER) and layouts.
std::vector<FrameFolder> frame_folders(const VideoOptions& o, bool video) {
  std::vector<FrameFolder> folders;
  if (!video) folders.push_back({"-o", o.output, "png"});
  if (!o.layout_dir.empty()) folders.push_back({"--layout-dir", o.layout_dir, "json"});
  if (!o.still_layouts.empty()) folders.push_back({"--still-layouts", o.still_layouts, "json"});
  return folders;
}

// Every output is checked before anything renders; then the folders are made and cleared of an
// earlier run's frames before the video is opened, so a folder that cannot be made leaves no video.
void prepare_outputs(const VideoOptions& o, bool video, size_t frames) {
  const std::vector<FrameFolder> folders = frame_folders(o, video);
  if (video) check_output_file("-o", o.output);
  for (const FrameFolder& f : folders) f.check(frames);
  // (the frames' layouts and the stills' have the same names)
  const auto same = [](const std::filesystem::path& a, const std::filesystem::path& b) {
    std::error_code error;
    return std::filesystem::weakly_canonical(a, error) ==
           std::filesystem::weakly_canonical(b, error);
  };
  if (!o.layout_dir.empty() && !o.still_layouts.empty() && same(o.layout_dir, o.still_layouts))
    throw UsageError("--still-layouts: " + o.still_layouts +
                     " is --layout-dir's folder too: the stills' layouts would replace the "
                     "frames'; give another folder");
  for (const FrameFolder& f : folders) {
    create_output_folder(f.option, f.folder);
    f.remove_earlier_frames();
  }
}

// What every drawing of the path shares.
struct PathDrawing {
  Context& ctx;
  const Scene& scene;
  const std::vector<Camera>& cameras;
  graph::Extent size;
  LabellingSettings settings;
  const VideoOptions& o;
};

// Each frame of a drawing with its layout where one was made (`visible` NaN and `shown` placed
// where legibility was not measured).
using FrameDone = std::function<void(size_t f, LabelledFrame& frame, const Layout* layout)>;

// The path drawn once by a renderer of its own (so that every drawing starts alike and the same
// plan gives the same frames). With a plan (`follower`), each frame leaves out the labels it
// withholds; `measured`: legibility read (the layers downloaded) and the layouts made, as they are
// for a plan.
void draw_path(const PathDrawing& d, PlanFollower* follower, bool measured, const FrameDone& done,
               bool layouts = false) {
  LabelledRenderer renderer(d.ctx, d.scene, d.cameras.front(), d.size, d.settings);
  for (size_t f = 0; f < d.cameras.size(); ++f) {
    if (follower) renderer.set_withheld(follower->withheld(f));
    if (f == 0) renderer.run();  // the first frame: the labels settled on their placement
    LabelledFrame frame = next_frame(renderer, d.cameras[f], f, d.o, measured);
    std::optional<Layout> layout;
    if (measured || layouts || follower) layout = measured_layout(frame, f);
    if (follower) follower->saw(*layout);
    done(f, frame, layout ? &*layout : nullptr);
  }
}

std::vector<int> label_ids(const Scene& scene) {
  std::vector<int> ids;
  for (const Label& label : scene.labels) ids.push_back(label.id);
  return ids;
}

// Rehearsals with a plan, at most, after the free one.
constexpr int kMaxPlannedRehearsals = 3;

// Each label's ranges over the whole path (labeling/video_plan.h): a free rehearsal gives the
// first plan, and each rehearsal with it drops the ranges it drew short, until it drew none.
ActiveRanges plan_video(const PathDrawing& d) {
  Progress progress("rehearsal frame", size_t(kMaxPlannedRehearsals + 1) * d.cameras.size());
  const std::vector<int> ids = label_ids(d.scene);
  int rehearsals = 0;
  // (legibility is not read: a plan keeps what is drawn, so that --layout-dir changes no frame)
  const auto rehearse = [&](PlanFollower* follower) {
    std::vector<Layout> layouts;
    const size_t before = size_t(rehearsals++) * d.cameras.size();
    draw_path(
        d, follower, false,
        [&](size_t f, LabelledFrame&, const Layout* layout) {
          layouts.push_back(*layout);
          progress.step_done(before + f + 1);
        },
        true);
    return layouts;
  };
  const double lead = d.settings.forces.fade_seconds * opaque_opacity + 1.0 / d.o.fps;
  ActiveRanges plan = first_plan(rehearse(nullptr), lead);
  size_t dropped = 0;
  for (int k = 0; k < kMaxPlannedRehearsals; ++k) {
    PlanFollower follower(plan, ids);
    const size_t short_ranges = drop_short_ranges(plan, rehearse(&follower));
    dropped += short_ranges;
    if (short_ranges == 0) break;
  }
  size_t ranges = 0;
  for (const auto& [id, r] : plan) ranges += r.size();
  std::printf(
      "planned %zu ranges of %zu labels in %d rehearsals (%zu short ones dropped), %.1f s\n",
      ranges, plan.size(), rehearsals, dropped, progress.seconds());
  return plan;
}

void video(DeviceOptions& device, const VideoOptions& o) {
  const graph::Extent size = parse_size(o.size, "--size");
  const std::filesystem::path output = o.output;
  const FrameWriter::Format format = output_format(output, o.background);
  const bool video_file = format != FrameWriter::Format::png_folder;
  Context ctx(device.context());
  const Scene scene = load_scene_reporting(o.scene, ctx);
  const std::vector<Camera> cameras = sampled_cameras(camera_path(scene, o), o.fps);
  prepare_outputs(o, video_file, cameras.size());
  // --title, --legend: one layout for every frame, the legend of all the scene's labels (so it
  // stays the same while labels come and go).
  LabellingSettings settings = labelling_settings(scene, o);
  std::optional<Annotations> notes;
  AnnotationLayout notes_layout;
  if (o.notes.any()) {
    notes.emplace(o.notes, settings, glm::uvec2(size.width, size.height));
    notes_layout = notes->layout(legend_entries(scene));
    keep_labels_off(settings, notes_layout);
  }
  const PathDrawing drawing{ctx, scene, cameras, size, settings, o};
  std::optional<PlanFollower> follower;
  if (o.plan) follower.emplace(plan_video(drawing), label_ids(scene));

  // Frames are compressed on worker threads while the next one renders; a video goes to a
  // temporary file, put in place by finish(): an error on the way leaves no video.
  FrameWriter writer(output, writer_settings(ctx, format, size, o));
  Progress progress("frame", cameras.size());
  // --still-layouts: a second renderer places every frame's camera afresh, as a still.
  std::unique_ptr<LabelledRenderer> still;
  if (!o.still_layouts.empty()) {
    still = std::make_unique<LabelledRenderer>(ctx, scene, cameras.front(), size, drawing.settings);
  }
  // (legibility only where a layout is written: it reads the layers back)
  const bool measured = !o.layout_dir.empty() || o.report;
  std::vector<Layout> frame_layouts, still_layouts;  // for the report
  draw_path(drawing, follower ? &*follower : nullptr, measured,
            [&](size_t f, LabelledFrame& frame, const Layout* layout) {
              if (notes) notes->draw(frame.image, notes_layout);
              writer.write(std::move(frame.image));  // (the picture is the frame's own copy)
              if (measured)
                record_layout(o.layout_dir, f, frame, *layout, o.report ? &frame_layouts : nullptr);
              if (still) {
                still->set_camera(cameras[f]);
                still->run();
                const LabelledFrame placed = still->result();
                record_layout(o.still_layouts, f, placed, measured_layout(placed, f),
                              o.report ? &still_layouts : nullptr);
              }
              if (f + 1 < cameras.size()) progress.step_done(f + 1);  // (the last once written)
            });
  writer.finish();
  progress.step_done(cameras.size());
  print_written(o, size, cameras.size(), progress.seconds());
  if (o.report) {
    const std::string report =
        to_json(sequence_metrics(frame_layouts, still_layouts), false).dump(2);
    std::printf("%s\n", report.c_str());
  }
}

// The camera's way and what is written: the path or turntable, the frame rate and size, the
// video and the layouts.
void add_path_and_output_options(CLI::App* cmd, const std::shared_ptr<VideoOptions>& o) {
  cmd->add_option("--path", o->path, "camera path: front,left_2,top_3 (docs/scene-format.md)");
  cmd->add_option("--orbit", o->orbit, "turntable: degrees about the scene's centre")
      ->check(finite_range(-36000.0, 36000.0));
  cmd->add_option("--seconds", o->seconds,
                  "duration of the turntable (default: 30 degrees a second)")
      ->check(finite_range(0.0, kMaxPathSeconds, true));
  cmd->add_option("--camera", o->camera, "named position the turntable starts from");
  cmd->add_option("--fps", o->fps, "frames per second")
      ->check(finite_range(1.0, 240.0))
      ->capture_default_str();
  cmd->add_option("--size", o->size, "image size, N or WxH")->capture_default_str();
  cmd->add_option("-o,--output", o->output,
                  "NAME.mp4 (H.264), NAME.gif (looping, one palette), or a folder for PNG frames")
      ->required();
  cmd->add_option("--layout-dir", o->layout_dir, "folder for each frame's layout JSON");
  cmd->add_option("--still-layouts", o->still_layouts,
                  "folder for the layout of a still placement of each frame's camera (one more "
                  "frame rendered per frame; `strata eval --stills`)");
  cmd->add_flag("--report", o->report,
                "print the layout-quality summary of `strata eval` over the frames (stdout, "
                "JSON) at the end");
}

// How the labels are placed in each frame.
void add_placement_options(CLI::App* cmd, const std::shared_ptr<VideoOptions>& o) {
  add_tidy_rounds_option(cmd, o->tidy_rounds, "after the placement (0: none)");
  cmd->add_flag("--screen-space", o->screen_space,
                "labels live on screen (the thesis), not as offsets from their anchors");
  cmd->add_flag("--no-forces", o->no_forces, "place every frame from scratch (labels jump)");
  cmd->add_option_function<std::string>(
         "--plan",
         [o](const std::string& value) {
           if (value != "on" && value != "off")
             throw UsageError("--plan: '" + value + "': expected on or off");
           o->plan = value == "on";
         },
         "on: each label's active ranges planned over the whole path before the frames are drawn "
         "(one steady range per stretch in view); off: every frame placed as the viewer would")
      ->default_str("on");
  add_hard_option(cmd, o->hard);
  add_greedy_option(cmd, o->greedy);
  add_label_look_options(cmd, o->look);
  add_background_option(cmd, o->background);
  add_annotation_options(cmd, o->notes);
}

// How the labels move from frame to frame (labeling/forces.h).
void add_force_options(CLI::App* cmd, const std::shared_ptr<VideoOptions>& o) {
  cmd->add_option("--label-speed", o->forces.speed_widths,
                  "forces: image widths per second a label moves at, at most")
      ->capture_default_str()
      ->check(finite_range(0.001, 10.0));
  cmd->add_option("--ease-in", o->forces.ease_in_seconds,
                  "seconds a label takes to get up to full speed (0: at once)")
      ->capture_default_str()
      ->check(finite_range(0.0, 10.0));
  // (pixels per second once: the same speed moved labels 4 times as far at a quarter the size)
  cmd->add_option_function<std::string>(
         "--speed",
         [](const std::string&) {
           throw UsageError(
               "--speed (pixels per second) is now --label-speed, in image widths per second "
               "(90 px/s at 1024 px wide is 0.088)");
         })
      ->group("");
  cmd->add_option("--hold", o->forces.hold_share,
                  "a label keeps its target unless a position costs less by this share of its "
                  "cost (plus --hold-cost)")
      ->capture_default_str()
      ->check(finite_range(0.0, 100.0));
  cmd->add_option("--hold-cost", o->forces.hold_cost, "the hold's fixed part (eq. 3.1 units)")
      ->capture_default_str()
      ->check(finite_range(0.0, 1e9));
  cmd->add_option("--fade", o->forces.fade_seconds, "seconds a label takes to fade in or out")
      ->capture_default_str()
      ->check(finite_range(0.0, 60.0));
  cmd->add_flag_callback(
      "--let-overlap", [o] { o->forces.keep_apart = false; },
      "let labels on their way pass over others and the image's edge (the thesis); default: "
      "drawn boxes are kept apart and inside the image");
  cmd->add_option("--wait", o->forces.wait_seconds,
                  "seconds a label whose way is taken waits before it fades out to fade in at "
                  "its target")
      ->capture_default_str()
      ->check(finite_range(0.0, 60.0));
  cmd->add_option("--previous-weight", o->forces.previous_weight,
                  "eq. 3.1's eta after the first frame: cost per pixel of distance to a label's "
                  "last target")
      ->capture_default_str()
      ->check(finite_range(0.0, 1e6));
  cmd->add_option("--layer-margin", o->layer_margin,
                  "layer hysteresis: how far past its slab an anchor goes before its label "
                  "changes layer, as a share of the distance to the next plane")
      ->capture_default_str()
      ->check(finite_range(0.0, 100.0));
}

}  // namespace

void add_video_command(CLI::App& app, DeviceOptions& device) {
  CLI::App* cmd = app.add_subcommand(
      "video", "Render the labelled scene along a camera path or a turntable, frame by frame");
  auto o = std::make_shared<VideoOptions>();
  cmd->add_option("scene", o->scene.file, "scene file, or a volume file or DICOM folder")
      ->required();
  add_scene_input_options(cmd, o->scene);
  add_path_and_output_options(cmd, o);
  add_placement_options(cmd, o);
  add_force_options(cmd, o);
  cmd->add_option("--threads", o->threads,
                  "threads compressing frames (default: one per core; 1 on a CPU device, where "
                  "rendering takes every core)")
      ->check(whole_range(1, 1024));
  cmd->callback([&device, o] { video(device, *o); });
}

}  // namespace strata::app
