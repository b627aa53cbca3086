// Camera paths: the thesis program's path text, eased moves around the poses' targets,
// turntables about the scene's centre, and the frames of a video.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/core/error.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/scene_bounds.h"
#include "labeling/camera_path.h"
#include "test_scenes.h"

namespace strata {
namespace {

CameraPose look_at(const std::string& name, glm::vec3 eye, glm::vec3 target, glm::vec3 up) {
  return {name, glm::lookAt(eye, target, up)};
}

// test::box_scene() seen from the front, the left and the top.
Scene box_scene() {
  Scene scene = test::box_scene();
  scene.camera_positions = {look_at("front", {10, -80, 30}, {10, 20, 30}, {0, 0, 1}),
                            look_at("left", {110, 20, 30}, {10, 20, 30}, {0, 0, 1}),
                            look_at("top", {10, 20, 130}, {10, 20, 30}, {0, -1, 0})};
  return scene;
}

// Loaded once: the volume and atlas take a moment.
const Scene& head_scene() {
  static const Scene scene = load_scene(STRATA_SOURCE_DIR "/assets/scenes/head.json");
  return scene;
}

float max_difference(const glm::mat4& a, const glm::mat4& b) {
  float most = 0.0f;
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) most = std::max(most, std::abs(a[c][r] - b[c][r]));
  }
  return most;
}

glm::dvec3 eye_of(const Camera& camera) {
  return glm::dvec3(glm::inverse(glm::dmat4(camera.view))[3]);
}

glm::dvec3 forward_of(const Camera& camera) {
  const glm::dmat4 v(camera.view);
  return -glm::dvec3(v[0][2], v[1][2], v[2][2]);  // minus the view's row 2
}

// Camera to world.
glm::dmat3 orientation_of(const Camera& camera) {
  return glm::transpose(glm::dmat3(glm::dmat4(camera.view)));
}

// The angle of a rotation, from its antisymmetric part (sin) and its trace (cos): acos of the
// trace alone loses all precision for the small angles the speed checks measure.
double rotation_degrees(const glm::dmat3& r) {
  const glm::dmat3 antisymmetric = r - glm::transpose(r);
  double sine = 0.0;
  for (int c = 0; c < 3; ++c) sine += glm::dot(antisymmetric[c], antisymmetric[c]);
  sine = std::sqrt(sine / 8.0);
  const double cosine = 0.5 * (r[0][0] + r[1][1] + r[2][2] - 1.0);
  return glm::degrees(std::atan2(sine, cosine));
}

// The point of the camera's viewing axis closest to `centre`, as the path derives its target.
glm::dvec3 target_of(const Camera& camera, glm::dvec3 centre) {
  const glm::dvec3 eye = eye_of(camera), forward = forward_of(camera);
  return eye + forward * glm::dot(centre - eye, forward);
}

