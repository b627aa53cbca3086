// Label pictures: PNG and JPEG files read as rgba8 (the JPEG written by stb's encoder, read by
// libjpeg-turbo), their errors, resampling to the drawn size, and the image atlas.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <stb_image_write.h>

#include "engine/core/image.h"
#include "engine/core/image_atlas.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using strata::Rgba8Image;
using strata::test::error_of;
using strata::test::read_file;
using strata::test::write_file;

fs::path test_folder(const std::string& name) {
  return strata::test::fresh_folder("image_tests", name);
}

// Four flat 16x16 quadrants: red, green / blue, yellow (8x8 blocks: JPEG keeps them flat).
Rgba8Image quadrants() {
  Rgba8Image image{32, 32, std::vector<uint8_t>(32 * 32 * 4)};
  const uint8_t colours[4][4] = {
      {220, 30, 30, 255}, {30, 200, 40, 255}, {40, 60, 210, 255}, {230, 220, 40, 255}};
  for (uint32_t y = 0; y < 32; ++y) {
    for (uint32_t x = 0; x < 32; ++x) {
      const uint8_t* c = colours[(y / 16) * 2 + x / 16];
      std::copy_n(c, 4, image.pixels.begin() + std::ptrdiff_t((y * 32 + x) * 4));
    }
  }
  return image;
}

std::array<int, 4> pixel(const Rgba8Image& image, uint32_t x, uint32_t y) {
  const size_t i = (size_t{y} * image.width + x) * 4;
  return {image.pixels[i], image.pixels[i + 1], image.pixels[i + 2], image.pixels[i + 3]};
}

int difference(std::array<int, 4> a, std::array<int, 4> b) {
  int worst = 0;
  for (size_t c = 0; c < 4; ++c) worst = std::max(worst, std::abs(a[c] - b[c]));
  return worst;
}

}  // namespace

