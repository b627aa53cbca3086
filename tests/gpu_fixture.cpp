#include "gpu_fixture.h"

#include "engine/core/png.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <doctest/doctest.h>
#include <sys/wait.h>

#include <glm/gtc/packing.hpp>

namespace strata::test {

Context& gpu() {
  static Context ctx([] {
    ContextOptions options;
    options.validation = true;
    options.quiet = true;
    return options;
  }());
  return ctx;
}

GpuTest::GpuTest() {
  ctx.validation_log().take();
}

GpuTest::~GpuTest() {
  for (const std::string& message : ctx.validation_log().take()) {
    FAIL_CHECK("validation layer: " << message);
  }
}

CommandResult run_strata(const std::string& args, const std::string& env) {
  const std::string command = env + (env.empty() ? "" : " ") + STRATA_BINARY + " " + args + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  REQUIRE_MESSAGE(pipe != nullptr, "cannot run " << command);
  char buffer[4096];
  size_t n = 0;
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) result.output.append(buffer, n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

Image layer_image(Context& ctx, graph::Extent size, uint32_t layer_count,
                  const std::vector<glm::vec4>& layers) {
  Image image(ctx, {VK_FORMAT_R16G16B16A16_SFLOAT,
                    {size.width, size.height, 1},
                    VK_IMAGE_TYPE_2D,
                    VK_IMAGE_USAGE_STORAGE_BIT,
                    layer_count,
                    true});
  std::vector<uint64_t> halves;
  for (const glm::vec4& c : layers) halves.push_back(glm::packHalf4x16(c));
  upload(ctx, image, as_bytes(halves), VK_IMAGE_LAYOUT_GENERAL);
  return image;
}

std::string probe_video(const std::string& file, const std::string& entries) {
  const std::string command =
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=" + entries +
      " -of csv=p=0 '" + file + "' 2>&1";
  std::FILE* pipe = popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::string out;
  char buffer[256];
  while (std::fgets(buffer, sizeof buffer, pipe)) out += buffer;
  pclose(pipe);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

std::string output_dir() {
  const std::string dir = STRATA_TEST_OUTPUT;
  std::filesystem::create_directories(dir);
  return dir;
}

void check_close(const std::vector<uint8_t>& actual, const std::vector<uint8_t>& expected,
                 graph::Extent size, const std::string& name, int tolerance, int channels) {
  REQUIRE(actual.size() == expected.size());
  size_t bad = 0;
  std::vector<uint8_t> diff(actual.size(), 255);
  for (size_t p = 0; p < actual.size() / 4; ++p) {
    int worst = 0;
    for (int ch = 0; ch < channels; ++ch) {
      const int d = std::abs(int(actual[4 * p + ch]) - int(expected[4 * p + ch]));
      worst = std::max(worst, d);
      if (ch < 3) diff[4 * p + ch] = uint8_t(std::min(255, d * 8));
    }
    bad += worst > tolerance;
  }
  const size_t pixels = actual.size() / 4;
  if (bad * 100 > pixels) {
    const std::string base = test::output_dir() + "/" + name;
    write_png(base + ".actual.png", size.width, size.height, actual);
    write_png(base + ".expected.png", size.width, size.height, expected);
    write_png(base + ".difference.png", size.width, size.height, diff);
  }
  CHECK_MESSAGE(bad * 100 <= pixels, name << ": " << bad << " of " << pixels
                                          << " pixels differ by more than " << tolerance << "/255");
}

}  // namespace strata::test
