// --segmentation on the command line and `strata info` of a segmentation, with the demo's
// TotalSegmentator-style label map (scripts/make-demo-segmentation.py) and AAL's atlas.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "gpu_fixture.h"
#include "test_files.h"

namespace strata {
namespace {

using test::run_strata;

#define CACHE STRATA_SOURCE_DIR "/assets/cache/"
#define HEAD CACHE "mricron/ch2.nii.gz"
#define REGIONS CACHE "demo/head-regions.nii.gz"

}  // namespace

TEST_SUITE("cli") {
  TEST_CASE("segmentation_info_lists_each_region_with_its_volume_and_anchor") {
    const auto r = run_strata("info " REGIONS);
    REQUIRE(r.exit_code == 0);
    CHECK(r.output.find("segmentation: label map, names from NIfTI label table") !=
          std::string::npos);
    CHECK(r.output.find("regions: 27") != std::string::npos);
    // value, name, colour as written, voxels, ml, anchor LPS and RAS (x and y negated).
    std::istringstream lines(r.output);
    bool found = false;
    for (std::string line; std::getline(lines, line);) {
      if (line.find(" thalamus_left ") == std::string::npos) continue;
      found = true;
      int value = 0;
      char name[64] = {};
      double red = 0, green = 0, blue = 0, ml = 0, l[3] = {}, a[3] = {};
      size_t voxels = 0;
      REQUIRE(std::sscanf(line.c_str(),
                          " %d %63s (%lf, %lf, %lf) %zu %lf (%lf, %lf, %lf) (%lf, %lf, %lf)",
                          &value, name, &red, &green, &blue, &voxels, &ml, &l[0], &l[1], &l[2],
                          &a[0], &a[1], &a[2]) == 13);
      CHECK(value == 23);
      CHECK(voxels > 5000);
      CHECK(ml == doctest::Approx(double(voxels) / 1000.0));  // 1 mm voxels
      CHECK(l[0] > 0.0);                                      // the patient's left: LPS x positive
      CHECK(a[0] == doctest::Approx(-l[0]));
      CHECK(a[1] == doctest::Approx(-l[1]));
      CHECK(a[2] == doctest::Approx(l[2]));
    }
    CHECK(found);
    // A label map without names of its own lists its regions with a names table.
    const auto aal =
        run_strata("info " CACHE "mricron/aal.nii.gz --names " CACHE "mricron/aal.nii.txt");
    CHECK(aal.exit_code == 0);
    CHECK(aal.output.find("regions: 116") != std::string::npos);
    CHECK(aal.output.find("Precentral_L") != std::string::npos);
  }

  TEST_CASE("render_segmentation_labels_every_region_in_one_command") {
    const std::string layout = test::output_dir() + "/segmentation-layout.json";
    const auto r = run_strata("--validate render " HEAD " --segmentation " REGIONS
                              " --size 96 -o /dev/null --layout " +
                              layout);
    CAPTURE(r.output);
    REQUIRE(r.exit_code == 0);
    CHECK(r.output.find("validation:") == std::string::npos);
    std::ifstream in(layout);
    const nlohmann::json json = nlohmann::json::parse(in);
    const nlohmann::json& labels = json.at("labels");
    CHECK(labels.size() == 27);
    bool thalamus = false;
    for (const auto& label : labels) thalamus |= label.at("text") == "thalamus left";
    CHECK(thalamus);
  }

  TEST_CASE("bench_segmentation_reports_the_anchors_time_of_every_region") {
    const auto r = run_strata("bench segmentation --size 40x30x20 --regions 9 --runs 2");
    REQUIRE(r.exit_code == 0);
    const nlohmann::json report = nlohmann::json::parse(r.output.substr(r.output.find('{')));
    CHECK(report.at("regions") == 9);
    CHECK(report.at("regions_with_voxels") == 9);
    CHECK(report.at("labelled_voxels").get<size_t>() > 0);
    CHECK(report.at("anchors_ms").at("median").get<double>() > 0.0);
    const auto bad = run_strata("bench segmentation --size 40x30");
    CHECK(bad.exit_code == 2);
  }

  TEST_CASE("segmentation_options_are_checked") {
    const auto names_alone = run_strata("render " HEAD " --names x.txt -o /dev/null");
    CHECK(names_alone.exit_code == 2);
    CHECK(names_alone.output.find("--names needs --segmentation") != std::string::npos);
    const auto no_names =
        run_strata("render " HEAD " --segmentation " CACHE "mricron/aal.nii.gz -o /dev/null");
    CHECK(no_names.exit_code == 1);
    CHECK(no_names.output.find("aal.nii.gz: the label map names no regions") != std::string::npos);
    const auto unknown =
        run_strata("render " HEAD " --segmentation " REGIONS " --regions heart -o /dev/null");
    CHECK(unknown.exit_code == 1);
    CHECK(unknown.output.find("no region 'heart' (it has 27: frontal_lobe_left") !=
          std::string::npos);
    const auto masks =
        run_strata("render " HEAD " --segmentation " REGIONS " --make masks -o /dev/null");
    CHECK(masks.exit_code == 1);
    CHECK(masks.output.find("27 masks and 1 volume(s) already: strata renders at most 8") !=
          std::string::npos);
    const auto make =
        run_strata("render " HEAD " --segmentation " REGIONS " --make meshes -o /dev/null");
    CHECK(make.exit_code == 2);
  }
}

}  // namespace strata
