#include "app/viewer/camera_control.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/scene/scene_bounds.h"

namespace strata {
namespace {

// The scene camera's lens on `pose`'s view.
Camera with_lens(const Camera& pose, const Camera& lens) {
  Camera camera = lens;
  camera.view = pose.view;
  return camera;
}

// World units per pixel at `distance` from the eye, for a viewport `height` pixels high.
double units_per_pixel(const Camera& lens, double distance, double height) {
  return 2.0 * distance * std::tan(glm::radians(double(lens.fov_y_degrees)) / 2.0) / height;
}

}  // namespace

CameraControl::CameraControl(const Scene& scene) : CameraControl(scene, scene.camera) {}

CameraControl::CameraControl(const Scene& scene, const Camera& start)
    : start_(with_lens(start, scene.camera)), camera_(start_) {
  const Bounds bounds = scene_bounds(scene);
  centre_ = glm::dvec3(bounds.centre());
  const double near = std::max(double(start_.near_plane), 1e-6);
  const double half_fov = glm::radians(double(start_.fov_y_degrees)) / 2.0;
  const double radius = bounds.empty() ? 0.0 : 0.5 * glm::length(glm::dvec3(bounds.hi - bounds.lo));
  // Slicer's reset distance: the content's sphere fills the view. Also the distance a camera gets
  // when the centre is behind it.
  distance_ = std::max(radius / std::sin(half_fov), 2.0 * near);
  min_distance_ = near;
  max_distance_ = std::max(double(start_.far_plane) - radius, min_distance_);
  set_camera(start_);
}

void CameraControl::rotate(glm::vec2 pixels, glm::uvec2 viewport) {
  if (viewport.x == 0 || viewport.y == 0) return;
  // vtkMRMLCameraWidget::ProcessRotate: Azimuth(-200 dx / width), Elevation(-200 dy / height)
  // with y up; azimuth > 0 moves the camera to its right, elevation > 0 raises it.
  turn(-rotate_degrees_per_viewport * double(pixels.x) / double(viewport.x),
       rotate_degrees_per_viewport * double(pixels.y) / double(viewport.y));
}

void CameraControl::rotate_step(int right, int up) {
  turn(rotate_step_degrees * right, rotate_step_degrees * up);
}

void CameraControl::turn(double right_degrees, double up_degrees) {
  stop_animation();
  // About the camera's own up, then its (new) right axis: the eye, at +z in camera space,
  // swings toward +x and +y.
  orientation_ = orientation_ * glm::angleAxis(glm::radians(right_degrees), glm::dvec3(0, 1, 0));
  orientation_ = orientation_ * glm::angleAxis(glm::radians(-up_degrees), glm::dvec3(1, 0, 0));
  orientation_ = glm::normalize(orientation_);
  update_view();
}

void CameraControl::zoom(double factor) {
  if (!(std::isfinite(factor) && factor > 0.0)) return;
  stop_animation();
  const double wanted = distance_ / factor;
  // Clamp only in the direction of the move, so a camera outside the range never jumps.
  distance_ = factor > 1.0 ? std::max(wanted, std::min(min_distance_, distance_))
                           : std::min(wanted, std::max(max_distance_, distance_));
  update_view();
}

void CameraControl::zoom_drag(float pixels_down, glm::uvec2 viewport) {
  if (viewport.y == 0) return;
  // vtkMRMLCameraWidget::ProcessScale: Dolly(1.1^(-10 dy / (height / 2))) with y up.
  zoom(std::pow(1.1, zoom_drag_exponent_per_viewport * double(pixels_down) / double(viewport.y)));
}

void CameraControl::zoom_wheel(double ticks) {
  zoom(std::pow(zoom_per_wheel_tick, -ticks));
}

void CameraControl::pan(glm::vec2 pixels, glm::uvec2 viewport) {
  if (viewport.y == 0) return;
  stop_animation();
  const double scale = units_per_pixel(camera_, distance_, double(viewport.y));
  const glm::dvec3 right = orientation_ * glm::dvec3(1, 0, 0);
  const glm::dvec3 up = orientation_ * glm::dvec3(0, 1, 0);
  // The content moves with the mouse, so the camera moves the other way (pixel y is down).
  target_ += scale * (-double(pixels.x) * right + double(pixels.y) * up);
  update_view();
}

void CameraControl::reset() {
  set_camera(start_);
}

void CameraControl::set_camera(const Camera& camera) {
  stop_animation();
  place(camera);
}

void CameraControl::place(const Camera& camera) {
  camera_ = with_lens(camera, start_);
  const glm::dmat4 view(camera_.view);
  const glm::dmat3 to_world = glm::transpose(glm::dmat3(view));
  const glm::dvec3 eye = -(to_world * glm::dvec3(view[3]));
  const glm::dvec3 forward = -to_world[2];
  orientation_ = glm::normalize(glm::quat_cast(to_world));
  const double along = glm::dot(centre_ - eye, forward);
  if (along > min_distance_) distance_ = along;
  target_ = eye + forward * distance_;
}

Camera CameraControl::view_from(AnatomicalView view) const {
  const ViewSide side = side_of(view);
  Camera camera = start_;
  camera.view = glm::mat4(glm::lookAt(centre_ + side.eye_direction * distance_, centre_, side.up));
  return camera;
}

void CameraControl::animate_to(const Camera& goal, double seconds) {
  const Camera end = with_lens(goal, start_);
  if (!(std::isfinite(seconds) && seconds > 0.0)) {
    set_camera(end);
    return;
  }
  CameraPath path;
  path.centre = glm::vec3(centre_);
  path.keys = {{camera_, 0.0}, {end, seconds}};
  stop_animation();
  animation_ = std::move(path);
  animation_time_ = 0.0;
}

void CameraControl::update(double seconds) {
  if (!animation_) return;
  animation_time_ = std::min(animation_time_ + std::max(seconds, 0.0), animation_->duration());
  // The orbit follows the move, so input mid-move goes on from where the camera is.
  place(animation_->at(animation_time_));  // exactly the goal at the end
  if (animation_time_ >= animation_->duration()) stop_animation();
}

void CameraControl::stop_animation() {
  animation_.reset();
}

// As camera_path.cpp's view_matrix: the eye at `distance_` behind the target along the view axis.
void CameraControl::update_view() {
  const glm::dmat3 to_world = glm::mat3_cast(orientation_);
  const glm::dvec3 eye = target_ + to_world[2] * distance_;
  const glm::dmat3 to_eye = glm::transpose(to_world);
  glm::dmat4 view(to_eye);
  view[3] = glm::dvec4(-(to_eye * eye), 1.0);
  camera_.view = glm::mat4(view);
}

std::optional<Camera> numbered_position(const Scene& scene, size_t index) {
  if (index >= scene.camera_positions.size()) return std::nullopt;
  Camera camera = scene.camera;
  camera.view = scene.camera_positions[index].view;
  return camera;
}

std::string new_position_name(const Scene& scene) {
  for (int n = 1;; ++n) {
    const std::string name = "view" + std::to_string(n);
    const bool taken = std::any_of(scene.camera_positions.begin(), scene.camera_positions.end(),
                                   [&](const CameraPose& pose) { return pose.name == name; });
    if (!taken) return name;
  }
}

}  // namespace strata
