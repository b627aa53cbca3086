// Writes that cannot lose data, end to end: a write that fails (a file-size limit standing in for
// a full disk, a folder that cannot be made) leaves the old file or nothing; an output extension
// strata cannot write is a usage error before any work; no output replaces a file the command
// read; every output is checked before anything renders; a folder of frames holds one run; the
// viewer's "save position" writes only the scene it opened, or a new file, and every scene it
// writes loads.
#include <doctest/doctest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "engine/core/files_read.h"
#include "engine/core/frame_writer.h"
#include "engine/core/png.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/io/volume_loader.h"
#include "gpu_fixture.h"
#include "test_files.h"

namespace fs = std::filesystem;

namespace strata {
namespace {

using test::run_strata;

// The shell runs strata with its files limited to 1 block (512 or 1024 bytes) and SIGXFSZ
// ignored, so a write past it fails with EFBIG as on a full disk.
const std::string kSmallFiles = "trap '' XFSZ; ulimit -f 1;";

// A small scene of its own files in `dir`: scene.json with the volume scan.mha, its transfer
// function tf.json and a label whose picture is `picture`; labels.csv beside it for --labels.
struct SceneFiles {
  fs::path scene, volume, transfer_function, picture, labels;
};

SceneFiles write_scene(const fs::path& dir, const std::string& picture = "pic.png") {
  SceneFiles files{dir / "scene.json", dir / "scan.mha", dir / "tf.json", dir / picture,
                   dir / "labels.csv"};
  fs::create_directories(dir);
  Volume volume;
  volume.dims = {16, 16, 16};
  volume.voxels.resize(volume.voxel_count());
  for (size_t i = 0; i < volume.voxels.size(); ++i) volume.voxels[i] = std::byte(i * 37 % 256);
  write_metaimage(files.volume, volume, false);
  test::write_file(files.transfer_function,
                   R"({"strata_transfer_function": 1, "stops": [
                      {"position": 0, "color": [1, 1, 1, 0]},
                      {"position": 1, "color": [1, 0.8, 0.6, 0.5]}]})");
  fs::create_directories(files.picture.parent_path());
  write_png(files.picture.string(), 4, 2, std::vector<uint8_t>(4 * 2 * 4, 200));
  test::write_file(files.labels, "label,r,a,s\nB,-8,-8,8\n");
  test::write_file(files.scene, R"({"strata_scene": 1,
    "volumes": [{"file": "scan.mha", "transfer_function": "tf.json"}],
    "labels": [{"id": 1, "text": "A", "anchor": [8, 8, 8], "image": ")" +
                                    picture + R"(", "image_height": 8}]})");
  return files;
}

// strata run so that it cannot write into a folder of mode 0555: as itself, or where it is root
// (who writes anywhere), as the user nobody.
std::string unprivileged() {
  return ::geteuid() == 0 ? "setpriv --reuid=65534 --regid=65534 --clear-groups" : "";
}

// Whether every folder down to `dir` lets others through: a clone in root's home (mode 0700) does
// not, and there the user nobody cannot reach the test's files.
bool others_reach(const fs::path& dir) {
  for (fs::path p = fs::absolute(dir);; p = p.parent_path()) {
    if ((fs::status(p).permissions() & fs::perms::others_exec) == fs::perms::none) return false;
    if (p == p.parent_path()) return true;
  }
}

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("an_input_is_known_by_its_identity_whatever_the_spelling_or_link") {
    const fs::path dir = test::fresh_folder("output_writes", "files_read");
    const fs::path input = test::write_file(dir / "input.json", "{}");
    const fs::path other = test::write_file(dir / "other.json", "{}");
    fs::create_directories(dir / "sub");
    fs::create_symlink(input, dir / "link.json");
    fs::create_hard_link(input, dir / "hard.json");
    const fs::path series = dir / "series";
    const fs::path slice = test::write_file(series / "deeper/IM0001", "DICM");
    record_file_read(input);
    record_file_read(series);
    for (const fs::path& same : {input, dir / "sub/../input.json", dir / "./input.json",
                                 dir / "link.json", dir / "hard.json"}) {
      CAPTURE(same);
      CHECK(input_replaced_by(same) == input);
    }
    CHECK(input_replaced_by(other) == std::nullopt);
    CHECK(input_replaced_by(dir / "new.json") == std::nullopt);
    // A file of a folder read whole is that folder's; a new file there, or the folder, is not.
    CHECK(input_replaced_by(slice) == series);
    CHECK(input_replaced_by(series / "new.png") == std::nullopt);
    CHECK(input_replaced_by(series) == std::nullopt);
  }
}

