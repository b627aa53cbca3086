// The strata program's subcommands and what they share: option values (option_values.cpp,
// option_range.cpp), options declared alike (shared_options.cpp) and the scene input
// (scene_input.cpp). main.cpp builds the command line from the add_*_command functions, parses it
// and prints errors.
#pragma once

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "engine/core/background.h"
#include "engine/core/error.h"
#include "engine/gpu/context.h"
#include "engine/graph/render_graph.h"
#include "engine/scene/scene.h"

namespace strata {
struct Ghosting;                // frame/labelled_render.h
enum class PlacementMethod;     // passes/placement.h
}

namespace strata::app {

// An option's value that cannot be used (--size 0, --fps 1000, --camera ','): like CLI11's own
// parse errors, main prints it with the error prefix and exits 2, the usage-error code.
class UsageError : public Error {
 public:
  using Error::Error;
};

// COUNT numbers separated by commas, each within 1e9, for `option` (a usage error naming `form`
// otherwise).
std::vector<float> parse_numbers(const std::string& text, size_t count, const char* option,
                                 const char* form);
// --window's "CENTER,WIDTH" (the volume's values; a usage error otherwise).
glm::vec2 parse_window(const std::string& text);

// The scene's camera position an option names (--camera): an unknown name is a usage error that
// names the option and the scene's positions.
Camera option_camera(const Scene& scene, const std::string& name, const char* option = "--camera");

// Numeric options: the text must be a finite number in [lo, hi] ((lo, hi] with open_low); NaN,
// infinities, words and values outside are usage errors (exit 2) that name the option and the
// range: "--seconds: nan is not a number in (0, 3600]". The text is checked before CLI11 converts
// it, so the same check serves float and integer options; whole_range also refuses fractions.
CLI::Validator finite_range(double lo, double hi, bool open_low = false);
CLI::Validator whole_range(double lo, double hi);

// Options every subcommand that opens a device shares.
struct DeviceOptions {
  std::string device;     // --device NAME|INDEX
  bool validate = false;  // --validate (also STRATA_VALIDATE=1; always on in debug builds)
  ContextOptions context() const;
};

// Every option of `app` and its subcommands that takes a value refuses an empty one ("--layout
// ''"): a usage error naming the option, not a default taken silently.
void refuse_empty_values(CLI::App& app);
// With no scene (render and view draw a test pattern) only `pattern_options` apply; with a scene
// the pattern's own (--blur) do not: any other option given is a usage error naming it.
void check_options_apply(const CLI::App* cmd, bool has_scene,
                         std::initializer_list<const char*> pattern_options,
                         std::initializer_list<const char*> pattern_only);

// The scene a command works on: a scene file, or a volume file or DICOM folder opened as one
// (docs/scene-format.md), and what the command line adds or overrides.
struct SceneInput {
  std::string file;
  std::string preset;             // --preset: every volume's transfer function
  std::string labels;             // --labels: a label file (.mrk.json, .fcsv, .csv) added
  std::string segmentation;       // --segmentation: its regions as labels (segmentation.h)
  std::string names;              // --names: its names table
  std::vector<std::string> regions;  // --regions: the regions chosen
  std::vector<std::string> make;     // --make: labels, masks, surfaces
  int frame = -1;                 // --frame: a 4-D volume's frame (-1: the first, with a warning)
  std::string series;             // --series: a DICOM folder's series (SeriesNumber or UID)
  std::string window;             // --window CENTER,WIDTH: a grey ramp in the volumes' values
  std::string crop;               // --crop X0,Y0,Z0,X1,Y1,Z1 (world, mm)
  std::vector<std::string> clip;  // --clip PX,PY,PZ,NX,NY,NZ, up to six
  std::optional<bool> fit;        // --fit, --no-fit: views fitted to what the cut-aways keep
  uint32_t layers = 0;            // --layers: 0 keeps the scene's settings.layers
  // The depth layers asked for: --layers, else the scene's.
  uint32_t layer_count(const Scene& scene) const;
};
// --preset, --labels, --frame, --window, --crop, --clip, --fit, --series and --layers (the
// positional FILE is the command's own).
void add_scene_input_options(CLI::App* cmd, SceneInput& in);

// Loads the scene (load_scene with the input's options) and prints its warnings (missing data
// files, a transfer-function preset chosen, ...) to stderr.
Scene load_scene_reporting(const SceneInput& in);
// The same, each volume checked against what the device can render (device_volume_limits) from
// its header, before its voxels are read.
Scene load_scene_reporting(const SceneInput& in, const Context& ctx);
Scene load_scene_reporting(const std::string& path);

// A file of strata's data (a demo scene): under the working folder if it is there, else beside
// the program (build/app/strata: the source tree's; bin/strata: share/strata/), else an Error.
std::string find_data_file(const std::string& relative);

// How labels look (render and video): --label-scale, --layer-colors and ghosting.
struct LabelLookOptions {
  float label_scale = 1.0f;
  bool layer_colors = false;
  std::optional<float> ghost;         // else the scene's settings.ghost
  std::optional<float> ghost_radius;  // else the scene's settings.ghost_radius
  bool ghost_leaders = false;
};
void add_label_look_options(CLI::App* cmd, LabelLookOptions& o);
// --tidy-rounds (render, video, view, bench view): rounds of the tidy-up, run `when`.
void add_tidy_rounds_option(CLI::App* cmd, uint32_t& rounds, const char* when);
// --hard (render, video): hard constraints.
void add_hard_option(CLI::App* cmd, bool& hard);
// --greedy (render, video, bench placement): the greedy placement in rounds or one by one.
void add_greedy_option(CLI::App* cmd, PlacementMethod& method);
// The ghosting asked for: the options, else the scene's settings.
Ghosting look_ghosting(const LabelLookOptions& o, const Scene& scene);

// --background's black, white, transparent or #rrggbb; a UsageError naming the option otherwise.
Background parse_background(const std::string& text);
// --background (render, video, view): the picture's background, parse_background's.
void add_background_option(CLI::App* cmd, Background& background);

// "1024" or "1024x768"; throws UsageError naming the option when it is neither or a side is outside
// 1 to 16384 (the device's own limit is checked when it is open: check_image_size).
graph::Extent parse_size(const std::string& text, const char* option);
// A UsageError naming the option and the device's limit when `size` is over maxImageDimension2D.
void check_image_size(const Context& ctx, graph::Extent size, const char* option);

// --placement (view, bench view): "beside" the frames on a queue of its own, in the "frame", or
// "auto": beside where the device has a second queue (Context::separate_placement_queue).
void add_placement_option(CLI::App* cmd, std::string& mode);
bool placement_beside(const std::string& mode, const Context& ctx);

void add_devices_command(CLI::App& app, DeviceOptions& device);
void add_render_command(CLI::App& app, DeviceOptions& device);
void add_view_command(CLI::App& app, DeviceOptions& device);
void add_bench_command(CLI::App& app, DeviceOptions& device);
void add_info_command(CLI::App& app);
void add_eval_command(CLI::App& app);
void add_video_command(CLI::App& app, DeviceOptions& device);
void add_pick_command(CLI::App& app, DeviceOptions& device);
// `bench encode` (app/bench_encode.cpp), added to the `bench` command.
void add_encode_bench(CLI::App* bench);
void add_segmentation_bench(CLI::App* bench);

}  // namespace strata::app
