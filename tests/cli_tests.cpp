// The strata program end to end: exit codes, messages and files.
#include <doctest/doctest.h>

#include <cstdio>
#include <filesystem>

#include "engine/core/png.h"
#include "gpu_fixture.h"

namespace strata {

using test::run_strata;

TEST_SUITE("cli") {
  TEST_CASE("devices_lists_lavapipe_as_usable") {
    const auto r = run_strata("devices");
    CHECK(r.exit_code == 0);
    CHECK(r.output.find("llvmpipe") != std::string::npos);
    CHECK(r.output.find("usable: has everything strata needs") != std::string::npos);
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
    CHECK(r.output.find("\"device\": \"llvmpipe") != std::string::npos);
    CHECK(r.output.find("\"name\": \"summed_area_table.scan\"") != std::string::npos);
    CHECK(r.output.find("\"name\": \"summed_area_table\", \"median_ms\"") != std::string::npos);
    CHECK(r.output.find("\"max_relative_error\": ") != std::string::npos);
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

  TEST_CASE("bad_sizes_and_unwritable_outputs_are_errors_naming_the_culprit") {
    const auto size = run_strata("render --size 0x10 -o /dev/null");
    CHECK(size.exit_code == 1);
    CHECK(size.output.find("--size: '0x10' is not a size") != std::string::npos);
    const auto file = run_strata("render --size 8 -o /nonexistent-dir/out.png");
    CHECK(file.exit_code == 1);
    CHECK(file.output.find("/nonexistent-dir/out.png: cannot write PNG") != std::string::npos);
    const auto usage = run_strata("frobnicate");
    CHECK(usage.exit_code != 0);
  }
}

}  // namespace strata