TEST_SUITE("loaders") {
  TEST_CASE("png_and_jpeg_pictures_read_as_rgba8") {
    const fs::path folder = test_folder("read");
    const Rgba8Image image = quadrants();
    const fs::path png = folder / "q.png";
    strata::write_png(png.string(), image.width, image.height, image.pixels);
    const Rgba8Image from_png = strata::read_image(png);
    CHECK(from_png.width == 32);
    CHECK(from_png.height == 32);
    CHECK(from_png.pixels == image.pixels);

    // A JPEG of any extension, colour and grey: each quadrant's centre within JPEG's error.
    const fs::path jpeg = folder / "q.picture";
    REQUIRE(stbi_write_jpg(jpeg.c_str(), 32, 32, 4, image.pixels.data(), 100));
    const Rgba8Image from_jpeg = strata::read_image(jpeg);
    REQUIRE(from_jpeg.width == 32);
    REQUIRE(from_jpeg.height == 32);
    for (const auto& at : {std::pair{8u, 8u}, {24u, 8u}, {8u, 24u}, {24u, 24u}}) {
      CAPTURE(at.first);
      CAPTURE(at.second);
      CHECK(difference(pixel(from_jpeg, at.first, at.second), pixel(image, at.first, at.second)) <= 6);
    }
    const std::vector<uint8_t> grey(16 * 8, 90);
    const fs::path grey_jpeg = folder / "grey.jpg";
    REQUIRE(stbi_write_jpg(grey_jpeg.c_str(), 16, 8, 1, grey.data(), 100));
    const Rgba8Image from_grey = strata::read_image(grey_jpeg);
    CHECK(from_grey.width == 16);
    CHECK(difference(pixel(from_grey, 3, 3), {90, 90, 90, 255}) <= 2);
  }

  TEST_CASE("bad_pictures_are_one_error_naming_the_file_and_the_reason") {
    const fs::path folder = test_folder("bad");
    const Rgba8Image image = quadrants();
    strata::write_png((folder / "q.png").string(), image.width, image.height, image.pixels);
    REQUIRE(stbi_write_jpg((folder / "q.jpg").c_str(), 32, 32, 4, image.pixels.data(), 90));
    const std::string png = read_file(folder / "q.png");
    const std::string jpeg = read_file(folder / "q.jpg");
    const auto error = [&](const std::string& name, const std::string& bytes) {
      const fs::path path = write_file(folder / name, bytes);
      return error_of([&] { strata::read_image(path); });
    };
    const fs::path missing = folder / "missing.png";
    CHECK(error_of([&] { strata::read_image(missing); }) == missing.string() + ": no such file");
    CHECK(error("text.png", "not a picture") ==
          (folder / "text.png").string() + ": not a PNG or JPEG file");
    CHECK(error("empty.jpg", "") == (folder / "empty.jpg").string() + ": not a PNG or JPEG file");
    CHECK(error("a.gif", "GIF89a\x01\x00\x01\x00") ==
          (folder / "a.gif").string() + ": not a PNG or JPEG file");
    // Cut short, or damaged after the header: libjpeg's or stb's reason, never a crash.
    const std::string cut_png = error("cut.png", png.substr(0, png.size() / 2));
    CHECK(cut_png.rfind((folder / "cut.png").string() + ": corrupt PNG: ", 0) == 0);
    const std::string cut_jpeg = error("cut.jpg", jpeg.substr(0, jpeg.size() / 2));
    CHECK(cut_jpeg.rfind((folder / "cut.jpg").string() + ": corrupt JPEG: ", 0) == 0);
    CHECK(error("header.jpg", jpeg.substr(0, 20)).find(": corrupt JPEG: ") != std::string::npos);
    std::string scrambled = jpeg;
    for (size_t i = jpeg.size() / 3; i < jpeg.size() - 2; i += 7) scrambled[i] = char(0xFF);
    CHECK(error("scrambled.jpg", scrambled).find(": corrupt JPEG: ") != std::string::npos);
    // A side over the limit is refused before any pixels are decoded.
    const std::vector<uint8_t> wide(size_t{strata::kMaxImageSide + 1} * 4, 255);
    strata::write_png((folder / "wide.png").string(), strata::kMaxImageSide + 1, 1, wide);
    CHECK(error_of([&] { strata::read_image(folder / "wide.png"); }) ==
          (folder / "wide.png").string() + ": 8193x1 pixels (expected 1 to 8192 a side)");
  }

  TEST_CASE("resizing_averages_when_shrinking_and_never_bleeds_transparent_colour") {
    const Rgba8Image image = quadrants();
    // Halved: each quadrant stays its flat colour away from the seams.
    const Rgba8Image half = strata::resized_premultiplied(image, 16, 16);
    CHECK(pixel(half, 3, 3) == pixel(image, 3, 3));
    CHECK(pixel(half, 12, 12) == pixel(image, 28, 28));
    // Across a seam, a blend of the two sides.
    const std::array<int, 4> seam = pixel(strata::resized_premultiplied(image, 2, 1), 0, 0);
    CHECK(seam[0] > 30);
    CHECK(seam[2] > 40);
    // Opaque red beside transparent green: premultiplied, the green never shows.
    Rgba8Image half_clear{2, 1, {255, 0, 0, 255, 0, 255, 0, 0}};
    const Rgba8Image one = strata::resized_premultiplied(half_clear, 1, 1);
    CHECK(pixel(one, 0, 0) == std::array<int, 4>{128, 0, 0, 128});
    // Enlarged: bilinear between texel centres, the edges clamped.
    const Rgba8Image grown = strata::resized_premultiplied(Rgba8Image{2,
                                                                      1,
                                                                      {0, 0, 0, 255,  //
                                                                       200, 0, 0, 255}},
                                                           4, 1);
    CHECK(pixel(grown, 0, 0)[0] == 0);
    CHECK(pixel(grown, 1, 0)[0] == 50);
    CHECK(pixel(grown, 2, 0)[0] == 150);
    CHECK(pixel(grown, 3, 0)[0] == 200);
  }

  TEST_CASE("image_atlas_packs_pictures_apart_with_their_edge_texels_around_them") {
    const Rgba8Image a = quadrants();
    const Rgba8Image b = strata::resized_premultiplied(a, 20, 10);
    const Rgba8Image c{300, 5, std::vector<uint8_t>(300 * 5 * 4, 7)};
    const std::vector<Rgba8Image> images = {a, b, c};
    const strata::ImageAtlas atlas = strata::pack_image_atlas(images);
    REQUIRE(atlas.rects.size() == 3);
    CHECK(atlas.width >= 302);
    CHECK(atlas.texels.size() == size_t{atlas.width} * atlas.height * 4);
    std::vector<glm::ivec4> texels;  // each picture's rectangle with its border, in texels
    for (size_t i = 0; i < 3; ++i) {
      const glm::vec4 r =
          atlas.rects[i] * glm::vec4(atlas.width, atlas.height, atlas.width, atlas.height);
      const glm::ivec4 t(glm::round(r));
      CHECK(t.z - t.x == int(images[i].width));
      CHECK(t.w - t.y == int(images[i].height));
      CHECK(t.x >= 1);
      CHECK(t.y >= 1);
      texels.push_back(t + glm::ivec4(-1, -1, 1, 1));
      // Its texels, and the border's copies of its edge.
      for (int y = t.y - 1; y < t.w + 1; ++y) {
        for (int x = t.x - 1; x < t.z + 1; ++x) {
          const uint32_t sx = uint32_t(std::clamp(x - t.x, 0, int(images[i].width) - 1));
          const uint32_t sy = uint32_t(std::clamp(y - t.y, 0, int(images[i].height) - 1));
          const size_t at = (size_t(y) * atlas.width + size_t(x)) * 4;
          const std::array<int, 4> in_atlas{atlas.texels[at], atlas.texels[at + 1],
                                            atlas.texels[at + 2], atlas.texels[at + 3]};
          REQUIRE(in_atlas == pixel(images[i], sx, sy));
        }
      }
    }
    for (size_t i = 0; i < 3; ++i) {
      for (size_t j = i + 1; j < 3; ++j) {
        const bool apart = texels[i].z <= texels[j].x || texels[j].z <= texels[i].x ||
                           texels[i].w <= texels[j].y || texels[j].w <= texels[i].y;
        CHECK(apart);
      }
    }
    const strata::ImageAtlas none = strata::pack_image_atlas({});
    CHECK(none.width == 1);
    CHECK(none.texels == std::vector<uint8_t>(4, 0));
  }
}