TEST_SUITE("cli") {
  TEST_CASE("render_that_cannot_write_its_png_leaves_the_old_file_and_no_other") {
    const fs::path dir = test::fresh_folder("output_writes", "render_limit");
    const fs::path png = test::write_file(dir / "out.png", "the old picture");
    const auto before = test::folder_bytes(dir);
    const auto r = run_strata("render --size 128 -o " + png.string(), kSmallFiles);
    INFO(r.output);
    CHECK(r.exit_code == 1);
    CHECK(r.output.find(png.string() + ": cannot write PNG: File too large") != std::string::npos);
    CHECK(test::folder_bytes(dir) == before);
    // (without the limit the same command writes it)
    CHECK(run_strata("render --size 128 -o " + png.string()).exit_code == 0);
    CHECK(test::read_file(png).starts_with("\x89PNG"));
  }

  TEST_CASE("an_output_extension_strata_cannot_write_is_a_usage_error_and_writes_nothing") {
    const fs::path dir = test::fresh_folder("output_writes", "extension");
    const auto render = run_strata("render --size 32 -o " + (dir / "x.bmp").string());
    CHECK(render.exit_code == 2);
    CHECK(render.output.find("-o: " + (dir / "x.bmp").string()) != std::string::npos);
    CHECK(render.output.find(".png, .jpg, .jpeg, .svg or .pdf") != std::string::npos);
    const auto video =
        run_strata("video " STRATA_SOURCE_DIR "/assets/scenes/head.json --orbit 10 --size 32 -o " +
                   (dir / "x.avi").string());
    CHECK(video.exit_code == 2);
    CHECK(video.output.find("-o: '" + (dir / "x.avi").string() + "'") != std::string::npos);
    CHECK(video.output.find("NAME.mp4, NAME.gif, or a folder") != std::string::npos);
    CHECK(fs::is_empty(dir));
  }

  // Each output over one of the files the command read (the scene, its volume, transfer
  // function and label picture, a --labels file), however it is spelled, is refused before
  // anything renders, naming the option and the input; nothing in the folder changes.
  TEST_CASE("no_output_replaces_a_file_the_command_read") {
    const fs::path dir = test::fresh_folder("output_writes", "over_inputs");
    const SceneFiles in = write_scene(dir, "frames/frame-00002.png");
    fs::create_directories(dir / "sub");
    fs::create_symlink(in.scene, dir / "link.json");
    fs::create_hard_link(in.scene, dir / "hard.json");
    const std::string scene = in.scene.string(), out = (dir / "out.png").string();
    const std::string render = "render --size 32 " + scene + " -o ";
    const std::string video = "video " + scene + " --orbit 12 --seconds 0.1 --size 32 -o ";
    struct Case {
      std::string args, option;
      fs::path output, input;
    };
    std::vector<Case> cases = {
        {render + out + " --layout " + scene, "--layout", in.scene, in.scene},
        {render + out + " --layout " + (dir / "sub/../scene.json").string(), "--layout",
         dir / "sub/../scene.json", in.scene},
        {render + out + " --layout " + (dir / "link.json").string(), "--layout", dir / "link.json",
         in.scene},
        {render + out + " --layout " + (dir / "hard.json").string(), "--layout", dir / "hard.json",
         in.scene},
        {render + out + " --labels " + in.labels.string() + " --layout " + in.labels.string(),
         "--layout", in.labels, in.labels},
        {render + in.picture.string(), "-o", in.picture, in.picture},
        {render + in.picture.string() + " --no-labels", "-o", in.picture, in.picture},
        {render + out + " --layout " + in.transfer_function.string(), "--layout",
         in.transfer_function, in.transfer_function},
        {render + out + " --layout " + in.volume.string(), "--layout", in.volume, in.volume},
        {video + (dir / "frames").string(), "-o", in.picture, in.picture},
        {"bench soak " + scene + " --frames 1 --json " + scene, "--json", in.scene, in.scene},
    };
    // (a second scene whose picture lies where --dump-layers writes a layer)
    const SceneFiles layers = write_scene(dir / "second", "layers/layer-1.png");
    cases.push_back({"render --size 32 " + layers.scene.string() + " -o " + out +
                         " --dump-layers " + (dir / "second/layers").string(),
                     "--dump-layers", layers.picture, layers.picture});
    const auto before = test::folder_bytes(dir);
    for (const Case& c : cases) {
      CAPTURE(c.args);
      const auto r = run_strata(c.args);
      CAPTURE(r.output);
      CHECK(r.exit_code == 2);
      CHECK(r.output.find("strata: error: " + c.option + ": " + c.output.string() +
                          " would replace the input " + c.input.string() + "; give another file") !=
            std::string::npos);
      CHECK(r.output.find("wrote") == std::string::npos);
      CHECK(test::folder_bytes(dir) == before);
    }
    // (the same commands write outputs of their own)
    CHECK(run_strata(render + out + " --layout " + (dir / "layout.json").string()).exit_code == 0);
  }

  // A --layout or --dump-layers that cannot be written is found before anything renders: the
  // error names the option, the folder and why, and no picture is written.
  TEST_CASE("every_output_is_checked_writable_before_anything_renders") {
    const fs::path dir = test::fresh_folder("output_writes", "unwritable");
    const SceneFiles in = write_scene(dir);
    fs::create_directories(dir / "read-only");
    fs::permissions(dir / "read-only", fs::perms(0555));
    fs::create_directories(dir / "open");  // (-o's folder, writable by anyone)
    fs::permissions(dir / "open", fs::perms::all);
    const std::string png = (dir / "open/out.png").string();
    const std::string render = "render --size 32 " + in.scene.string() + " -o " + png;
    struct Case {
      std::string args, message, as;
    };
    const std::vector<Case> cases = {
        {render + " --layout " + (dir / "missing/l.json").string(),
         "--layout: " + (dir / "missing/l.json").string() + ": the folder " +
             (dir / "missing").string() + " does not exist"},
        {render + " --layout " + dir.string(), "--layout: " + dir.string() + ": is a folder"},
        {render + " --dump-layers " + (in.scene / "layers").string(),
         "--dump-layers: " + (in.scene / "layers").string() +
             ": cannot create the folder: " + in.scene.string() + " is not a folder"},
        {render + " --dump-layers " + (dir / "read-only/layers").string(),
         "--dump-layers: " + (dir / "read-only/layers").string() +
             ": cannot create the folder: cannot write into the folder " +
             (dir / "read-only").string() + ": Permission denied",
         unprivileged()},
        {render + " --layout " + (dir / "read-only/l.json").string(),
         "--layout: " + (dir / "read-only/l.json").string() + ": cannot write into the folder " +
             (dir / "read-only").string() + ": Permission denied",
         unprivileged()},
    };
    for (const Case& c : cases) {
      CAPTURE(c.args);
      if (!c.as.empty() && !others_reach(dir)) {
        MESSAGE("not run as the user nobody, who cannot reach " << dir.string());
        continue;
      }
      const auto r = run_strata(c.args, c.as);
      CAPTURE(r.output);
      CHECK(r.exit_code == 1);
      CHECK(r.output.find("strata: error: " + c.message) != std::string::npos);
      CHECK(!fs::exists(png));
    }
  }

  // A second run into the folders of a first, with fewer frames, leaves only its own frames and
  // layouts (the first run's are removed, and said so); files of other names stay.
  TEST_CASE("frames_into_a_folder_of_an_earlier_run_leave_only_this_runs_frames") {
    const fs::path dir = test::fresh_folder("output_writes", "earlier_frames");
    const SceneFiles in = write_scene(dir);
    const fs::path frames = dir / "frames", layouts = dir / "layouts";
    const std::string video = "video " + in.scene.string() + " --size 32 --fps 30 --orbit 12 -o " +
                              frames.string() + " --layout-dir " + layouts.string();
    REQUIRE(run_strata(video + " --seconds 0.3").exit_code == 0);
    CHECK(test::folder_bytes(frames).size() == 10);
    const std::vector<std::string> others = {"frame-1.png", "frame-000001.png", "notes.txt",
                                             "frame-00001.png.txt"};
    for (const std::string& name : others) test::write_file(frames / name, "not a frame");
    const auto r = run_strata(video + " --seconds 0.1");
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    CHECK(r.output.find("strata: " + frames.string() +
                        ": removed 10 png files of an earlier run (frame-00000.png to "
                        "frame-00009.png)") != std::string::npos);
    CHECK(r.output.find("strata: " + layouts.string() + ": removed 10 json files") !=
          std::string::npos);
    std::vector<std::string> expected = others;
    for (size_t f = 0; f < 4; ++f) expected.push_back(frame_file_name(f, "png"));
    std::vector<std::string> found;
    for (const auto& [name, bytes] : test::folder_bytes(frames)) found.push_back(name);
    std::sort(expected.begin(), expected.end());
    CHECK(found == expected);
    CHECK(test::folder_bytes(layouts).size() == 4);
    // The stills' layouts would replace the frames' of the same names.
    const auto same =
        run_strata(video + " --seconds 0.1 --still-layouts " + layouts.string() + "/.");
    CHECK(same.exit_code == 2);
    CHECK(same.output.find("--still-layouts: " + layouts.string() +
                           "/. is --layout-dir's folder too") != std::string::npos);
  }

#if STRATA_VIDEO
  // An MP4 on a full disk (a file-size limit of 4 KiB) fails at the first frame that does not
  // fit, before the rest are rendered, not at the index after all of them (the whole video, about
  // 20 KiB, would fit FFmpeg's buffer).
  TEST_CASE("video_on_a_full_disk_fails_at_the_first_frame_that_does_not_fit") {
    const fs::path dir = test::fresh_folder("output_writes", "full_disk");
    const SceneFiles in = write_scene(dir);
    const fs::path mp4 = dir / "out.mp4";
    const auto r =
        run_strata("video " + in.scene.string() +
                       " --size 64 --fps 30 --orbit 180 --seconds 1.5 -o " + mp4.string(),
                   "trap '' XFSZ; ulimit -f 4;");
    INFO(r.output);
    CHECK(r.exit_code == 1);
    CHECK(r.output.find(mp4.string() + ": writing a frame: File too large") != std::string::npos);
    CHECK(!fs::exists(mp4));
    // A disk with no room at all (/dev/full) fails at the header, before the first frame.
    fs::create_symlink("/dev/full", dir / "full.mp4");
    const auto full =
        run_strata("video " + in.scene.string() + " --size 32 --orbit 12 --seconds 0.1 -o " +
                   (dir / "full.mp4").string());
    CHECK(full.exit_code == 1);
    CHECK(full.output.find("full.mp4: writing the header: No space left on device") !=
          std::string::npos);
  }

  TEST_CASE("video_that_cannot_write_its_mp4_or_make_its_layout_folder_leaves_no_mp4") {
    const fs::path dir = test::fresh_folder("output_writes", "video");
    const std::string video = "video " STRATA_SOURCE_DIR
                              "/assets/scenes/head.json --orbit 12 --seconds 0.1 --size 64 -o ";
    const fs::path old_mp4 = test::write_file(dir / "old.mp4", "the old video");
    const auto before = test::folder_bytes(dir);
    const auto limited = run_strata(video + old_mp4.string(), kSmallFiles);
    INFO(limited.output);
    CHECK(limited.exit_code == 1);
    CHECK(limited.output.find("File too large") != std::string::npos);
    CHECK(test::folder_bytes(dir) == before);
    // A layout folder inside a file cannot be made: found before the video is opened.
    const fs::path mp4 = dir / "new.mp4";
    const auto no_folder =
        run_strata(video + mp4.string() + " --layout-dir " + (old_mp4 / "layouts").string());
    INFO(no_folder.output);
    CHECK(no_folder.exit_code == 1);
    CHECK(no_folder.output.find("--layout-dir: " + (old_mp4 / "layouts").string() +
                                ": cannot create the folder") != std::string::npos);
    CHECK(test::folder_bytes(dir) == before);
  }
#endif
}

