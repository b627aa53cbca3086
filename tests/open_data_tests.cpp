// A user's own data in one command (strata render VOLUME): volumes and DICOM folders opened as
// scenes, the fitted camera, transfer-function presets, labels from a file; and the options that
// must do what they say (scene settings, limits, output formats, --dump-layers, progress).
#include <doctest/doctest.h>

#include <cstring>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "engine/core/image.h"
#include "engine/scene/io/volume_loader.h"
#include "gpu_fixture.h"
#include "test_files.h"

namespace strata {

using test::run_strata;

namespace {

const std::string kCache = STRATA_SOURCE_DIR "/assets/cache";

std::string out_path(const std::string& name) {
  return test::output_dir() + "/open-" + name;
}

// The share of pixels that are not the background (the corner pixel's colour).
double content_share(const Rgba8Image& image) {
  size_t content = 0;
  const uint8_t* corner = image.pixels.data();
  for (size_t p = 0; p < size_t{image.width} * image.height; ++p) {
    const uint8_t* px = image.pixels.data() + p * 4;
    int difference = 0;
    for (int c = 0; c < 3; ++c) difference += std::abs(int(px[c]) - int(corner[c]));
    content += difference > 24;
  }
  return double(content) / double(size_t{image.width} * image.height);
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Four points on the head (RAS millimetres of the MNI template ch2 is in; +r is the patient's
// right): the patient's left and right, the top of the brain and below it.
std::string head_points_csv() {
  const std::filesystem::path path = out_path("head-points.csv");
  test::write_file(path,
                   "text,r,a,s\n"
                   "left,-60,-20,20\n"
                   "right,60,-20,20\n"
                   "top,0,-20,70\n"
                   "low,0,-20,-30\n");
  return path.string();
}

glm::vec2 anchor_of(const nlohmann::json& layout, const std::string& text) {
  for (const auto& l : layout["labels"]) {
    if (l["text"] == text) return {l["anchor"][0].get<float>(), l["anchor"][1].get<float>()};
  }
  FAIL("no label " << text);
  return {};
}

}  // namespace

TEST_SUITE("cli") {
  TEST_CASE("render_opens_a_nifti_volume_from_the_front_with_a_preset_and_labels_from_csv") {
    const std::string image = out_path("ch2.png"), layout = out_path("ch2.json");
    const auto r = run_strata("render " + kCache + "/mricron/ch2.nii.gz --size 96 -o " + image +
                              " --labels " + head_points_csv() + " --layout " + layout);
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    CHECK(contains(r.output, "has no transfer function; preset mr-head"));
    CHECK(contains(r.output, "4 of 4 labels shown"));
    const double share = content_share(read_image(image));
    CHECK(share > 0.25);
    CHECK(share < 0.95);
    // From the front (anterior): the patient's left on the image's right, the top up.
    const nlohmann::json json = nlohmann::json::parse(test::read_file(layout));
    CHECK(anchor_of(json, "left").x > anchor_of(json, "right").x + 20.0f);
    CHECK(anchor_of(json, "top").y < anchor_of(json, "low").y - 20.0f);
  }

  TEST_CASE("slicer_markups_in_ras_and_fiducials_in_lps_put_the_anchors_on_the_same_pixels") {
    std::vector<nlohmann::json> layouts;
    for (const char* labels : {"landmarks_ras.mrk.json", "landmarks_lps.fcsv"}) {
      const std::string layout = out_path(std::string(labels) + ".layout.json");
      const auto r = run_strata(
          "render " + kCache + "/mricron/ch2.nii.gz --size 128 -o " + out_path("landmarks.png") +
          " --labels " STRATA_SOURCE_DIR "/tests/data/labels/" + labels + " --layout " + layout);
      INFO(r.output);
      REQUIRE(r.exit_code == 0);
      layouts.push_back(nlohmann::json::parse(test::read_file(layout)));
    }
    REQUIRE(layouts[0]["labels"].size() == 3);
    REQUIRE(layouts[1]["labels"].size() == 3);
    for (size_t i = 0; i < 3; ++i) {
      const auto& a = layouts[0]["labels"][i];
      const auto& b = layouts[1]["labels"][i];
      CHECK(a["text"] == b["text"]);
      CHECK(a["anchor"] == b["anchor"]);
      // and inside the picture, where the point is on the head
      CHECK(a["anchor"][0].get<float>() > 10.0f);
      CHECK(a["anchor"][0].get<float>() < 118.0f);
    }
  }

  TEST_CASE("render_opens_the_six_anatomical_views_of_a_volume_by_name") {
    const std::string image = out_path("ch2-views.png"), layout = out_path("ch2-views.json");
    const auto r = run_strata("render " + kCache + "/mricron/ch2.nii.gz --size 64 --no-labels -o " +
                              image + " --camera anterior,posterior,left,right,superior,inferior");
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    for (const char* view : {"anterior", "posterior", "left", "right", "superior", "inferior"}) {
      const Rgba8Image shot = read_image(out_path(std::string("ch2-views-") + view + ".png"));
      CHECK_MESSAGE(content_share(shot) > 0.25, view);
    }
  }

  TEST_CASE("render_opens_a_dicom_ct_folder_with_a_ct_preset") {
    const std::string image = out_path("ct5n.png");
    const auto r = run_strata("render " + kCache + "/dicom/CT5N --size 64 -o " + image);
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    CHECK(contains(r.output, "preset ct-"));
    CHECK(contains(r.output, "Hounsfield"));
    CHECK(content_share(read_image(image)) > 0.2);
  }

  TEST_CASE("render_opens_a_metaimage_and_a_preset_can_be_chosen") {
    const std::filesystem::path mha = out_path("ch2.mha");
    write_metaimage(mha, load_volume(kCache + "/mricron/ch2.nii.gz"), true);
    const std::string image = out_path("ch2-mha.jpg");
    const auto r =
        run_strata("render " + mha.string() + " --preset mr-brain --size 64 -o " + image);
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    CHECK_FALSE(contains(r.output, "has no transfer function"));  // chosen, not defaulted
    const std::string bytes = test::read_file(image);
    REQUIRE(bytes.size() > 3);
    CHECK(bytes.substr(0, 3) == "\xFF\xD8\xFF");  // a JPEG, as the extension says
    CHECK(content_share(read_image(image)) > 0.2);

    const auto bad = run_strata("render " + mha.string() + " --preset bone -o " + image);
    CHECK(bad.exit_code == 2);  // (a bad option value)
    CHECK(contains(bad.output, "--preset: 'bone' is not a preset (ct-skin,"));
  }

  TEST_CASE("a_4d_nifti_shows_its_first_frame_or_the_one_asked_for_and_says_so") {
    const std::string image = out_path("4d.png");
    const std::string file = kCache + "/nibabel/example4d.nii.gz";
    const auto first = run_strata("render " + file + " --size 48 -o " + image);
    INFO(first.output);
    CHECK(first.exit_code == 0);
    CHECK(contains(first.output, "4-D image with 2 frames; showing frame 0 (choose with --frame)"));
    const auto second = run_strata("render " + file + " --frame 1 --size 48 -o " + image);
    CHECK(second.exit_code == 0);
    CHECK(contains(second.output, "showing frame 1"));
    const auto past = run_strata("render " + file + " --frame 2 --size 48 -o " + image);
    CHECK(past.exit_code != 0);
    CHECK(contains(past.output, "frame 2 is out of range: the image has 2 frames, 0 to 1"));
    const auto info = run_strata("info " + kCache + "/dicom/CT_small.dcm");
    CHECK(info.exit_code == 0);
    CHECK(contains(info.output, "128x128x1"));
  }

  TEST_CASE("a_scene_without_camera_or_transfer_function_is_fitted_and_given_a_preset") {
    const std::filesystem::path scene = out_path("bare.json");
    test::write_file(scene, R"({"strata_scene": 1,
      "volumes": [{"file": ")" + kCache +
                                R"(/mricron/ch2.nii.gz"}],
      "labels": [{"id": 1, "text": "Thalamus", "anchor": [-10, 18, 8]}],
      "settings": {"layers": 2}})");
    const std::string image = out_path("bare.png");
    const auto r = run_strata("render " + scene.string() + " --size 96 -o " + image);
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    CHECK(contains(r.output, "1 of 1 labels shown"));  // not from inside the head
    CHECK(contains(r.output, "preset mr-head"));       // a warning, not a black image
    CHECK(content_share(read_image(image)) > 0.25);

    // settings.layers applies unless --layers overrides it.
    const auto two = run_strata("render " + scene.string() + " --no-labels --size 32 -o " + image);
    CHECK(contains(two.output, "(32x32, 2 layers)"));
    const auto three =
        run_strata("render " + scene.string() + " --no-labels --layers 3 --size 32 -o " + image);
    CHECK(contains(three.output, "(32x32, 3 layers)"));
  }

  TEST_CASE("out_of_range_options_and_unknown_formats_are_errors_that_name_the_limit") {
    const std::string head = STRATA_SOURCE_DIR "/assets/scenes/head.json";
    const auto nine = run_strata("render " + head + " --layers 9 -o " + out_path("x.png"));
    CHECK(nine.exit_code != 0);
    CHECK(contains(nine.output, "--layers"));
    CHECK(contains(nine.output, "8"));
    const auto zero = run_strata("render " + head + " --layers 0 -o " + out_path("x.png"));
    CHECK(zero.exit_code != 0);
    const auto size = run_strata("render " + head + " --size 0 -o " + out_path("x.png"));
    CHECK(size.exit_code != 0);
    CHECK(contains(size.output, "1 to 16384"));
    const auto huge = run_strata("render " + head + " --size 20000x10 -o " + out_path("x.png"));
    CHECK(huge.exit_code != 0);
    CHECK(contains(huge.output, "16384"));
    std::filesystem::remove(out_path("x.bmp"));
    const auto bmp = run_strata("render " + head + " --size 32 -o " + out_path("x.bmp"));
    CHECK(bmp.exit_code != 0);
    CHECK(contains(bmp.output, "x.bmp: cannot write images as '.bmp'"));
    CHECK_FALSE(std::filesystem::exists(out_path("x.bmp")));
    const auto missing =
        run_strata("render " + kCache + "/mricron/none.nii.gz -o " + out_path("x.png"));
    CHECK(missing.exit_code != 0);
    CHECK(contains(missing.output, "none.nii.gz: no such file"));
  }

  TEST_CASE("usage_errors_exit_2_and_a_write_that_fails_is_an_error") {
    const auto usage = run_strata("render --bogus");
    CHECK(usage.exit_code == 2);
    CHECK(
        contains(usage.output, "strata: error: The following argument was not expected: --bogus"));
    const auto range = run_strata("render --layers 9");
    CHECK(range.exit_code == 2);
    CHECK(contains(range.output, "strata: error: --layers"));
    CHECK(run_strata("--help").exit_code == 0);
    // Option values strata checks itself are usage errors too.
    const std::string head = STRATA_SOURCE_DIR "/assets/scenes/head.json";
    for (const std::string& args :
         {std::string("render --size 0"),
          "render " + head + " --size 16 --camera front,,left -o " + out_path("never.png"),
          std::string("video --fps 1000 --orbit 90"), std::string("video --size 16")}) {
      const auto value = run_strata(args);
      INFO(args, ": ", value.output);
      CHECK(value.exit_code == 2);
      CHECK(contains(value.output, "strata: error: "));
    }
    // Input errors: 1.
    const auto input = run_strata("render /nonexistent/scene.json --size 16");
    CHECK(input.exit_code == 1);
    CHECK(contains(input.output, "strata: error: /nonexistent/scene.json: no such file"));
    // A full disk: the write is checked, not reported as done.
    const auto full = run_strata("render --size 16 -o /dev/full");
    CHECK(full.exit_code == 1);
    CHECK(contains(full.output, "/dev/full: cannot write PNG: No space left on device"));
    CHECK_FALSE(contains(full.output, "wrote /dev/full"));
  }

  TEST_CASE("dump_layers_leaves_the_labelled_image_as_it_is") {
    const std::string head = STRATA_SOURCE_DIR "/assets/scenes/head.json";
    const std::string plain = out_path("plain.png"), dumped = out_path("dumped.png");
    const std::string folder = out_path("layers");
    std::filesystem::remove_all(folder);
    REQUIRE(run_strata("render " + head + " --size 64 -o " + plain).exit_code == 0);
    const auto r =
        run_strata("render " + head + " --size 64 -o " + dumped + " --dump-layers " + folder);
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    CHECK(contains(r.output, "labels shown"));
    CHECK(test::read_file(plain) == test::read_file(dumped));
    CHECK(std::filesystem::exists(folder + "/layer-0.png"));
  }

  TEST_CASE("bench_finds_its_default_scene_outside_the_repository") {
    const auto r = run_strata("bench render --size 32 --runs 1", "cd / &&");
    INFO(r.output);
    CHECK(r.exit_code == 0);
    CHECK(contains(r.output, "\"benchmark\""));
  }

  TEST_CASE("optimised_orders_report_their_progress") {
    const std::string head = STRATA_SOURCE_DIR "/assets/scenes/head.json";
    const auto r = run_strata("render " + head + " --size 32 --order optimized -o " +
                              out_path("optimized.png"));
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    CHECK(contains(r.output, "insertion order 8/8"));
  }

  TEST_CASE("a_volume_the_device_cannot_hold_is_refused_from_its_header") {
    // NIfTI-1 headers alone (no voxels): the device's limits are checked before any is read.
    const auto header = [](int16_t x, int16_t y, int16_t z) {
      std::string h(352, '\0');
      const auto put = [&](size_t at, auto v) { std::memcpy(h.data() + at, &v, sizeof v); };
      put(0, int32_t{348}), put(40, int16_t{3}), put(42, x), put(44, y), put(46, z);
      put(70, int16_t{2}), put(108, 352.0f);
      for (size_t i = 0; i < 4; ++i) put(76 + 4 * i, 1.0f);
      h.replace(344, 4, std::string("n+1\0", 4));
      return h;
    };
    const std::string wide = out_path("wide.nii"), many = out_path("many.nii");
    test::write_file(wide, header(30000, 2, 2));
    test::write_file(many, header(2048, 2048, 1024));
    const auto a = run_strata("render " + wide + " --size 32 -o " + out_path("wide.png"));
    CHECK(a.exit_code == 1);
    INFO(a.output);
    CHECK(contains(a.output, "strata: error: " + wide + ": dim[1..3] = 30000x2x2: the device ("));
    CHECK(contains(a.output, ") renders at most "));
    const auto b = run_strata("render " + many + " --size 32 -o " + out_path("many.png"));
    CHECK(b.exit_code == 1);
    INFO(b.output);
    CHECK((contains(b.output, "voxels; the device (") || contains(b.output, "of memory")));
  }
}

}  // namespace strata
