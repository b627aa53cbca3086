// The strata program end to end: exit codes, messages and files.
#include <doctest/doctest.h>

#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "engine/core/png.h"
#include "gpu_fixture.h"
#include "test_files.h"

namespace strata {

using test::run_strata;

namespace {

// A bench report: the one JSON object in the output (stderr's lines may come before or after).
nlohmann::json bench_report(const std::string& output) {
  const size_t start = output.find("{\n"), end = output.rfind("\n}");
  REQUIRE(end != std::string::npos);
  REQUIRE(start < end);
  return nlohmann::json::parse(output.substr(start, end + 2 - start));
}

// The entry of a bench report's "passes" or "groups" list with this name (null if none).
nlohmann::json named(const nlohmann::json& list, const std::string& name) {
  for (const auto& entry : list) {
    if (entry["name"] == name) return entry;
  }
  return nlohmann::json();
}

// A folder of the test output, emptied.
std::string empty_folder(const std::string& name) {
  const std::string dir = test::output_dir() + "/" + name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// `strata video` of head.json, four 64-pixel frames, into `dir` (options before -o: `extra`).
std::string short_video(const std::string& dir, const std::string& extra = "") {
  return "video " STRATA_SOURCE_DIR
         "/assets/scenes/head.json --orbit 12 --seconds 0.1 --fps 30 --size 64 " +
         extra + "-o " + dir;
}

}  // namespace

TEST_SUITE("cli") {
  TEST_CASE("devices_lists_lavapipe_as_usable") {
    const auto r = run_strata("devices");
    CHECK(r.exit_code == 0);
    CHECK(r.output.find("llvmpipe") != std::string::npos);
    CHECK(r.output.find("usable: has everything strata needs") != std::string::npos);
    // (lavapipe has conditional rendering and no pipeline statistics)
    CHECK(r.output.find("optional: conditional rendering yes, pipeline statistics no") !=
          std::string::npos);
  }

  TEST_CASE("render_writes_the_demo_png_with_validation_on_and_silent") {
    const std::string path = test::output_dir() + "/cli-render.png";
    std::filesystem::remove(path);
    const auto r = run_strata("--validate render --size 64x48 -o " + path);
    CHECK(r.exit_code == 0);
    CHECK(r.output.find("validation:") == std::string::npos);
    const Rgba8Image image = read_png(path);
    CHECK(image.width == 64);
    CHECK(image.height == 48);
  }

  TEST_CASE("bench_sat_prints_json_with_device_passes_and_a_checked_result") {
    const auto r = run_strata("bench sat --size 96x40 --runs 3");
    CHECK(r.exit_code == 0);
    const nlohmann::json report = bench_report(r.output);
    CHECK(report["device"].get<std::string>().starts_with("llvmpipe"));
    CHECK(report["benchmark"] == "sat");
    CHECK(report["runs"] == 3);
    CHECK(named(report["passes"], "summed_area_table.scan")["median_ms"].is_number());
    CHECK(named(report["groups"], "summed_area_table")["min_ms"].is_number());
    CHECK(report["max_relative_error"].get<double>() < 1e-5);
  }

  // The placement benchmark, validated: the label loop as one pass, and its baseline returning to
  // the host at every barrier inside that pass.
  TEST_CASE("bench_placement_runs_validated_with_its_readback_baseline") {
    const auto r = run_strata("--validate bench placement --scene " STRATA_SOURCE_DIR
                              "/assets/scenes/head.json --size 96 --labels 6 --runs 1");
    CHECK(r.exit_code == 0);
    CHECK(r.output.find("validation:") == std::string::npos);
    const nlohmann::json report = bench_report(r.output);
    CHECK(report["benchmark"] == "placement");
    CHECK(report["labels"] == 6);
    CHECK(named(report["passes"], "placement.labels")["median_ms"].get<double>() > 0.0);
    CHECK(report["label_loop_ms"].get<double>() > 0.0);
    CHECK(report["forces_ms"].get<double>() > 0.0);
    CHECK(report["label_loop_with_readback_per_label_ms"].get<double>() > 0.0);
  }

  // Label counts swept in one run (issue 18): one report, an entry per count with the whole
  // placement, the loop and every pass's and group's median; the slow readback baseline skipped
  // (null). 12 is more than head.json's 11 labels: they are repeated.
  TEST_CASE("bench_placement_sweeps_label_counts_into_one_report") {
    const auto r = run_strata("bench placement --scene " STRATA_SOURCE_DIR
                              "/assets/scenes/head.json --size 64 --labels 5,12 --runs 1 "
                              "--no-baseline");
    REQUIRE(r.exit_code == 0);
    const nlohmann::json report = bench_report(r.output);
    CHECK(report["benchmark"] == "placement");
    CHECK(report["readback_baseline"] == false);
    const nlohmann::json& sweep = report["sweep"];
    REQUIRE(sweep.size() == 2);
    for (size_t i = 0; i < sweep.size(); ++i) {
      CAPTURE(i);
      const nlohmann::json& entry = sweep[i];
      CHECK(entry["labels"] == (i == 0 ? 5 : 12));
      CHECK(entry["placement_ms"].get<double>() > 0.0);
      CHECK(entry["label_loop_ms"].get<double>() > 0.0);
      CHECK(entry["label_loop_us_per_label"].get<double>() > 0.0);
      CHECK(entry["tidy_ms"].get<double>() > 0.0);
      CHECK(entry["passes"]["placement.labels"].get<double>() > 0.0);
      CHECK(entry["groups"]["placement"].get<double>() > 0.0);
      CHECK(entry["label_loop_with_readback_per_label_ms"].is_null());
      CHECK(entry["speedup"].is_null());
    }
    // The table for people on stderr: a header and a row per count.
    CHECK(r.output.find("labels  shown") != std::string::npos);
  }

  // The viewer's whole frame with the labels asked for, and each group's total in it.
  TEST_CASE("bench_view_measures_the_frame_with_the_labels_asked_for") {
    const auto r = run_strata("bench view " STRATA_SOURCE_DIR
                              "/assets/scenes/head.json --size 64 --frames 3 --labels 12");
    REQUIRE(r.exit_code == 0);
    const nlohmann::json report = bench_report(r.output);
    CHECK(report["labels"] == 12);
    for (const char* run :
         {"gpu_frame_ms", "gpu_frame_ms_stamped_per_group", "gpu_frame_ms_stamped_per_pass"}) {
      CAPTURE(run);
      CHECK(report[run]["median"].get<double>() > 0.0);
      CHECK(report[run]["p95"].get<double>() >= report[run]["median"].get<double>());
    }
    for (const char* group : {"render", "placement", "labels", "ui"}) {
      CAPTURE(group);
      CHECK(report["mean_group_total_ms"][group].get<double>() > 0.0);
      CHECK(report["mean_group_total_ms_stamped_per_pass"][group].get<double>() > 0.0);
    }
    CHECK(report["mean_pass_ms"]["placement.labels"].get<double>() > 0.0);
    CHECK(r.output.find("bench view: 12 labels") != std::string::npos);
  }

  // strata pick: the point under a pixel of head.json's front view in LPS and RAS (x and y
  // negated), the atlas region it lies in, nothing on the background; a pixel outside the image
  // is a usage error.
  TEST_CASE("pick_prints_the_point_in_both_systems_and_its_atlas_region") {
    const auto r = run_strata("pick " STRATA_SOURCE_DIR
                              "/assets/scenes/head.json --camera front --size 96 --at 48,40 "
                              "--at 2,2");
    REQUIRE(r.exit_code == 0);
    double l[3] = {}, a[3] = {};
    char region[64] = {};
    const size_t at = r.output.find("48,40: LPS ");
    REQUIRE(at != std::string::npos);
    REQUIRE(std::sscanf(r.output.c_str() + at,
                        "48,40: LPS %lf %lf %lf mm, RAS %lf %lf %lf mm, region %63[^\n]", &l[0],
                        &l[1], &l[2], &a[0], &a[1], &a[2], region) == 7);
    CHECK(a[0] == doctest::Approx(-l[0]));
    CHECK(a[1] == doctest::Approx(-l[1]));
    CHECK(a[2] == doctest::Approx(l[2]));
    CHECK(l[1] < 0.0);  // (seen from the front: anterior, LPS y negative)
    CHECK(std::string(region) == "Frontal Sup Medial L");
    CHECK(r.output.find("2,2: nothing") != std::string::npos);
    const auto outside =
        run_strata("pick " STRATA_SOURCE_DIR "/assets/scenes/head.json --size 96 --at 96,3");
    CHECK(outside.exit_code == 2);
    CHECK(outside.output.find("--at: 96,3 lies outside the 96x96 image") != std::string::npos);
  }

  TEST_CASE("dump_graph_prints_the_frame_passes_and_barriers") {
    const auto r = run_strata("render " STRATA_SOURCE_DIR
                              "/assets/scenes/head.json --size 48 --dump-graph -o /dev/null");
    CHECK(r.exit_code == 0);
    CHECK(r.output.find("pass 13 'placement.labels' (compute, placement)") != std::string::npos);
    CHECK(r.output.find("26 passes, 70 barriers") != std::string::npos);
  }

  // The thesis program's screenshots: one still per named position, named after it.
  TEST_CASE("render_with_several_positions_writes_one_png_per_position") {
    const std::string dir = empty_folder("stills");
    const auto r = run_strata("render " STRATA_SOURCE_DIR
                              "/assets/scenes/head.json --size 64 "
                              "--camera front,left -o " +
                              dir + "/head.png --layout " + dir + "/layout.json");
    CHECK(r.exit_code == 0);
    for (const char* name : {"front", "left"}) {
      CAPTURE(name);
      const Rgba8Image image = read_png(dir + "/head-" + name + ".png");
      CHECK(image.width == 64);
      CHECK(image.height == 64);
      CHECK(std::filesystem::exists(dir + "/layout-" + name + ".json"));
    }
    CHECK(!std::filesystem::exists(dir + "/head.png"));
    CHECK(read_png(dir + "/head-front.png").pixels != read_png(dir + "/head-left.png").pixels);
  }

  TEST_CASE("an_unknown_position_in_the_list_is_one_error_naming_it") {
    const std::string dir = empty_folder("stills-unknown");
    const auto r = run_strata("render " STRATA_SOURCE_DIR
                              "/assets/scenes/head.json --size 32 "
                              "--camera front,nowhere -o " +
                              dir + "/head.png");
    CHECK(r.exit_code == 2);  // (a bad option value)
    CHECK(r.output.find("strata: error: ") != std::string::npos);
    CHECK(r.output.find("no camera position named 'nowhere'") != std::string::npos);
    CHECK(std::filesystem::is_empty(dir));  // names are checked before anything renders
  }

  // A turntable video: the frame count and size ffprobe reads, a layout per frame, and strata
  // eval over the sequence.
#if STRATA_VIDEO
  TEST_CASE("video_of_a_turntable_has_its_frames_and_layouts") {
    const std::string dir = test::output_dir() + "/turntable";
    std::filesystem::remove_all(dir);
    const auto r = run_strata("--validate video " STRATA_SOURCE_DIR
                              "/assets/scenes/head.json --orbit 12 --seconds 0.2 --fps 30 "
                              "--size 64 -o " +
                              dir + ".mp4 --layout-dir " + dir);
    CHECK(r.exit_code == 0);
    CHECK(r.output.find("validation:") == std::string::npos);
    CHECK(r.output.find("wrote 7 frames (64x64, 30 fps)") != std::string::npos);
    CHECK(test::probe_video(dir + ".mp4", "width,height,nb_read_frames") == "64,64,7");
    const auto eval = run_strata("eval " + dir + "/frame-0000*.json");
    CHECK(eval.exit_code == 0);
    const nlohmann::json report = bench_report(eval.output);
    CHECK(report["frames"] == 7);
    CHECK(report["sequence"]["jumps"] == 0);
  }

#endif

  // Layouts with opacity, target and seconds, stills of the same cameras, and the report at the
  // end, which is what `strata eval --stills` says of the files written.
  TEST_CASE("video_report_measures_the_frames_as_eval_does_with_stills") {
    const std::string dir = empty_folder("video-report");
    const auto r = run_strata("video " STRATA_SOURCE_DIR
                              "/assets/scenes/head.json --orbit 20 --seconds 0.25 --fps 12 "
                              "--size 128 -o " +
                              dir + "/frames --layout-dir " + dir + "/layouts --still-layouts " +
                              dir + "/stills --report");
    REQUIRE(r.exit_code == 0);
    const nlohmann::json report = bench_report(r.output);
    const size_t frames = report["frames"].get<size_t>();
    CHECK(frames >= 3);
    CHECK_FALSE(report.contains("per_frame"));
    const nlohmann::json& total = report["total"];
    CHECK(total["labels"] == 11 * frames);
    CHECK(total["opaque"].get<size_t>() > 0);
    CHECK(total["opaque"].get<size_t>() <=
          total["shown"].get<size_t>() + total["illegible"].get<size_t>());
    CHECK(total["still_opaque"].get<size_t>() > 0);
    CHECK(total["opaque_of_still"].get<double>() > 0.0);
    const nlohmann::json& sequence = report["sequence"];
    CHECK(sequence["seconds"].get<double>() == doctest::Approx(double(frames - 1) / 12.0));
    CHECK(sequence["motion_mean_of_width_per_second"].get<double>() >= 0.0);
    CHECK(sequence["motion_p95_of_width_per_second"].get<double>() >=
          sequence["motion_mean_of_width_per_second"].get<double>());
    CHECK(sequence["opaque_flips_per_label_per_second"].get<double>() >= 0.0);
    CHECK(sequence["label_frame_pairs"] == 11 * (frames - 1));

    const auto layout = [&](const std::string& folder, int frame) {
      char name[32];
      std::snprintf(name, sizeof name, "/frame-%05d.json", frame);
      return nlohmann::json::parse(test::read_file(dir + "/" + folder + name));
    };
    CHECK(layout("layouts", 0)["seconds"].is_null());  // the first frame is a still
    const nlohmann::json second = layout("layouts", 1);
    CHECK(second["seconds"].get<double>() == doctest::Approx(1.0 / 12.0));
    for (const auto& label : second["labels"]) {
      CHECK(label["opacity"].get<double>() >= 0.0);
      CHECK(label["opacity"].get<double>() <= 1.0);
      CHECK((label["target"].is_null() || label["target"].size() == 4));
    }
    CHECK(layout("stills", 1)["seconds"].is_null());

    const auto eval =
        run_strata("eval " + dir + "/layouts/frame-*.json --stills " + dir + "/stills");
    REQUIRE(eval.exit_code == 0);
    const nlohmann::json evaluated = bench_report(eval.output);
    CHECK(evaluated["total"] == total);
    CHECK(evaluated["sequence"] == sequence);
    CHECK(evaluated["per_frame"].size() == frames);
  }

  // A planned video (the default): the path rehearsed first, then every label drawn in at most
  // one range per stretch of its anchor in view, none shorter than 1 s away from the ends, with
  // no overlap or cut in any frame; the bound of the stills is at least what the frames read.
  TEST_CASE("a_planned_video_shows_each_label_in_one_range_per_stretch_none_short_inside") {
    const std::string dir = empty_folder("video-plan");
    const auto r = run_strata("--validate video " STRATA_SOURCE_DIR
                              "/assets/scenes/head.json --orbit 90 --seconds 3 --fps 8 --size 160 "
                              "-o " +
                              dir + "/frames --layout-dir " + dir + "/layouts --still-layouts " +
                              dir + "/stills --report");
    REQUIRE(r.exit_code == 0);
    CHECK(r.output.find("validation:") == std::string::npos);
    CHECK(r.output.find("planned ") != std::string::npos);
    const nlohmann::json report = bench_report(r.output);
    const nlohmann::json& sequence = report["sequence"];
    CHECK(report["frames"] == 25);
    CHECK(sequence["active_ranges"].get<size_t>() > 0);
    CHECK(sequence["extra_ranges"] == 0);
    CHECK(sequence["short_ranges_inside"] == 0);
    CHECK(report["total"]["overlaps"] == 0);
    CHECK(report["total"]["cut"] == 0);
    CHECK(sequence["readable_of_bound"].get<double>() > 0.0);
    CHECK(sequence["readable_of_bound"].get<double>() <= 1.0);
  }

  // Frames compressed on worker threads are the files of frames written one after another, and
  // the last line says how fast the frames came.
  TEST_CASE("video_frames_written_on_threads_are_the_bytes_of_frames_written_one_by_one") {
    const std::string dir = empty_folder("video-threads");
    const std::string video = short_video(dir);
    const auto serial = run_strata(video + "/serial --threads 1");
    REQUIRE(serial.exit_code == 0);
    const auto threaded = run_strata(video + "/threaded --threads 3");
    REQUIRE(threaded.exit_code == 0);
    CHECK(threaded.output.find("wrote 4 frames (64x64, 30 fps) to " + dir + "/threaded in ") !=
          std::string::npos);
    CHECK(threaded.output.find(" frames/s\n") != std::string::npos);
    const auto frames = test::folder_bytes(dir + "/serial");
    CHECK(frames.size() == 4);
    CHECK(test::folder_bytes(dir + "/threaded") == frames);
  }

  // A write that fails on a worker thread (files limited to one block, as on a full disk) ends
  // the run with the first frame's error and exit 1, and leaves no frame, no MP4 and no GIF.
  TEST_CASE("video_whose_frames_fail_on_worker_threads_exits_1_with_the_first_frames_error") {
    const std::string dir = empty_folder("video-threads-full");
    const std::string video = short_video(dir, "--threads 3 ");
    const std::string small_files = "trap '' XFSZ; ulimit -f 1;";
    const auto png = run_strata(video + "/frames", small_files);
    CHECK(png.exit_code == 1);
    CHECK(png.output.find("strata: error: " + dir +
                          "/frames/frame-00000.png: cannot write PNG: File too large") !=
          std::string::npos);
    CHECK(std::filesystem::is_empty(dir + "/frames"));
#if STRATA_VIDEO
    const auto mp4 = run_strata(video + "/video.mp4", small_files);
    CHECK(mp4.exit_code == 1);
    CHECK(mp4.output.find("File too large") != std::string::npos);
    CHECK(!std::filesystem::exists(dir + "/video.mp4"));
    const auto gif = run_strata(video + "/video.gif", small_files);
    CHECK(gif.exit_code == 1);
    CHECK(gif.output.find("File too large") != std::string::npos);
    CHECK(!std::filesystem::exists(dir + "/video.gif"));
#endif
  }

  // The video's writers alone: frames a second of each, and the files they wrote kept.
  TEST_CASE("bench_encode_reports_the_frames_a_second_of_the_png_mp4_and_gif_writers") {
    const std::string dir = empty_folder("bench-encode");
    const auto r = run_strata("bench encode --size 64x48 --frames 5 --threads 2 --output " + dir);
    REQUIRE(r.exit_code == 0);
    const nlohmann::json report = bench_report(r.output);
    CHECK(report["benchmark"] == "encode");
    CHECK(report["threads"] == 2);
    CHECK(report["png"]["frames_per_second"].get<double>() > 0.0);
    CHECK(read_png(dir + "/frames/frame-00004.png").width == 64);
#if STRATA_VIDEO
    CHECK(report["mp4"]["frames_per_second"].get<double>() > 0.0);
    CHECK(test::probe_video(dir + "/video.mp4", "width,height,nb_read_frames") == "64,48,5");
    CHECK(report["gif"]["frames_per_second"].get<double>() > 0.0);
    CHECK(test::probe_video(dir + "/video.gif", "codec_name,nb_read_frames") == "gif,5");
#else
    CHECK(report["mp4"].is_null());
    CHECK(report["gif"].is_null());
#endif
  }

  // --background: a value it does not know, and transparency where the output keeps no alpha, are
  // usage errors before anything renders; a colour fills what the scene leaves empty.
  TEST_CASE("background_is_a_colour_or_transparent_where_the_output_keeps_alpha") {
    const std::string head = STRATA_SOURCE_DIR "/assets/scenes/head.json";
    const std::string dir = empty_folder("background");
    const auto pink = run_strata("render " + head + " --background pink -o " + dir + "/x.png");
    CHECK(pink.exit_code == 2);
    CHECK(pink.output.find("--background: 'pink' is not a background (black, white, transparent "
                           "or #rrggbb)") != std::string::npos);
    const auto jpeg =
        run_strata("render " + head + " --background transparent -o " + dir + "/x.jpg");
    CHECK(jpeg.exit_code == 2);
    CHECK(jpeg.output.find("JPEG has no alpha") != std::string::npos);
    for (const char* video : {"x.mp4", "x.gif"}) {
      CAPTURE(video);
      const auto r = run_strata("video " + head + " --orbit 10 --background transparent -o " + dir +
                                "/" + video);
      CHECK(r.exit_code == 2);
      CHECK(r.output.find("keeps no alpha; write PNG frames to a folder") != std::string::npos);
    }
    CHECK(std::filesystem::is_empty(dir));
    const auto red = run_strata(
        "render " + head + " --no-labels --background '#ff0000' --size 32 -o " + dir + "/red.png");
    REQUIRE(red.exit_code == 0);
    const Rgba8Image image = read_png(dir + "/red.png");
    CHECK(std::vector<uint8_t>(image.pixels.begin(), image.pixels.begin() + 4) ==
          std::vector<uint8_t>{255, 0, 0, 255});
  }

#if STRATA_VIDEO
  // A turntable as a GIF that FFmpeg reads with every frame; and a full turn either way loops
  // without a seam: the last frame is not the first again, and the step from it to the first is
  // like the steps between the others (a bare volume: only the camera moves).
  TEST_CASE("a_full_turn_loops_as_a_gif_without_repeating_its_first_frame") {
    const std::string dir = empty_folder("turn-loop");
    const auto gif = run_strata("video " STRATA_SOURCE_DIR
                                "/assets/scenes/head.json --orbit 360 --seconds 1 --fps 6 "
                                "--size 64 --background white -o " +
                                dir + "/turn.gif");
    REQUIRE(gif.exit_code == 0);
    CHECK(gif.output.find("wrote 6 frames (64x64, 6 fps)") != std::string::npos);
    CHECK(test::probe_video(dir + "/turn.gif", "codec_name,width,height,nb_read_frames") ==
          "gif,64,64,6");
    const auto png = run_strata("video " STRATA_SOURCE_DIR
                                "/assets/cache/mricron/ch2.nii.gz --orbit -360 --seconds 1 "
                                "--fps 8 --size 64 -o " +
                                dir + "/frames");
    REQUIRE(png.exit_code == 0);
    std::vector<Rgba8Image> frames;
    for (const auto& [name, bytes] : test::folder_bytes(dir + "/frames"))
      frames.push_back(read_png(dir + "/frames/" + name));
    REQUIRE(frames.size() == 8);
    const auto step = [](const Rgba8Image& a, const Rgba8Image& b) {
      double sum = 0.0;
      for (size_t i = 0; i < a.pixels.size(); ++i)
        sum += std::abs(int(a.pixels[i]) - int(b.pixels[i]));
      return sum / double(a.pixels.size());
    };
    const double seam = step(frames.back(), frames.front());
    for (size_t i = 0; i + 1 < frames.size(); ++i) {
      const double other = step(frames[i], frames[i + 1]);
      CAPTURE(i);
      CAPTURE(other);
      CHECK(seam > 0.5 * other);
      CHECK(seam < 2.0 * other);
    }
  }
#endif

  TEST_CASE("video_with_two_paths_or_none_is_one_clear_error") {
    const auto both = run_strata("video " STRATA_SOURCE_DIR
                                 "/assets/scenes/head.json --orbit 10 --path front -o x.mp4");
    CHECK(both.exit_code == 2);
    CHECK(both.output.find("give --path or --orbit, not both") != std::string::npos);
    const auto none = run_strata("video " STRATA_SOURCE_DIR "/assets/scenes/head.json -o x.mp4");
    CHECK(none.exit_code == 2);
    CHECK(none.output.find("give a camera path") != std::string::npos);
  }

  TEST_CASE("no_vulkan_driver_is_one_clear_error_and_exit_1") {
    const auto r =
        run_strata("render -o /dev/null",
                   "VK_DRIVER_FILES=/nonexistent/icd.json VK_ICD_FILENAMES=/nonexistent/icd.json");
    CHECK(r.exit_code == 1);
    CHECK(r.output.find("strata: error: no Vulkan") != std::string::npos);
    CHECK(r.output.find("Segmentation") == std::string::npos);
  }

  TEST_CASE("an_unknown_device_is_named_in_the_error") {
    const auto r = run_strata("--device quantum-gpu render -o /dev/null");
    CHECK(r.exit_code == 1);
    CHECK(r.output.find("no Vulkan device matches 'quantum-gpu'") != std::string::npos);
    const auto env = run_strata("render -o /dev/null", "STRATA_DEVICE=9");
    CHECK(env.exit_code == 1);
    CHECK(env.output.find("no Vulkan device matches '9'") != std::string::npos);
  }

  TEST_CASE("info_describes_the_head_demo_scene") {
    const auto r = run_strata(std::string("info ") + STRATA_SOURCE_DIR "/assets/scenes/head.json");
    CHECK(r.exit_code == 0);
    CHECK(r.output.find("181x217x181") != std::string::npos);
    CHECK(r.output.find("uint8") != std::string::npos);
    CHECK(r.output.find("Precentral L") != std::string::npos);
    CHECK(r.output.find("Cerebelum 6 R") != std::string::npos);
    CHECK(r.output.find("front") != std::string::npos);
    CHECK(r.output.find("oblique") != std::string::npos);
  }

  // Label files: the count, the system they were written in, their bounds in both systems and,
  // with --scene, the anchors outside every volume of the scene.
  TEST_CASE("info_describes_label_files_and_checks_them_against_a_scene") {
    for (const char* name : {"landmarks_ras.mrk.json", "landmarks_lps.fcsv",
                             "landmarks_slicer4_ras.fcsv", "landmarks_ras.csv"}) {
      CAPTURE(name);
      const auto r =
          run_strata(std::string("info ") + STRATA_SOURCE_DIR "/tests/data/labels/" + name);
      CHECK(r.exit_code == 0);
      const bool ras = std::string(name).find("ras") != std::string::npos;
      CHECK(r.output.find(std::string("labels: 3, written in ") + (ras ? "RAS" : "LPS")) !=
            std::string::npos);
      CHECK(r.output.find("bounds: LPS (-20.5, -40, -12.5) .. (15.125, 25.75, 30) mm, RAS "
                          "(-15.125, -25.75, -12.5) .. (20.5, 40, 30) mm") != std::string::npos);
      CHECK(r.output.find("not checked (--scene SCENE)") != std::string::npos);
    }
    const auto folder = test::fresh_folder("cli", "info_labels");
    const std::string csv = test::write_file(
        folder / "marks.csv", "text,r,a,s\ninside,0,10,20\nbeyond the head,0,400,0\n");
    const auto r =
        run_strata("info " + csv + " --scene " STRATA_SOURCE_DIR "/assets/scenes/head.json");
    CHECK(r.exit_code == 0);
    CHECK(r.output.find("inside the volumes of ") != std::string::npos);
    CHECK(r.output.find(": 1 of 2") != std::string::npos);
    CHECK(r.output.find("outside:    1  \"beyond the head\" at LPS (0, -400, 0)") !=
          std::string::npos);
    const auto usage = run_strata(std::string("info ") +
                                  STRATA_SOURCE_DIR "/assets/scenes/head.json --scene " + csv);
    CHECK(usage.exit_code == 2);
  }

  TEST_CASE("info_says_when_a_label_file_passes_the_label_limit_with_the_scene") {
    const auto folder = test::fresh_folder("cli", "info_label_limit");
    std::string csv = "text,l,p,s\n";
    for (int i = 0; i < 4090; ++i) csv += "L," + std::to_string(i % 50) + ",0,0\n";
    const std::string file = test::write_file(folder / "many.csv", csv);
    const auto alone = run_strata("info " + file);
    CHECK(alone.exit_code == 0);
    CHECK(alone.output.find("too many") == std::string::npos);
    const auto r =
        run_strata("info " + file + " --scene " STRATA_SOURCE_DIR "/assets/scenes/head.json");
    CHECK(r.exit_code == 0);
    CHECK(r.output.find("  too many for a scene: 4090 labels, 4") != std::string::npos);
    CHECK(r.output.find("; strata places at most 4096 in a scene\n") != std::string::npos);
  }

  TEST_CASE("info_imports_a_thesis_scene_and_warns_about_its_missing_volume") {
    const auto r = run_strata(std::string("info ") + STRATA_SOURCE_DIR
                              "/tests/data/voly-labeller/scenes/dice.xml");
    CHECK(r.exit_code == 0);
    CHECK(r.output.find("N11") != std::string::npos);
    CHECK(r.output.find("dice.mha") != std::string::npos);
  }

  TEST_CASE("info_of_a_broken_file_is_one_error_naming_it") {
    const std::string path = test::output_dir() + "/broken.json";
    {
      std::FILE* f = std::fopen(path.c_str(), "w");
      REQUIRE(f != nullptr);
      std::fputs("{\"strata_scene\": 1, \"labels\": [", f);
      std::fclose(f);
    }
    const auto r = run_strata("info " + path);
    CHECK(r.exit_code == 1);
    CHECK(r.output.find("strata: error: " + path) != std::string::npos);
  }

  // Two frames: boxes overlapping by 10 x 10 px, then label 1 jumps 50 px and label 2 hides.
  TEST_CASE("eval_prints_frame_and_sequence_metrics_of_layout_files") {
    const auto folder = test::fresh_folder("cli", "eval");
    const std::string a = test::write_file(folder / "a.json", R"({"width": 100, "height": 100,
      "labels": [{"id": 1, "anchor": [10, 10], "box": [20, 20, 20, 10], "shown": true},
                 {"id": 2, "anchor": [50, 50], "box": [30, 20, 20, 10], "shown": true}]})");
    const std::string b = test::write_file(folder / "b.json", R"({"width": 100, "height": 100,
      "labels": [{"id": 1, "anchor": [10, 10], "box": [50, 60, 20, 10], "shown": true},
                 {"id": 2, "anchor": [50, 50], "box": [30, 20, 20, 10], "shown": false}]})");
    const auto one = run_strata("eval " + a);
    CHECK(one.exit_code == 0);
    const nlohmann::json single = nlohmann::json::parse(one.output);
    CHECK(single["frames"] == 1);
    CHECK(single["frame"]["shown"] == 2);
    CHECK(single["frame"]["overlaps"] == 1);
    const auto two = run_strata("eval " + a + " " + b);
    CHECK(two.exit_code == 0);
    const nlohmann::json report = nlohmann::json::parse(two.output);
    CHECK(report["frames"] == 2);
    CHECK(report["per_frame"][0]["overlap_area_px2"] == 100.0);
    CHECK(report["per_frame"][1]["hidden"] == 1);
    CHECK(report["total"]["overlaps"] == 1);
    CHECK(report["sequence"]["movement_mean_px"] == 50.0);
    CHECK(report["sequence"]["jumps"] == 1);
    CHECK(report["sequence"]["show_hide_flips"] == 1);
  }