namespace {

// Runs the viewer on `scene` with a script that saves two positions; the run's output.
std::string save_positions(const fs::path& scene, const fs::path& script_folder) {
  const fs::path script = test::write_file(script_folder / "save.txt",
                                           "save-position mine\nsave-position mine2\nquit\n");
  const auto r =
      run_strata("view " + scene.string() + " --size 64 --no-panel --script " + script.string());
  INFO(r.output);
  CHECK(r.exit_code == 0);
  return r.output;
}

// After saving: the files of `folder` are those before, but `saved` (new, or changed), which
// loads and holds both new positions.
void check_only_saved(const fs::path& folder, const std::map<std::string, std::string>& before,
                      const fs::path& saved) {
  auto after = test::folder_bytes(folder);
  const std::string name = fs::relative(saved, folder).string();
  REQUIRE(after.count(name) == 1);
  CHECK(after[name] != (before.count(name) ? before.at(name) : std::string()));
  after.erase(name);
  auto unchanged = before;
  unchanged.erase(name);
  CHECK(after == unchanged);
  const Scene scene = load_scene(saved);
  size_t found = 0;
  for (const CameraPose& pose : scene.camera_positions) found += pose.name.starts_with("mine");
  CHECK(found == 2);
}

}  // namespace

TEST_SUITE("window") {
  // A script's outputs over the scene's files, or over the script itself, are refused before the
  // window opens, naming the script's line; `save` to the label file the viewer opened is its
  // purpose and passes.
  TEST_CASE("viewer_script_outputs_over_inputs_are_refused_before_the_window_opens") {
    const fs::path dir = test::fresh_folder("output_writes", "viewer_inputs");
    const SceneFiles in = write_scene(dir);
    const fs::path script = dir / "s.txt";
    struct Case {
      std::string lines, refused;
    };
    const std::vector<Case> cases = {
        {"report " + in.scene.string() + "\n",
         ":1: report: " + in.scene.string() + " would replace the input " + in.scene.string()},
        {"screenshot " + script.string() + "\n",
         ":1: screenshot: " + script.string() + " would replace the input " + script.string()},
        {"layout " + in.transfer_function.string() + "\n", ":1: layout: "},
        {"capture " + in.picture.string() + "\n", ":1: capture: "},
        {"record start " + in.volume.string() + "\n", ":1: record start: "},
        {"save " + in.labels.string() + "\nsave " + in.scene.string() + "\n",
         ":2: save: " + in.scene.string() + " would replace the input"},
    };
    const auto before = test::folder_bytes(dir);
    for (const Case& c : cases) {
      test::write_file(script, c.lines + "quit\n");
      const auto r = run_strata("view " + in.scene.string() + " --labels " + in.labels.string() +
                                " --size 64 --no-panel --script " + script.string());
      CAPTURE(c.lines);
      CAPTURE(r.output);
      CHECK(r.exit_code == 2);
      CHECK(r.output.find("strata: error: " + script.string() + c.refused) != std::string::npos);
      CHECK(r.output.find("view: ") == std::string::npos);  // (no frame drawn)
      fs::remove(script);
      CHECK(test::folder_bytes(dir) == before);
    }
  }

  TEST_CASE("viewer_save_position_writes_only_its_scene_or_a_new_file_and_all_load") {
    const fs::path root = test::fresh_folder("output_writes", "viewer");
    const fs::path scripts = test::fresh_folder("output_writes", "viewer_scripts");
    const fs::path source = STRATA_SOURCE_DIR;
    // The demo scenes, copied with their paths as seen from assets/scenes/ (the data linked).
    fs::create_directories(root / "scenes");
    fs::create_directory_symlink(source / "assets/cache", root / "cache");
    fs::create_directory_symlink(source / "assets/transfer_functions", root / "transfer_functions");
    fs::create_directory_symlink(source / "assets/scenes/pictures", root / "scenes/pictures");
    std::vector<fs::path> scenes;
    for (const auto& entry : fs::directory_iterator(source / "assets/scenes")) {
      if (entry.path().extension() != ".json") continue;
      scenes.push_back(root / "scenes" / entry.path().filename());
      fs::copy_file(entry.path(), scenes.back());
    }
    REQUIRE(scenes.size() >= 4);
    // A small volume, alone and beside a transfer function and a scene file of its name.
    Volume volume;
    volume.dims = {12, 10, 8};
    volume.voxels.resize(volume.voxel_count());
    for (size_t i = 0; i < volume.voxels.size(); ++i) volume.voxels[i] = std::byte(i * 37 % 256);
    fs::create_directories(root / "alone");
    fs::create_directories(root / "crowded");
    write_metaimage(root / "alone/scan.mha", volume, false);
    write_metaimage(root / "crowded/scan.mha", volume, false);
    fs::copy_file(source / "assets/transfer_functions/head-t1.json", root / "crowded/scan.json");
    test::write_file(root / "crowded/scan.scene.json", "not a scene, and not to be replaced\n");

    for (const fs::path& scene : scenes) {
      INFO(scene.string());
      const auto before = test::folder_bytes(root);
      const std::string output = save_positions(scene, scripts);
      CHECK(output.find("saved position 'mine2' in " + scene.string()) != std::string::npos);
      check_only_saved(root, before, scene);
    }
    {
      const auto before = test::folder_bytes(root);
      const std::string output = save_positions(root / "alone/scan.mha", scripts);
      const fs::path saved = root / "alone/scan.scene.json";
      CHECK(output.find("in a new scene file " + saved.string()) != std::string::npos);
      CHECK(output.find("saved position 'mine2' in " + saved.string()) != std::string::npos);
      check_only_saved(root, before, saved);
    }
    {
      const auto before = test::folder_bytes(root);
      const std::string output = save_positions(root / "crowded/scan.mha", scripts);
      const fs::path saved = root / "crowded/scan.scene-2.json";
      CHECK(output.find("in a new scene file " + saved.string()) != std::string::npos);
      check_only_saved(root, before, saved);
    }
  }
}

}  // namespace strata
