#include "engine/scene/scene_bounds.h"

namespace strata {

void Bounds::add(glm::vec3 point) {
  lo = glm::min(lo, point);
  hi = glm::max(hi, point);
}

Bounds scene_bounds(const Scene& scene) {
  Bounds bounds;
  for (const Volume& volume : scene.volumes) {
    if (volume.voxel_count() == 0) continue;
    const auto [lo, hi] = volume.world_bounds();
    bounds.add(lo);
    bounds.add(hi);
  }
  for (const Mesh& mesh : scene.meshes) {
    for (const glm::vec3& p : mesh.positions)
      bounds.add(glm::vec3(mesh.transform * glm::vec4(p, 1.0f)));
  }
  return bounds;
}

}  // namespace strata