  TEST_CASE("eval_of_a_missing_or_malformed_file_is_one_error_naming_it_and_exit_1") {
    const auto folder = test::fresh_folder("cli", "eval_errors");
    const std::string bad = test::write_file(folder / "bad.json", R"({"width": 8, "height": 8,
      "labels": [{"id": 1, "anchor": [1, 1], "box": [0, 0, 4], "shown": true}]})");
    const auto malformed = run_strata("eval " + bad + " " + folder.string() + "/missing.json");
    CHECK(malformed.exit_code == 1);
    CHECK(malformed.output.find("strata: error: " + bad + ": labels[0].box: expected 4 numbers") !=
          std::string::npos);
    const auto absent = run_strata("eval " + folder.string() + "/missing.json");
    CHECK(absent.exit_code == 1);
    CHECK(absent.output == "strata: error: " + folder.string() + "/missing.json: no such file\n");
  }

  // The layout render writes reads back: eval counts the labels the file holds.
  TEST_CASE("eval_reads_the_layout_that_render_writes") {
    const std::string layout = (test::fresh_folder("cli", "eval_render") / "head.json").string();
    const auto render = run_strata("render " STRATA_SOURCE_DIR
                                   "/assets/scenes/head.json --size 128 -o /dev/null --layout " +
                                   layout);
    REQUIRE(render.exit_code == 0);
    const nlohmann::json written = nlohmann::json::parse(test::read_file(layout));
    size_t shown = 0;
    for (const auto& label : written["labels"]) shown += label["shown"].get<bool>() ? 1 : 0;
    const auto r = run_strata("eval " + layout);
    CHECK(r.exit_code == 0);
    const nlohmann::json frame = nlohmann::json::parse(r.output)["frame"];
    CHECK(frame["labels"] == written["labels"].size());
    CHECK(frame["shown"] == shown);
    CHECK(shown > 0);
  }

  // --label-scale scales every label box; a scale out of range is refused before any work.
  TEST_CASE("label_scale_scales_the_boxes_the_layout_reports") {
    const std::filesystem::path folder = test::fresh_folder("cli", "label_scale");
    std::vector<nlohmann::json> layouts;
    for (const char* scale : {"1", "2"}) {
      const std::string layout = (folder / (std::string(scale) + ".json")).string();
      const auto r = run_strata("render " STRATA_SOURCE_DIR
                                "/assets/scenes/head.json --size 128 -o /dev/null --label-scale " +
                                std::string(scale) + " --layout " + layout);
      REQUIRE(r.exit_code == 0);
      layouts.push_back(nlohmann::json::parse(test::read_file(layout)));
    }
    const auto& small = layouts[0]["labels"][0]["box"];
    const auto& large = layouts[1]["labels"][0]["box"];
    CHECK(large[2].get<double>() == doctest::Approx(2.0 * small[2].get<double>()).epsilon(0.1));
    CHECK(large[3].get<double>() == doctest::Approx(2.0 * small[3].get<double>()).epsilon(0.1));
    const auto bad = run_strata("render --size 8 -o /dev/null --label-scale 9");
    CHECK(bad.exit_code != 0);
    CHECK(bad.output.find("--label-scale") != std::string::npos);
  }

  // The demo scene with pictures (a JPEG above a label's text, a PNG left of another's): its
  // layout notes each picture and gives those labels the taller or wider boxes.
  TEST_CASE("render_of_a_scene_with_label_pictures_lays_them_out") {
    const std::filesystem::path folder = test::fresh_folder("cli", "label_pictures");
    const std::string layout = (folder / "layout.json").string();
    const auto r =
        run_strata("render " STRATA_SOURCE_DIR "/assets/scenes/head-images.json --size 128 -o " +
                   (folder / "head.png").string() + " --layout " + layout);
    REQUIRE(r.exit_code == 0);
    const nlohmann::json labels = nlohmann::json::parse(test::read_file(layout))["labels"];
    int pictures = 0;
    for (const auto& label : labels) {
      if (!label.contains("image")) {
        CHECK(label["box"][3] == 20);  // one line of text
        continue;
      }
      ++pictures;
      const std::string image = label["image"];
      CHECK(std::filesystem::exists(image));
      CHECK(label["box"][3].get<double>() >= 48.0 + 6.0);  // the picture and its padding
    }
    CHECK(pictures == 2);
  }

  TEST_CASE("a_label_picture_that_cannot_be_read_is_one_error_naming_the_label") {
    const std::filesystem::path folder = test::fresh_folder("cli", "bad_label_picture");
    const std::filesystem::path scene =
        test::write_file(folder / "scene.json", R"({"strata_scene": 1, "labels": [
          {"id": 1, "text": "a", "anchor": [0, 0, 0], "image": "notes.png"}]})");
    test::write_file(folder / "notes.png", "not a picture");
    const auto r = run_strata("render " + scene.string() + " --size 64 -o /dev/null");
    CHECK(r.exit_code == 1);
    CHECK(r.output.find("strata: error: " + scene.string() +
                        ": labels[0].image: " + (folder / "notes.png").string() +
                        ": not a PNG or JPEG file") != std::string::npos);
  }

  TEST_CASE("bad_sizes_and_unwritable_outputs_are_errors_naming_the_culprit") {
    const auto size = run_strata("render --size 0x10 -o /dev/null");
    CHECK(size.exit_code == 2);
    CHECK(size.output.find("--size: '0x10' is not a size") != std::string::npos);
    const auto file = run_strata("render --size 8 -o /nonexistent-dir/out.png");
    CHECK(file.exit_code == 1);
    CHECK(file.output.find("-o: /nonexistent-dir/out.png: the folder /nonexistent-dir does not "
                           "exist") != std::string::npos);
    const auto usage = run_strata("frobnicate");
    CHECK(usage.exit_code == 2);
  }
}

}  // namespace strata
