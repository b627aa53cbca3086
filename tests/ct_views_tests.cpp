// A bare CT as a user opens it: the standard views by name, a crop fitted again, the scene's
// preset and window keys as the options, and the documented windows showing what they claim. The
// CT is a phantom of a head in Hounsfield units (the bundled CT5N holds no bone): air, skin and
// soft tissue, a skull, brain inside, a neck of soft tissue only, a nose in front.
#include <doctest/doctest.h>

#include <cmath>
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

std::string out_path(const std::string& name) {
  return test::output_dir() + "/ct-views-" + name;
}

// 64^3 voxels of 3 mm, centred on the origin (LPS).
Volume ct_head_phantom(bool with_bone = true) {
  Volume v;
  v.name = "phantom";
  v.type = VoxelType::int16;
  v.dims = {64, 64, 64};
  v.spacing = glm::vec3(3.0f);
  v.origin = glm::vec3(-94.5f);
  std::vector<int16_t> values(v.voxel_count());
  for (uint32_t k = 0; k < 64; ++k) {
    for (uint32_t j = 0; j < 64; ++j) {
      for (uint32_t i = 0; i < 64; ++i) {
        const glm::vec3 p = v.origin + 3.0f * glm::vec3(i, j, k);
        const float r = glm::length(p / glm::vec3(70.0f, 85.0f, 90.0f));
        int16_t value = -1000;
        if (p.z > -40.0f && r <= 1.0f) {
          value = r < 0.82f ? 35 : r <= 0.92f ? (with_bone ? 1000 : 40) : 40;
        } else if (p.z <= -40.0f && p.z > -90.0f &&
                   glm::length(glm::vec2(p.x, p.y - 10.0f)) < 40.0f) {
          value = 40;  // the neck
        }
        if (glm::length(p - glm::vec3(0.0f, -85.0f, 0.0f)) < 14.0f) value = 40;  // the nose
        values[(size_t{k} * 64 + j) * 64 + i] = value;
      }
    }
  }
  v.voxels.resize(values.size() * 2);
  std::memcpy(v.voxels.data(), values.data(), v.voxels.size());
  v.value_range = {-1000.0f, with_bone ? 1000.0f : 40.0f};
  return v;
}

std::string phantom_file(bool with_bone = true) {
  const std::string path = out_path(with_bone ? "phantom.mha" : "phantom-no-bone.mha");
  if (!std::filesystem::exists(path)) write_metaimage(path, ct_head_phantom(with_bone), true);
  return path;
}

// Whether a pixel differs from the background (the corner's colour).
bool content_at(const Rgba8Image& image, uint32_t x, uint32_t y) {
  const uint8_t* corner = image.pixels.data();
  const uint8_t* px = image.pixels.data() + (size_t{y} * image.width + x) * 4;
  int difference = 0;
  for (int c = 0; c < 3; ++c) difference += std::abs(int(px[c]) - int(corner[c]));
  return difference > 24;
}

int brightness(const Rgba8Image& image, uint32_t x, uint32_t y) {
  const uint8_t* px = image.pixels.data() + (size_t{y} * image.width + x) * 4;
  return (int(px[0]) + int(px[1]) + int(px[2])) / 3;
}

// The larger side of the box around the content, in pixels (0 for none).
uint32_t content_extent(const Rgba8Image& image) {
  uint32_t x0 = image.width, y0 = image.height, x1 = 0, y1 = 0;
  for (uint32_t y = 0; y < image.height; ++y) {
    for (uint32_t x = 0; x < image.width; ++x) {
      if (!content_at(image, x, y)) continue;
      x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
    }
  }
  return x1 < x0 ? 0 : std::max(x1 - x0, y1 - y0) + 1;
}

size_t content_pixels(const Rgba8Image& image) {
  size_t n = 0;
  for (uint32_t y = 0; y < image.height; ++y)
    for (uint32_t x = 0; x < image.width; ++x) n += content_at(image, x, y);
  return n;
}

Rgba8Image render(const std::string& args, const std::string& name) {
  const std::string image = out_path(name);
  const auto r = run_strata("render " + args + " --size 96 -o " + image);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  return read_image(image);
}

}  // namespace

