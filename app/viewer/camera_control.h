// The interactive viewer's camera: mouse drags, the wheel and keys turn it about a target, move it
// toward it and slide it sideways, with 3D Slicer's conventions (vtkMRMLCameraWidget: left drag
// rotates, right drag and the wheel zoom, middle or shift+left drag pans). No window and no GPU:
// the viewer feeds it events and renders camera(). Animated moves (to a named position or an
// anatomical view) follow the camera paths' interpolation (camera_path.h).
//
// World space is DICOM's LPS+ patient space (docs/ARCHITECTURE.md, "Code map"): +x is the
// patient's left, +y posterior, +z superior. The loaders convert to it (NIfTI and RAS NRRD negate
// x and y; DICOM and MetaImage are LPS already), so "anterior" is -y, not Slicer's RAS +y.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "engine/scene/camera.h"
#include "engine/scene/fitted_camera.h"
#include "engine/scene/scene.h"
#include "labeling/camera_path.h"

namespace strata {

// Slicer's numbers (vtkMRMLCameraWidget: MotionFactor 10, delta = -20 / size per pixel).
// A drag across the whole viewport turns the camera this far: horizontally about its up axis
// (azimuth), vertically about its right axis (elevation).
inline constexpr double rotate_degrees_per_viewport = 200.0;
// One arrow-key press (vtkMRMLCameraNode::RotateAround).
inline constexpr double rotate_step_degrees = 15.0;
// One wheel tick moves the eye this factor nearer or farther (1.1^2: Slicer's 1.1^(0.2 *
// MotionFactor)). A right drag over the whole viewport height zooms by 1.1^20 (6.7 times).
inline constexpr double zoom_per_wheel_tick = 1.21;
inline constexpr double zoom_drag_exponent_per_viewport = 20.0;  // of 1.1

// The camera as an orbit: a target, the eye's distance from it and the camera's orientation.
// The lens (field of view, near, far) is always the scene camera's.
class CameraControl {
 public:
  // Orbits about the scene's content; starts (and resets) at `start`, the scene's camera unless
  // given.
  explicit CameraControl(const Scene& scene);
  CameraControl(const Scene& scene, const Camera& start);

  // The camera now: mid-animation, the animation's pose.
  const Camera& camera() const { return camera_; }
  glm::dvec3 target() const { return target_; }
  double distance() const { return distance_; }

  // Left drag by `pixels` (x right, y down) in a viewport of `viewport` pixels: the content
  // follows the mouse, turning about the target (a trackball: the camera's own axes, so it can
  // go over the top).
  void rotate(glm::vec2 pixels, glm::uvec2 viewport);
  // Arrow keys: `right` presses of the right arrow (negative: left) turn the camera to its right
  // about its up axis; `up` presses (negative: down) raise it about its right axis.
  void rotate_step(int right, int up);
  // The eye moves toward the target until it is `factor` times nearer (> 1) or farther (< 1);
  // never past the target, never closer than the near plane or farther than keeps the content
  // inside the far plane (unless it started there).
  void zoom(double factor);
  // Right drag: Slicer pulls the content closer as the mouse is pulled toward the user, so a drag
  // down (`pixels_down` > 0) zooms in.
  void zoom_drag(float pixels_down, glm::uvec2 viewport);
  // The wheel, in ticks as GLFW's scroll y offset gives them: Slicer zooms out as the wheel turns
  // away from the user (> 0), matching the right drag, and in toward the user.
  void zoom_wheel(double ticks);
  // Middle or shift+left drag: target and eye slide in the view plane so that the point under the
  // cursor at the target's depth stays under it.
  void pan(glm::vec2 pixels, glm::uvec2 viewport);

  // Back to the starting camera, exactly.
  void reset();
  // Puts the controller on `camera`'s pose (the lens stays the scene's). The new target is the
  // point of its viewing axis nearest the scene's centre, as camera paths derive it; the current
  // distance if the centre is behind the camera or nearer than the near plane.
  void set_camera(const Camera& camera);
  // The camera on `view`'s side of the scene's centre at the current distance.
  Camera view_from(AnatomicalView view) const;

  // Starts a move from the current camera to `goal` over `seconds` (> 0; otherwise it jumps),
  // eased as a two-position camera path. Any rotate, zoom, pan or set_camera ends it where it is.
  void animate_to(const Camera& goal, double seconds);
  // Advances the animation by `seconds`; at its end the controller is on the goal exactly.
  void update(double seconds);
  bool animating() const { return animation_.has_value(); }
  // The move animate_to started (the camera at time t is its at(t)), if one is running.
  const CameraPath* animation() const { return animation_ ? &*animation_ : nullptr; }

  // The current camera as a named position, for the scene's camera_positions.
  CameraPose pose(const std::string& name) const { return {name, camera_.view}; }

 private:
  void stop_animation();
  void place(const Camera& camera);  // set_camera without ending the animation
  void turn(double right_degrees, double up_degrees);
  void update_view();

  Camera start_;
  Camera camera_;
  glm::dvec3 centre_{0.0};
  double min_distance_ = 0.0;
  double max_distance_ = 0.0;
  glm::dvec3 target_{0.0};
  double distance_ = 1.0;
  glm::dquat orientation_{1.0, 0.0, 0.0, 0.0};  // camera to world
  std::optional<CameraPath> animation_;
  double animation_time_ = 0.0;
};

// The scene's position `index` (0-based, keys 1 to 9) with the scene's lens; none past the end.
std::optional<Camera> numbered_position(const Scene& scene, size_t index);

// A name for a new saved position that the scene does not have yet: view1, view2, ...
std::string new_position_name(const Scene& scene);

}  // namespace strata