std::string error_of(const Scene& scene, const std::string& text) {
  try {
    parse_camera_path(scene, text);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The angle from a to b about +z, in degrees, of their parts across z.
double degrees_about_z(glm::dvec3 a, glm::dvec3 b) {
  return glm::degrees(std::atan2(a.x * b.y - a.y * b.x, a.x * b.x + a.y * b.y));
}

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("path_text_gives_positions_at_summed_times_with_one_second_by_default") {
    const Scene scene = box_scene();
    const CameraPath path = parse_camera_path(scene, "front,left_2,top, default_0.5");
    REQUIRE(path.keys.size() == 4);
    CHECK(path.keys[0].time == 0.0);
    CHECK(path.keys[1].time == 2.0);
    CHECK(path.keys[2].time == 3.0);
    CHECK(path.keys[3].time == 3.5);
    CHECK(path.duration() == 3.5);
    CHECK(path.keys[1].camera.view == scene.camera_positions[1].view);
    CHECK(path.keys[3].camera.view == scene.camera.view);
    for (const CameraKey& key : path.keys) {
      CHECK(key.camera.fov_y_degrees == 30.0f);
      CHECK(key.camera.near_plane == 1.0f);
      CHECK(key.camera.far_plane == 500.0f);
    }
    CHECK(parse_camera_path(scene, "top").duration() == 0.0);
  }

  TEST_CASE("a_position_whose_name_has_an_underscore_is_found_whole") {
    Scene scene = box_scene();
    scene.camera_positions.push_back(look_at("left_side", {110, 20, 40}, {10, 20, 30}, {0, 0, 1}));
    const CameraPath whole = parse_camera_path(scene, "front,left_side");
    CHECK(whole.keys[1].camera.view == scene.camera_positions[3].view);
    CHECK(whole.duration() == 1.0);
    const CameraPath timed = parse_camera_path(scene, "front,left_side_4");
    CHECK(timed.keys[1].camera.view == scene.camera_positions[3].view);
    CHECK(timed.duration() == 4.0);
  }

  TEST_CASE("path_errors_name_the_part_and_the_reason") {
    Scene scene = box_scene();
    scene.source = "box.json";
    CHECK(contains(error_of(scene, ""), "box.json: camera path '': empty"));
    CHECK(contains(error_of(scene, " "), "empty"));
    CHECK(contains(error_of(scene, "front,,left"), "camera path 'front,,left': part 2 is empty"));
    const std::string unknown = error_of(scene, "front,lft_2");
    CHECK(contains(unknown, "'lft_2': no position named 'lft'"));
    CHECK(contains(unknown, "front, left, top, default"));
    CHECK(contains(error_of(scene, "front,back"), "'back': no position named 'back'"));
    for (const char* bad : {"x", "0", "-1", "nan", "inf", "", "2s"}) {
      CAPTURE(bad);
      const std::string part = std::string("left_") + bad;
      CHECK(contains(error_of(scene, "front," + part),
                     "'" + part + "': '" + bad + "' is not a duration"));
    }
    CHECK(contains(error_of(scene, "front_2,left"), "'front_2': the first position"));
  }

  TEST_CASE("path_passes_through_its_positions_at_their_times") {
    const Scene& scene = head_scene();
    const CameraPath path = parse_camera_path(scene, "front,left_2,top_3,oblique_1.5");
    const std::pair<const char*, double> stops[] = {
        {"front", 0.0}, {"left", 2.0}, {"top", 5.0}, {"oblique", 6.5}};
    for (const auto& [name, time] : stops) {
      CAPTURE(name);
      const glm::mat4 view = camera_for(scene, name).view;
      CHECK(max_difference(path.at(time).view, view) < 1e-4f);
      // The moves themselves arrive there and leave from there: no jump at a key.
      CHECK(max_difference(path.at(time - 1e-6).view, view) < 1e-4f);
      CHECK(max_difference(path.at(time + 1e-6).view, view) < 1e-4f);
    }
    CHECK(path.at(-1.0).view == path.at(0.0).view);
    CHECK(path.at(100.0).view == path.at(6.5).view);
  }

  TEST_CASE("mid_move_keeps_the_distance_to_the_target_and_is_the_slerp_midpoint") {
    const Scene& scene = head_scene();
    const glm::dvec3 centre(scene_bounds(scene).centre());
    const Camera front = camera_for(scene, "front"), left = camera_for(scene, "left");
    const Camera mid = parse_camera_path(scene, "front,left_2").at(1.0);  // smoothstep(0.5) = 0.5
    const glm::dvec3 target_a = target_of(front, centre), target_b = target_of(left, centre);
    const double distance_a = glm::distance(eye_of(front), target_a);
    const double distance_b = glm::distance(eye_of(left), target_b);
    const glm::dvec3 target = 0.5 * (target_a + target_b);
    const double distance = 0.5 * (distance_a + distance_b);
    CHECK(glm::distance(eye_of(mid), target) == doctest::Approx(distance).epsilon(1e-5));
    CHECK(glm::distance(eye_of(mid) + forward_of(mid) * distance, target) < 1e-2);
    // A straight line between the eyes would pass about 0.7 times as close to the head.
    const double linear = glm::distance(0.5 * (eye_of(front) + eye_of(left)), centre);
    CHECK(glm::distance(eye_of(mid), centre) > 0.95 * std::min(distance_a, distance_b));
    CHECK(linear < 0.75 * std::min(distance_a, distance_b));
    // Half the turn from front to mid, the same half from mid to left.
    const glm::dmat3 a = orientation_of(front), m = orientation_of(mid), b = orientation_of(left);
    const glm::dmat3 first_half = m * glm::transpose(a), second_half = b * glm::transpose(m);
    for (int c = 0; c < 3; ++c) CHECK(glm::distance(first_half[c], second_half[c]) < 1e-5);
    CHECK(rotation_degrees(b * glm::transpose(a)) == doctest::Approx(90.0).epsilon(1e-4));
    CHECK(rotation_degrees(first_half) == doctest::Approx(45.0).epsilon(1e-4));
  }

  TEST_CASE("eased_moves_start_and_stop_at_zero_speed") {
    const Scene& scene = head_scene();
    const CameraPath path = parse_camera_path(scene, "front,left_2,top_3");
    const double h = 1e-3;
    auto speed = [&](double t0, double t1) {
      return glm::distance(eye_of(path.at(t1)), eye_of(path.at(t0))) / (t1 - t0);
    };
    auto turn_rate = [&](double t0, double t1) {
      const Camera a = path.at(t0), b = path.at(t1);
      return rotation_degrees(orientation_of(b) * glm::transpose(orientation_of(a))) / (t1 - t0);
    };
    for (const auto& [start, end] : {std::pair{0.0, 2.0}, std::pair{2.0, 5.0}}) {
      CAPTURE(start);
      const double mean_speed = speed(start, end);
      const double mean_turn = turn_rate(start, end);
      REQUIRE(mean_speed > 100.0);
      CHECK(speed(start, start + h) < 0.01 * mean_speed);
      CHECK(speed(end - h, end) < 0.01 * mean_speed);
      CHECK(turn_rate(start, start + h) < 0.01 * mean_turn);
      CHECK(turn_rate(end - h, end) < 0.01 * mean_turn);
      const double middle = 0.5 * (start + end);
      CHECK(speed(middle - h, middle + h) > mean_speed);
    }
  }

  TEST_CASE("a_full_turn_returns_to_the_start_at_a_constant_distance_from_the_centre") {
    const Scene& scene = head_scene();
    const glm::dvec3 centre(scene_bounds(scene).centre());
    const Camera start = camera_for(scene, "oblique");
    const CameraPath path = orbit_path(scene, start, 360.0, 8.0);
    CHECK(path.up == glm::vec3(0, 0, 1));  // the axis closest to the oblique camera's up
    CHECK(path.duration() == 8.0);
    CHECK(max_difference(path.at(8.0).view, start.view) < 1e-4f);
    CHECK(max_difference(path.at(8.0 - 1e-6).view, start.view) < 1e-3f);
    const glm::dvec3 from_centre = eye_of(start) - centre;
    for (int i = 0; i <= 16; ++i) {
      CAPTURE(i);
      const glm::dvec3 now = eye_of(path.at(0.5 * i)) - centre;
      CHECK(glm::length(now) == doctest::Approx(glm::length(from_centre)).epsilon(1e-5));
      CHECK(now.z == doctest::Approx(from_centre.z).epsilon(1e-5));  // a turntable keeps height
    }
    // The scene turns counter-clockwise seen from above, so the eye circles clockwise, at a
    // constant angular speed: no easing.
    CHECK(std::abs(degrees_about_z(from_centre, eye_of(path.at(4.0)) - centre)) ==
          doctest::Approx(180.0).epsilon(1e-4));
    CHECK(degrees_about_z(from_centre, eye_of(path.at(2.0)) - centre) ==
          doctest::Approx(-90.0).epsilon(1e-4));
    CHECK(degrees_about_z(from_centre, eye_of(path.at(0.1)) - centre) ==
          doctest::Approx(-4.5).epsilon(1e-4));
    const glm::dmat3 half = orientation_of(path.at(4.0)) * glm::transpose(orientation_of(start));
    CHECK(rotation_degrees(half) == doctest::Approx(180.0).epsilon(1e-4));
  }

  TEST_CASE("a_turntable_turns_about_the_world_axis_closest_to_the_camera_up") {
    const Scene scene = box_scene();
    CHECK(orbit_path(scene, camera_for(scene, "top"), 90.0, 1.0).up == glm::vec3(0, -1, 0));
    CHECK(orbit_path(scene, scene.camera, 90.0, 1.0).up == glm::vec3(0, 0, 1));
    CHECK_THROWS_AS(orbit_path(scene, scene.camera, 90.0, 0.0), Error);
  }

  TEST_CASE("sample_gives_round_duration_times_fps_plus_one_frames_from_start_to_end") {
    const Scene scene = box_scene();
    const CameraPath path = parse_camera_path(scene, "front,left_2,top_3");
    const std::vector<Camera> frames = sample(path, 30.0);
    REQUIRE(frames.size() == 151);
    CHECK(frames.front().view == path.at(0.0).view);
    CHECK(frames.back().view == path.at(5.0).view);
    CHECK(max_difference(frames[30].view, path.at(1.0).view) < 1e-5f);
    CHECK(sample(parse_camera_path(scene, "front,left_1.01"), 10.0).size() == 11);
    CHECK(sample(parse_camera_path(scene, "front,left_1.01"), 10.0).back().view ==
          scene.camera_positions[1].view);
    CHECK(sample(parse_camera_path(scene, "top"), 30.0).size() == 1);
    CHECK_THROWS_AS(sample(path, 0.0), Error);
  }

  // Every way a video comes back to its start (whole turns either way, a path back to its first
  // position) loops: its last frame, the first again, is dropped, and the step from the last
  // frame to the first is every other step. Paths that end elsewhere keep their last frame.
  TEST_CASE("a_looping_path_drops_the_frame_that_repeats_the_first_and_keeps_its_step") {
    const Scene& scene = head_scene();
    const Camera start = camera_for(scene, "oblique");
    const auto turn = [](const Camera& a, const Camera& b) {
      return rotation_degrees(orientation_of(b) * glm::transpose(orientation_of(a)));
    };
    for (const double degrees : {360.0, -360.0, 720.0}) {
      CAPTURE(degrees);
      const CameraPath path = orbit_path(scene, start, degrees, 2.0);
      CHECK(path.loops());
      const std::vector<Camera> frames = sample(path, 12.0);
      REQUIRE(frames.size() == 24);
      const double step = std::abs(degrees) / 24.0;
      for (size_t i = 0; i < frames.size(); ++i) {
        CAPTURE(i);
        const Camera& next = frames[(i + 1) % frames.size()];
        CHECK(turn(frames[i], next) == doctest::Approx(step).epsilon(1e-4));
      }
    }
    CHECK_FALSE(orbit_path(scene, start, 359.0, 2.0).loops());
    CHECK(sample(orbit_path(scene, start, 180.0, 2.0), 12.0).size() == 25);

    const Scene boxes = box_scene();
    const CameraPath there_and_back = parse_camera_path(boxes, "front,left_2,top_1,front_1");
    CHECK(there_and_back.loops());
    const std::vector<Camera> frames = sample(there_and_back, 10.0);
    REQUIRE(frames.size() == 40);
    CHECK(max_difference(frames.back().view, frames.front().view) > 1e-3f);
    CHECK(max_difference(frames.back().view, there_and_back.at(3.9).view) < 1e-5f);
    CHECK_FALSE(parse_camera_path(boxes, "front,left_2").loops());
    CHECK_FALSE(parse_camera_path(boxes, "front").loops());
    CHECK(sample(parse_camera_path(boxes, "front"), 10.0).size() == 1);
  }

  TEST_CASE("scene_bounds_cover_volumes_and_transformed_meshes_and_empty_scenes_centre_on_zero") {
    Scene scene;
    CHECK(scene_bounds(scene).empty());
    CHECK(scene_bounds(scene).centre() == glm::vec3(0.0f));
    Volume volume;
    volume.dims = {3, 3, 3};
    volume.spacing = glm::vec3(2.0f);
    volume.origin = glm::vec3(1.0f);
    scene.volumes.push_back(volume);
    Mesh mesh;
    mesh.positions = {{0, 0, 0}, {1, 2, 3}};
    mesh.transform = glm::translate(glm::mat4(1.0f), glm::vec3(100, 0, 0));
    scene.meshes.push_back(mesh);
    const Bounds bounds = scene_bounds(scene);
    CHECK(bounds.lo == glm::vec3(1, 0, 0));
    CHECK(bounds.hi == glm::vec3(101, 5, 5));
    CHECK(bounds.centre() == glm::vec3(51, 2.5f, 2.5f));
  }
}

}  // namespace strata
