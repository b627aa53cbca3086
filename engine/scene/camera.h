// The one camera: a pose (the view matrix) and a perspective lens. The renderer, the layering and
// the anchor projection all take it, so a point lands on the same pixel and depth everywhere; the
// camera paths and the viewer interpolate and orbit its pose.
#pragma once

#include <optional>
#include <string>

#include <glm/glm.hpp>

namespace strata {

struct Camera {
  glm::mat4 view{1.0f};  // world to eye space (right-handed, looking down -z)
  float fov_y_degrees = 45.0f;
  float near_plane = 0.1f;
  float far_plane = 100.0f;

  // Eye to Vulkan's clip space for an image of `aspect` (width / height): y points down and depth
  // runs from 0 at the near plane to 1 at the far plane.
  glm::mat4 projection(float aspect) const;
  // The eye's position in world space.
  glm::vec3 eye() const;
};

// Why a lens makes no meaningful picture, naming its field ("fov_y", "near", "far"): a field of
// view outside 0.1..179 degrees, near not > 0, far not > near, far past 1e9 mm, or far / near
// past 1e6, where the float projection loses its far plane (value_limits.h). Nothing when fine.
struct LensProblem {
  const char* field;
  std::string reason;
};
std::optional<LensProblem> lens_problem(const Camera& camera);

// A named pose of the scene's camera ("--camera NAME"); the lens stays the scene's.
struct CameraPose {
  std::string name;
  glm::mat4 view{1.0f};
  bool fitted = false;  // a standard view complete_scene fitted (fitted_camera.h), not the file's
};

// Where a world point lands in an image of `size` pixels: its pixel position (x right, y down,
// pixel centres at +0.5) and eye depth; visible when it is between the near and far planes and
// inside the image.
struct ProjectedPoint {
  glm::vec2 pixel{0.0f};
  float eye_depth = 0.0f;
  bool visible = false;
};

ProjectedPoint project(const Camera& camera, glm::vec3 world, glm::uvec2 size);

}  // namespace strata
