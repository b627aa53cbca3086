// Cameras made from the content when a scene has none: the six anatomical views, each at the
// distance where the content's box just fits the view. strata's world is the patient's LPS
// (docs/ARCHITECTURE.md, "Code map"), so each view is a world axis.
#pragma once

#include <array>
#include <optional>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "engine/scene/camera.h"
#include "engine/scene/scene.h"

namespace strata {

// The six buttons of Slicer's 3D view controller (ctkVTKRenderView::lookFromAxis): the camera
// on that side of the patient, looking at the content's centre. Front, back and the sides have
// the head up (+z); from above and below, the face (anterior, -y) is up.
enum class AnatomicalView { anterior, posterior, left, right, superior, inferior };

inline constexpr std::array<const char*, 6> kAnatomicalViewNames = {
    "anterior", "posterior", "left", "right", "superior", "inferior"};

const char* to_string(AnatomicalView view);
std::optional<AnatomicalView> anatomical_view_named(std::string_view name);

struct ViewSide {
  glm::dvec3 eye_direction;  // unit, from the centre towards the eye, in LPS
  glm::dvec3 up;
};
ViewSide side_of(AnatomicalView view);

// The scene's content seen from `view`, near enough that its bounding box fills the view's
// square (fov_y of `lens` both ways, 5% margin); near and far from `lens`.
glm::mat4 fitted_view(const Scene& scene, AnatomicalView view, float fov_y_degrees);

// The six views as named positions (kAnatomicalViewNames) for a lens of `fov_y_degrees`, and
// the near and far planes that hold the content from all of them.
struct AnatomicalPositions {
  std::vector<CameraPose> positions;
  float nearest = 0.0f, farthest = 0.0f;  // eye depths of the content's nearest and farthest point
};
AnatomicalPositions anatomical_positions(const Scene& scene, float fov_y_degrees);

// A lens and a view for a scene without a camera: anterior, or for flat content (one slice)
// the view facing it; near and far planes holding the content from all six views with room to
// zoom out; and the six views as named positions.
struct FittedCamera {
  Camera camera;
  std::vector<CameraPose> positions;
};
FittedCamera fitted_camera(const Scene& scene);

}  // namespace strata
