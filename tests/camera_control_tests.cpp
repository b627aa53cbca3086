// The viewer's camera control: Slicer's drags, wheel and keys, anatomical views in LPS, animated
// moves along the camera paths' interpolation, and saving a position into the scene file.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/scene/io/scene_loader.h"
#include "engine/scene/scene_bounds.h"
#include "app/viewer/camera_control.h"
#include "test_scenes.h"

namespace strata {
namespace {

const glm::uvec2 viewport{640, 480};

// test::box_scene(), seen obliquely from the front left and above.
Scene box_scene() {
  Scene scene = test::box_scene();
  scene.camera_positions = {
      {"front", glm::lookAt(glm::vec3(10, -80, 30), glm::vec3(10, 20, 30), glm::vec3(0, 0, 1))}};
  return scene;
}

const glm::dvec3 box_centre{10, 20, 30};

// Loaded once: the volume and atlas take a moment.
const Scene& head_scene() {
  static const Scene scene = load_scene(STRATA_SOURCE_DIR "/assets/scenes/head.json");
  return scene;
}

glm::dvec3 eye_of(const Camera& camera) {
  return glm::dvec3(glm::inverse(glm::dmat4(camera.view))[3]);
}

// Camera to world: columns right, up, back.
glm::dmat3 orientation_of(const Camera& camera) {
  return glm::transpose(glm::dmat3(glm::dmat4(camera.view)));
}

float max_difference(const glm::mat4& a, const glm::mat4& b) {
  float most = 0.0f;
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) most = std::max(most, std::abs(a[c][r] - b[c][r]));
  }
  return most;
}

// The signed angle from a to b about `axis`, in degrees.
double degrees_about(glm::dvec3 a, glm::dvec3 b, glm::dvec3 axis) {
  a -= axis * glm::dot(a, axis);
  b -= axis * glm::dot(b, axis);
  return glm::degrees(std::atan2(glm::dot(glm::cross(a, b), axis), glm::dot(a, b)));
}