TEST_SUITE("cli") {
  TEST_CASE("a_bare_ct_opens_the_oblique_views_and_the_short_names") {
    const auto r = run_strata(
        "render " + phantom_file() +
        " --size 64 --window 40,400 --camera front,oblique,als,posterior-right-inferior -o " +
        out_path("names.png"));
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    for (const char* name : {"front", "oblique", "als", "posterior-right-inferior"}) {
      CAPTURE(name);
      const Rgba8Image shot = read_image(out_path(std::string("names-") + name + ".png"));
      CHECK(content_extent(shot) > 30);  // (the oblique views fit the box's corners)
    }
    // The nose (anterior) is seen from the front, the oblique views from its side.
    CHECK(read_image(out_path("names-front.png")).pixels !=
          read_image(out_path("names-oblique.png")).pixels);
    const auto bad = run_strata("render " + phantom_file() + " --size 16 --camera als-x -o " +
                                out_path("bad.png"));
    CHECK(bad.exit_code == 2);
    CHECK(bad.output.find("no camera position named 'als-x'") != std::string::npos);
  }

  // A quarter of the head kept (its upper left): the camera fitted again to it fills the picture
  // (the whole head's camera shows it in a corner). The skin window makes all that is kept show.
  TEST_CASE("a_crop_of_a_bare_ct_is_fitted_to_fill_the_picture") {
    const std::string crop = " --window 40,400 --crop 0,-85,0,70,85,90";
    for (const char* camera : {"front", "left", "oblique"}) {
      CAPTURE(camera);
      const Rgba8Image fitted = render(phantom_file() + crop + " --camera " + camera,
                                       std::string("crop-") + camera + ".png");
      // (an oblique view fits the box's corners, which a rounded head leaves empty)
      const double share = std::string(camera) == "oblique" ? 0.5 : 0.8;
      CHECK(content_extent(fitted) >= uint32_t(share * 96));
    }
    const Rgba8Image whole = render(phantom_file() + crop + " --no-fit", "crop-no-fit.png");
    CHECK(content_extent(whole) < uint32_t(0.6 * 96));
  }

  TEST_CASE("a_scene_preset_or_window_key_renders_as_the_option") {
    const std::string scene = out_path("keys.json");
    for (const auto& [key, option] :
         {std::pair{std::string(R"("preset": "ct-bone")"), std::string("--preset ct-bone")},
          std::pair{std::string(R"("window": [900, 1200])"), std::string("--window 900,1200")}}) {
      CAPTURE(key);
      test::write_file(scene, R"({"strata_scene": 1, "volumes": [{"file": ")" + phantom_file() +
                                  R"(", )" + key + "}]}");
      const Rgba8Image keyed = render(scene + " --camera oblique", "keyed.png");
      const Rgba8Image given =
          render(phantom_file() + " " + option + " --camera oblique", "given.png");
      CHECK(keyed.pixels == given.pixels);
      CHECK(content_pixels(keyed) > 500);
    }
  }

  // The windows the docs give (docs/scene-format.md, README, --help): 900,1200 shows bone only
  // (its ramp starts at 300 HU, above soft tissue), 40,400 the skin.
  TEST_CASE("the_documented_windows_show_what_they_claim") {
    const Rgba8Image bone = render(phantom_file() + " --window 900,1200", "bone.png");
    const Rgba8Image skin = render(phantom_file() + " --window 40,400", "skin.png");
    const Rgba8Image no_bone = render(phantom_file(false) + " --window 900,1200", "no-bone.png");
    // Over the skull (the head's middle): opaque and bright in both.
    CHECK(brightness(bone, 48, 36) > 100);
    CHECK(brightness(skin, 48, 36) > 100);
    // Over the neck, soft tissue only: nothing in the bone window, the skin in the skin window.
    CHECK_FALSE(content_at(bone, 48, 80));
    CHECK(content_at(skin, 48, 80));
    // Soft tissue alone adds nothing to the bone window.
    CHECK(content_pixels(no_bone) == 0);
  }
}

TEST_SUITE("window") {
  // The viewer's level and window are the volume's values: saved, the scene holds its transfer
  // function in HU, so it shows the same tissue on another scan; a preset chosen is saved by name.
  TEST_CASE("the_viewer_saves_its_window_and_preset_in_the_volumes_values") {
    const std::filesystem::path folder = test::fresh_folder("ct_views", "viewer");
    const std::filesystem::path volume = folder / "ct.mha";
    std::filesystem::copy_file(phantom_file(), volume);
    const auto view = [&](const std::string& lines) {
      const std::filesystem::path script =
          test::write_file(folder / "script.txt", lines + "quit\n");
      const auto r = run_strata("view " + volume.string() + " --size 64 --no-panel --script " +
                                script.string());
      INFO(r.output);
      CHECK(r.exit_code == 0);
      const std::filesystem::path saved = folder / "ct.scene.json";
      const nlohmann::json scene = nlohmann::json::parse(test::read_file(saved));
      std::filesystem::remove(saved);
      return scene["volumes"][0];
    };
    const nlohmann::json preset = view("preset ct-bone\nsave-position a\n");
    CHECK(preset["preset"] == "ct-bone");
    const nlohmann::json windowed = view("window 300 1500\nsave-position a\n");
    CHECK_FALSE(windowed.contains("preset"));
    const nlohmann::json& tf = windowed["transfer_function"];
    CHECK(tf["units"] == "HU");
    // The preset's 0..1 of the value range spread over 300 -+ 750 HU.
    CHECK(tf["stops"].front()["position"].get<double>() == doctest::Approx(-450.0).epsilon(1e-4));
    CHECK(tf["stops"].back()["position"].get<double>() == doctest::Approx(1050.0).epsilon(1e-4));
  }
}

}  // namespace strata
