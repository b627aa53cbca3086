// Writes that cannot lose data, end to end: a write that fails (a file-size limit standing in for
// a full disk, a folder that cannot be made) leaves the old file or nothing; an output extension
// strata cannot write is a usage error before any work; the viewer's "save position" writes only
// the scene it opened, or a new file, and every scene it writes loads.
#include <doctest/doctest.h>

#include <filesystem>
#include <map>
#include <string>

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

}  // namespace

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
    CHECK(render.output.find(".png, .jpg or .jpeg") != std::string::npos);
    const auto video =
        run_strata("video " STRATA_SOURCE_DIR "/assets/scenes/head.json --orbit 10 --size 32 -o " +
                   (dir / "x.avi").string());
    CHECK(video.exit_code == 2);
    CHECK(video.output.find("-o: '" + (dir / "x.avi").string() + "'") != std::string::npos);
    CHECK(video.output.find("NAME.mp4, or a folder") != std::string::npos);
    CHECK(fs::is_empty(dir));
  }

#if STRATA_VIDEO
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