glm::vec2 pixel_of(const Camera& camera, glm::dvec3 point) {
  return project(camera, glm::vec3(point), viewport).pixel;
}

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("camera_control_starts_on_the_scene_camera_aimed_at_the_content") {
    const Scene scene = box_scene();
    const CameraControl control(scene);
    CHECK(control.camera().view == scene.camera.view);
    CHECK(control.camera().fov_y_degrees == 30.0f);
    CHECK(glm::length(control.target() - box_centre) < 1e-4);
    CHECK(control.distance() == doctest::Approx(glm::length(eye_of(scene.camera) - box_centre)));
    CHECK(!control.animating());
  }

  TEST_CASE("camera_control_rotate_keeps_the_target_and_the_distance") {
    CameraControl control(box_scene());
    const glm::dvec3 target = control.target();
    const double distance = control.distance();
    for (int i = 0; i < 50; ++i) control.rotate({37.0f, -21.0f}, viewport);
    CHECK(glm::length(control.target() - target) < 1e-9);
    CHECK(glm::length(eye_of(control.camera()) - target) ==
          doctest::Approx(distance).epsilon(1e-5));
    // Still a rotation: orthonormal, no drift after many small turns.
    const glm::dmat3 o = orientation_of(control.camera());
    const glm::dmat3 identity = glm::transpose(o) * o;
    for (int c = 0; c < 3; ++c) {
      for (int r = 0; r < 3; ++r)
        CHECK(identity[c][r] == doctest::Approx(c == r ? 1.0 : 0.0).epsilon(1e-5));
    }
  }

  TEST_CASE("camera_control_drag_across_the_viewport_turns_200_degrees_at_any_size") {
    for (const glm::uvec2 size : {glm::uvec2(640, 480), glm::uvec2(1920, 1080)}) {
      CAPTURE(size.x);
      CameraControl control(box_scene());
      const glm::dvec3 up = orientation_of(control.camera())[1];
      const glm::dvec3 before = eye_of(control.camera()) - control.target();
      // A quarter of the width to the right: the content turns right, so the eye swings 50
      // degrees to the camera's left (negative about its up).
      control.rotate({float(size.x) / 4.0f, 0.0f}, size);
      CHECK(degrees_about(before, eye_of(control.camera()) - control.target(), up) ==
            doctest::Approx(-50.0).epsilon(1e-4));
      CHECK(glm::length(orientation_of(control.camera())[1] - up) < 1e-5);  // a pure azimuth
      control.rotate({float(size.x) * 3.0f / 4.0f, 0.0f}, size);
      // 200 degrees to the left in all is 160 to the right.
      CHECK(degrees_about(before, eye_of(control.camera()) - control.target(), up) ==
            doctest::Approx(160.0).epsilon(1e-4));
    }
  }

  TEST_CASE("camera_control_content_follows_the_mouse_when_rotating") {
    CameraControl control(box_scene());
    // A point between the target and the eye: the surface facing the camera.
    const glm::dvec3 front = control.target() + 0.5 * (eye_of(control.camera()) - control.target());
    const glm::vec2 start = pixel_of(control.camera(), front);
    control.rotate({10.0f, 0.0f}, viewport);
    CHECK(pixel_of(control.camera(), front).x > start.x + 1.0f);
    control.rotate({-10.0f, 0.0f}, viewport);
    control.rotate({0.0f, 10.0f}, viewport);  // down
    CHECK(pixel_of(control.camera(), front).y > start.y + 1.0f);
  }

  TEST_CASE("camera_control_arrow_keys_turn_15_degrees_a_press") {
    CameraControl control(box_scene());
    const glm::dmat3 o = orientation_of(control.camera());
    const glm::dvec3 before = eye_of(control.camera()) - control.target();
    control.rotate_step(2, 0);  // right arrow twice: the camera moves to its right
    CHECK(degrees_about(before, eye_of(control.camera()) - control.target(), o[1]) ==
          doctest::Approx(30.0).epsilon(1e-4));
    control.rotate_step(-2, 0);
    control.rotate_step(0, 1);  // up arrow: the camera rises over its right axis
    CHECK(degrees_about(before, eye_of(control.camera()) - control.target(), -o[0]) ==
          doctest::Approx(15.0).epsilon(1e-4));
    CHECK(glm::dot(eye_of(control.camera()) - control.target(), o[1]) > 0.0);
  }

  TEST_CASE("camera_control_zoom_divides_the_distance_and_never_passes_the_target") {
    const Scene scene = box_scene();
    CameraControl control(scene);
    const glm::dvec3 target = control.target();
    const double start = control.distance();
    const glm::dvec3 forward = -orientation_of(control.camera())[2];
    control.zoom(2.0);
    CHECK(control.distance() == doctest::Approx(start / 2.0));
    CHECK(glm::length(eye_of(control.camera()) - (target - forward * start / 2.0)) < 1e-3);
    control.zoom(0.5);
    CHECK(control.distance() == doctest::Approx(start));

    // Slicer's wheel: away from the user zooms out by 1.21 a tick, toward the user zooms in.
    control.zoom_wheel(1.0);
    CHECK(control.distance() == doctest::Approx(start * 1.21));
    control.zoom_wheel(-1.0);
    CHECK(control.distance() == doctest::Approx(start));
    // Slicer's right drag: pulling the mouse down by half the height zooms in by 1.1^10.
    control.zoom_drag(240.0f, viewport);
    CHECK(control.distance() == doctest::Approx(start / std::pow(1.1, 10.0)));
    control.zoom_drag(-240.0f, viewport);
    CHECK(control.distance() == doctest::Approx(start));

    control.zoom(1e9);
    CHECK(control.distance() == doctest::Approx(scene.camera.near_plane));
    CHECK(glm::dot(target - eye_of(control.camera()), forward) > 0.0);  // still in front
    CHECK(glm::length(control.target() - target) < 1e-9);
    control.zoom(1e-9);
    // Far enough that the content's sphere just stays inside the far plane.
    const Bounds bounds = scene_bounds(scene);
    const double radius = 0.5 * glm::length(glm::dvec3(bounds.hi - bounds.lo));
    CHECK(control.distance() == doctest::Approx(scene.camera.far_plane - radius));
    control.zoom(0.0);  // ignored, as are NaN and negative factors
    control.zoom(std::nan(""));
    control.zoom(-2.0);
    CHECK(control.distance() == doctest::Approx(scene.camera.far_plane - radius));
  }

  TEST_CASE("camera_control_pan_keeps_the_point_at_the_target_depth_under_the_cursor") {
    CameraControl control(box_scene());
    control.rotate({23.0f, 41.0f}, viewport);
    const glm::dvec3 target = control.target();
    const double distance = control.distance();
    const glm::vec2 before = pixel_of(control.camera(), target);
    CHECK(glm::length(before - glm::vec2(viewport) / 2.0f) < 0.01f);
    for (const glm::vec2 delta : {glm::vec2(37.0f, -12.0f), glm::vec2(-120.5f, 80.25f)}) {
      const glm::vec2 from = pixel_of(control.camera(), target);
      control.pan(delta, viewport);
      CHECK(glm::length(pixel_of(control.camera(), target) - (from + delta)) < 0.01f);
    }
    CHECK(control.distance() == distance);
    // The new target is at the image's centre again; the view direction is unchanged.
    CHECK(glm::length(pixel_of(control.camera(), control.target()) - glm::vec2(viewport) / 2.0f) <
          0.01f);
  }

  TEST_CASE("camera_control_anatomical_views_are_the_patients_sides_in_lps") {
    const Scene scene = box_scene();
    CameraControl control(scene);
    control.zoom(1.5);
    const double distance = control.distance();
    const glm::dvec3 c = box_centre;
    // LPS: +x the patient's left, +y posterior, +z superior.
    const glm::dvec3 left(10, 0, 0), posterior(0, 10, 0), superior(0, 0, 10);
    auto depth = [](const Camera& camera, glm::dvec3 p) {
      return project(camera, glm::vec3(p), viewport).eye_depth;
    };
    struct Expected {
      AnatomicalView view;
      glm::dvec3 eye_direction;
      glm::dvec3 image_up;  // a point that way from the centre is above it in the image
    };
    const Expected expected[] = {
        {AnatomicalView::anterior, {0, -1, 0}, superior},
        {AnatomicalView::posterior, {0, 1, 0}, superior},
        {AnatomicalView::left, {1, 0, 0}, superior},
        {AnatomicalView::right, {-1, 0, 0}, superior},
        {AnatomicalView::superior, {0, 0, 1}, -posterior},  // the face up
        {AnatomicalView::inferior, {0, 0, -1}, -posterior},
    };
    for (const Expected& e : expected) {
      CAPTURE(int(e.view));
      const Camera camera = control.view_from(e.view);
      CHECK(glm::length(eye_of(camera) - (c + e.eye_direction * distance)) < 1e-3);
      CHECK(glm::length(pixel_of(camera, c) - glm::vec2(viewport) / 2.0f) < 0.01f);
      CHECK(pixel_of(camera, c + e.image_up).y < pixel_of(camera, c).y - 1.0f);
      CHECK(std::abs(pixel_of(camera, c + e.image_up).x - pixel_of(camera, c).x) < 0.01f);
      CHECK(camera.fov_y_degrees == scene.camera.fov_y_degrees);
    }
    // The side a view is named after is nearer the camera than the opposite one.
    const Camera anterior = control.view_from(AnatomicalView::anterior);
    CHECK(depth(anterior, c - posterior) < depth(anterior, c + posterior));
    const Camera from_left = control.view_from(AnatomicalView::left);
    CHECK(depth(from_left, c + left) < depth(from_left, c - left));
    const Camera from_right = control.view_from(AnatomicalView::right);
    CHECK(depth(from_right, c - left) < depth(from_right, c + left));
    // Seen from the front, the patient's left is on the image's right.
    CHECK(pixel_of(anterior, c + left).x > pixel_of(anterior, c).x + 1.0f);
  }

  TEST_CASE("camera_control_anatomical_views_match_the_head_scenes_named_positions") {
    const Scene& scene = head_scene();
    const CameraControl control(scene);
    for (const auto& [name, view] :
         {std::pair{"front", AnatomicalView::anterior}, std::pair{"left", AnatomicalView::left},
          std::pair{"top", AnatomicalView::superior}}) {
      const std::string position = name;
      CAPTURE(position);
      const glm::dmat3 want = orientation_of(camera_for(scene, position));
      const glm::dmat3 got = orientation_of(control.view_from(view));
      for (int c = 0; c < 3; ++c) CHECK(glm::length(got[c] - want[c]) < 1e-5);
    }
  }

  TEST_CASE("camera_control_reset_returns_the_exact_starting_view") {
    const Scene scene = box_scene();
    const Camera start = *numbered_position(scene, 0);
    CameraControl control(scene, start);
    CHECK(control.camera().view == start.view);
    control.rotate({100.0f, 50.0f}, viewport);
    control.zoom(1.7);
    control.pan({30.0f, 12.0f}, viewport);
    control.animate_to(control.view_from(AnatomicalView::superior), 1.0);
    control.update(0.3);
    control.reset();
    CHECK(!control.animating());
    CHECK(control.camera().view == start.view);
    CHECK(control.camera().near_plane == scene.camera.near_plane);
    CHECK(control.camera().far_plane == scene.camera.far_plane);
  }

  TEST_CASE("camera_control_animation_follows_the_camera_path_and_ends_on_the_goal") {
    const Scene scene = box_scene();
    CameraControl control(scene);
    const Camera goal = control.view_from(AnatomicalView::left);
    control.animate_to(goal, 2.0);
    REQUIRE(control.animating());
    CameraPath path;
    path.centre = scene_bounds(scene).centre();
    path.keys = {{scene.camera, 0.0}, {goal, 2.0}};
    control.update(1.0);
    CHECK(control.animating());
    CHECK(max_difference(control.camera().view, path.at(1.0).view) < 1e-6f);
    control.update(0.5);
    CHECK(max_difference(control.camera().view, path.at(1.5).view) < 1e-6f);
    control.update(0.75);  // past the end
    CHECK(!control.animating());
    CHECK(control.camera().view == goal.view);
    control.update(1.0);
    CHECK(control.camera().view == goal.view);
    // A move of no duration jumps.
    control.animate_to(scene.camera, 0.0);
    CHECK(!control.animating());
    CHECK(control.camera().view == scene.camera.view);
  }

  TEST_CASE("camera_control_input_interrupts_an_animation_where_it_is") {
    const Scene scene = box_scene();
    CameraControl control(scene);
    control.animate_to(control.view_from(AnatomicalView::superior), 1.0);
    control.update(0.4);
    const Camera now = control.camera();
    control.pan({0.0f, 0.0f}, viewport);
    CHECK(!control.animating());
    CHECK(max_difference(control.camera().view, now.view) < 1e-4f);
    control.update(1.0);
    CHECK(max_difference(control.camera().view, now.view) < 1e-4f);
    // Rotating goes on from the interrupted pose, about its target.
    control.animate_to(control.view_from(AnatomicalView::posterior), 1.0);
    control.update(0.5);
    const glm::dvec3 target = control.target();
    const double distance = control.distance();
    control.rotate({5.0f, 0.0f}, viewport);
    CHECK(!control.animating());
    CHECK(glm::length(control.target() - target) < 1e-9);
    CHECK(control.distance() == distance);
  }

  TEST_CASE("camera_control_set_camera_orbits_about_the_centre_on_its_axis") {
    CameraControl control(box_scene());
    const Camera front = *numbered_position(box_scene(), 0);
    control.set_camera(front);
    CHECK(control.camera().view == front.view);
    CHECK(glm::length(control.target() - box_centre) < 1e-4);
    CHECK(control.distance() == doctest::Approx(100.0));
    // A camera facing away from the centre keeps the distance it had.
    control.set_camera(
        {glm::lookAt(glm::vec3(10, -80, 30), glm::vec3(10, -180, 30), glm::vec3(0, 0, 1))});
    CHECK(control.distance() == doctest::Approx(100.0));
    CHECK(glm::length(control.target() - glm::dvec3(10, -180, 30)) < 1e-3);
  }

  TEST_CASE("camera_control_saved_position_reads_back_from_the_scene_file") {
    const std::filesystem::path folder =
        std::filesystem::path(STRATA_TEST_OUTPUT) / "camera_control_tests";
    std::filesystem::create_directories(folder);
    Scene scene = box_scene();
    scene.has_camera = true;  // its own camera, written back (a fitted one is not)
    CameraControl control(scene);
    control.rotate({123.0f, -45.0f}, viewport);
    control.zoom_wheel(-2.0);
    CHECK(new_position_name(scene) == "view1");
    scene.camera_positions.push_back(control.pose(new_position_name(scene)));
    CHECK(new_position_name(scene) == "view2");
    const std::filesystem::path path = folder / "saved.json";
    save_scene_json(path, scene);
    const Scene back = load_scene_json(path);
    REQUIRE(back.camera_positions.size() == 2);
    CHECK(back.camera_positions[1].name == "view1");
    CHECK(back.camera_positions[1].view == control.camera().view);
    CHECK(back.camera.view == scene.camera.view);
    const std::optional<Camera> saved = numbered_position(back, 1);
    REQUIRE(saved);
    CHECK(saved->view == control.camera().view);
    CHECK(saved->fov_y_degrees == scene.camera.fov_y_degrees);
    CHECK(!numbered_position(back, 2));
  }
}

}  // namespace strata
