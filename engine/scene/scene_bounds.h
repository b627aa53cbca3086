// Where a scene's content lies in world space: the box around its volumes and meshes. Camera
// paths derive each pose's target from its centre, and turntables turn about it.
#pragma once

#include <limits>

#include <glm/glm.hpp>

#include "engine/scene/scene.h"

namespace strata {

struct Bounds {
  glm::vec3 lo{std::numeric_limits<float>::max()};
  glm::vec3 hi{-std::numeric_limits<float>::max()};

  bool empty() const { return lo.x > hi.x; }
  // The box's centre; the origin for an empty box, so an empty scene still has a pivot.
  glm::vec3 centre() const { return empty() ? glm::vec3(0.0f) : 0.5f * (lo + hi); }
  void add(glm::vec3 point);
};

// Every volume's world bounds (the box of its voxel centres) and every mesh vertex after the
// mesh's transform. Labels are left out: they annotate the content and never widen it.
Bounds scene_bounds(const Scene& scene);

// The same with each volume's box cut by its cut-aways (crop box, clipping planes): the box around
// what they keep. A volume they cut away whole adds nothing.
Bounds kept_bounds(const Scene& scene);

}  // namespace strata
