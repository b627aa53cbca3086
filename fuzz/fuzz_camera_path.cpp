// Camera-path text (`strata video --path`, labeling/camera_path.cpp) through parse_camera_path on
// a small scene of a box seen from named positions, then the path sampled and evaluated: a path
// must parse into keys that sample() turns into a bounded number of finite cameras, or give an
// Error.
#include <cmath>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "fuzz/fuzz_input.h"
#include "labeling/camera_path.h"
#include "tests/test_scenes.h"

namespace {

// tests/test_scenes.h's box, with named positions around it.
strata::Scene box_scene() {
  strata::Scene scene = strata::test::box_scene();
  const auto pose = [](const char* name, glm::vec3 eye, glm::vec3 target, glm::vec3 up) {
    return strata::CameraPose{name, glm::lookAt(eye, target, up)};
  };
  const glm::vec3 centre(10, 20, 30);
  scene.camera_positions = {pose("front", {10, -80, 30}, centre, {0, 0, 1}),
                            pose("left", {110, 20, 30}, centre, {0, 0, 1}),
                            pose("top", {10, 20, 130}, centre, {0, -1, 0}),
                            pose("left_side", {110, 21, 30}, centre, {0, 0, 1}),
                            // (facing away from the centre: a move to it turns on the spot)
                            pose("back", {10, 120, 30}, {10, 200, 30}, {0, 0, 1})};
  return scene;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const strata::Scene scene = box_scene();
  const std::string text(reinterpret_cast<const char*>(data), size);
  strata::fuzz::expect_only_errors([&] {
    const strata::CameraPath path = strata::parse_camera_path(scene, text);
    if (path.keys.empty() ||
        !(path.duration() >= 0.0 && path.duration() <= strata::kMaxPathSeconds)) {
      std::fprintf(stderr, "fuzz: a path of %zu keys lasting %g s\n", path.keys.size(),
                   path.duration());
      std::abort();
    }
    // (2 fps: at most 7,201 frames, so a long path stays quick to sample)
    for (const strata::Camera& camera : strata::sample(path, 2.0)) {
      for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r) {
          if (!std::isfinite(camera.view[c][r])) {
            std::fprintf(stderr, "fuzz: a camera that is not finite\n");
            std::abort();
          }
        }
      }
    }
  });
  return 0;
}
