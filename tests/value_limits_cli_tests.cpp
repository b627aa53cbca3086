// `strata render` of files whose values a float holds but a picture cannot use: exit 1 and the
// loader's one message, before any device work.
#include <doctest/doctest.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "gpu_fixture.h"
#include "test_files.h"

namespace strata {
namespace {

std::string folder_for(const std::string& name) {
  return test::fresh_folder("value_limits_cli", name).string();
}

// A little-endian NIfTI-1 file of 2x2x2 uint8 voxels with pixdim[1] = `spacing`.
std::string nifti_with_spacing(float spacing) {
  std::string bytes(352 + 8, '\0');
  const auto put = [&](size_t offset, auto value) {
    std::memcpy(bytes.data() + offset, &value, sizeof value);
  };
  put(0, int32_t{348});
  put(40, int16_t{3});
  for (size_t axis = 0; axis < 3; ++axis) put(42 + 2 * axis, int16_t{2});
  put(70, int16_t{2});
  put(76, 1.0f);
  put(80, spacing);
  put(84, 1.0f);
  put(88, 1.0f);
  put(108, 352.0f);
  std::memcpy(bytes.data() + 344, "n+1\0", 4);
  return bytes;
}

test::CommandResult run_strata_render(const std::string& scene, const std::string& folder) {
  return test::run_strata("render " + scene + " --size 32 -o " + folder + "/out.png");
}

// The one "strata: error: " line's message (the device line may come before it), or what was
// wrong: no error line, or more than one.
std::string only_error(const std::string& output) {
  const std::string tag = "strata: error: ";
  const size_t start = output.find(tag);
  if (start == std::string::npos) return "(no error line in: " + output + ")";
  if (output.find(tag, start + 1) != std::string::npos) return "(two error lines: " + output + ")";
  const size_t end = output.find('\n', start);
  return output.substr(start + tag.size(),
                       end == std::string::npos ? end : end - start - tag.size());
}

}  // namespace

TEST_SUITE("cli") {
  TEST_CASE("render_of_a_nifti_with_spacing_3e38_exits_1_with_one_message") {
    const std::string folder = folder_for("spacing");
    const std::string path = folder + "/head.nii";
    test::write_file(path, nifti_with_spacing(3e38f));
    const auto r = run_strata_render(path, folder);
    CHECK(r.exit_code == 1);
    CHECK(only_error(r.output) == path + ": pixdim[1]: spacing 3e+38 mm is outside 1e-06..10000");
  }

  TEST_CASE("render_of_a_scene_with_an_anchor_at_3e38_exits_1_with_one_message") {
    const std::string folder = folder_for("anchor");
    const std::string path = folder + "/scene.json";
    test::write_file(path, R"({"strata_scene": 1,
                               "labels": [{"id": 0, "text": "a", "anchor": [0, 0, 3e38]}]})");
    const auto r = run_strata_render(path, folder);
    CHECK(r.exit_code == 1);
    CHECK(only_error(r.output) ==
          path + ": labels[0].anchor: anchor 0 0 3e+38 mm is outside -1e+06..1e+06");
  }
}

}  // namespace strata
