// A camera path's durations and a video's frame count are bounded (labeling/camera_path.h):
// errors before anything is allocated, not a bad_alloc.
#include <doctest/doctest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/core/error.h"
#include "labeling/camera_path.h"
#include "test_scenes.h"

namespace strata {

TEST_SUITE("cpu") {
  TEST_CASE("camera_path_refuses_huge_segments_and_sums_and_sample_refuses_huge_frame_counts") {
    Scene scene = test::box_scene();
    scene.camera_positions = {
        {"front", glm::lookAt(glm::vec3(10, -80, 30), glm::vec3(10, 20, 30), glm::vec3(0, 0, 1))},
        {"left", glm::lookAt(glm::vec3(110, 20, 30), glm::vec3(10, 20, 30), glm::vec3(0, 0, 1))}};
    CHECK_THROWS_WITH_AS(parse_camera_path(scene, "front,left_1e9"),
                         doctest::Contains("'1e9' is not a duration (seconds in (0, 3600])"),
                         Error);
    CHECK_THROWS_WITH_AS(parse_camera_path(scene, "front,left_2000,front_1601"),
                         doctest::Contains("'front_1601': the path lasts more than 3600 s"), Error);
    const CameraPath hour = parse_camera_path(scene, "front,left_1800,front_1800");
    CHECK(hour.duration() == 3600.0);
    CHECK(sampled_frames(hour, 24.0) == 86401.0);
    CHECK(sample(parse_camera_path(scene, "front,left_2"), 30.0).size() == 61);
    CHECK_THROWS_WITH_AS(sample(hour, 30.0), doctest::Contains("more than 100000 frames"), Error);
    CHECK_THROWS_AS(orbit_path(scene, scene.camera, 90.0, 1e9), Error);
  }
}

}  // namespace strata
