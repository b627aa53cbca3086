// Cameras made from the content when a scene has none: the six anatomical views and the eight
// oblique ones between them, each at the distance where the content's box just fits the view.
// strata's world is the patient's LPS (docs/ARCHITECTURE.md, "Code map"), so each anatomical view
// is a world axis.
#pragma once

#include <array>
#include <optional>
#include <string>
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

// The standard views every scene has as named positions: the six anatomical ones (in
// kAnatomicalViewNames' order), then the eight three-quarter views between a front or back, a
// side and the top or bottom, named in that order ("anterior-right-superior"): 45 degrees round
// from the front or back, 30 degrees above or below, the head up.
struct StandardView {
  std::string name;
  ViewSide side;
};
const std::vector<StandardView>& standard_views();

// `oblique` is the three-quarter view from the front, the patient's right and above (as the demo
// scene's own `oblique`).
inline constexpr const char* kObliqueViewName = "anterior-right-superior";

// The standard view `name` means, by its name or another: front, back, top, bottom, oblique, an
// oblique view's three words in any order or their initials (`ars`, `ras`). nullopt for a name
// that is none of these.
std::optional<std::string> standard_view_name(std::string_view name);

// The scene's content seen from `view`, near enough that its bounding box fills the view's
// square (fov_y of `lens` both ways, 5% margin); near and far from `lens`.
glm::mat4 fitted_view(const Scene& scene, AnatomicalView view, float fov_y_degrees);

// What the fitted views fit: the whole content, or what the volumes' cut-aways (crop boxes,
// clipping planes) keep of it (kept_bounds in scene_bounds.h).
enum class FitTo { content, kept };

// The standard views as named positions (marked fitted) for a lens of `fov_y_degrees`, and the
// near and far planes that hold the whole content from all of them.
struct AnatomicalPositions {
  std::vector<CameraPose> positions;
  float nearest = 0.0f, farthest = 0.0f;  // eye depths of the content's nearest and farthest point
};
AnatomicalPositions anatomical_positions(const Scene& scene, float fov_y_degrees,
                                         FitTo fit = FitTo::content);

// A lens and a view for a scene without a camera: anterior, or for flat content (one slice)
// the view facing it; near and far planes holding the content from all the standard views with
// room to zoom out; and the standard views as named positions.
struct FittedCamera {
  Camera camera;
  std::vector<CameraPose> positions;
};
FittedCamera fitted_camera(const Scene& scene, FitTo fit = FitTo::content);

// `view` moved along its own axis and sideways, its orientation kept, until it looks at the
// centre of what `fit` takes of the content from the distance where that box fills the view: a
// scene's own camera or position fitted again to a crop.
glm::mat4 refitted_view(const Scene& scene, const glm::mat4& view, float fov_y_degrees, FitTo fit);

}  // namespace strata
