// The one camera: a pose (the view matrix) and a perspective lens. The renderer, the layering and
// the anchor projection all take it, so a point lands on the same pixel and depth everywhere; the
// camera paths and the viewer interpolate and orbit its pose.
#pragma once

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

// A named pose of the scene's camera ("--camera NAME"); the lens stays the scene's.
struct CameraPose {
  std::string name;
  glm::mat4 view{1.0f};
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
