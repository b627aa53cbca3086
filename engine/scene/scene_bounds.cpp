#include "engine/scene/scene_bounds.h"

#include <cmath>

namespace strata {
namespace {

// The planes (n, w), n.p + w >= 0 inside, of a volume's box of voxel centres and its cut-aways.
std::vector<glm::dvec4> kept_planes(const Volume& volume) {
  const glm::dmat4 to_index = glm::inverse(glm::dmat4(volume.index_to_world()));
  std::vector<glm::dvec4> planes;
  for (int axis = 0; axis < 3; ++axis) {
    const glm::dvec4 row(to_index[0][axis], to_index[1][axis], to_index[2][axis],
                         to_index[3][axis]);  // index coordinate `axis` of a world point
    planes.push_back(row);
    planes.push_back(glm::dvec4(0, 0, 0, double(volume.dims[axis]) - 1.0) - row);
  }
  for (const glm::vec4& cut : volume.cut) planes.push_back(glm::dvec4(cut));
  return planes;
}

// The corners of the convex region the planes keep: each point where three planes meet that no
// plane cuts away (a few hundred triples at most: kMaxCutPlanes + 6 planes).
void add_corners(const std::vector<glm::dvec4>& planes, Bounds& bounds) {
  const size_t n = planes.size();
  for (size_t a = 0; a < n; ++a) {
    for (size_t b = a + 1; b < n; ++b) {
      for (size_t c = b + 1; c < n; ++c) {
        const glm::dmat3 m = glm::transpose(
            glm::dmat3(glm::dvec3(planes[a]), glm::dvec3(planes[b]), glm::dvec3(planes[c])));
        if (std::abs(glm::determinant(m)) < 1e-12) continue;
        const glm::dvec3 p = glm::inverse(m) * -glm::dvec3(planes[a].w, planes[b].w, planes[c].w);
        const double slack = 1e-6 * (1.0 + glm::length(p));
        bool inside = true;
        for (const glm::dvec4& plane : planes)
          inside = inside && glm::dot(glm::dvec3(plane), p) + plane.w >= -slack;
        if (inside) bounds.add(glm::vec3(p));
      }
    }
  }
}

// The content's box, each volume's cut by its cut-aways where `cut`.
Bounds content_box(const Scene& scene, bool cut) {
  Bounds bounds;
  for (const Volume& volume : scene.volumes) {
    if (volume.voxel_count() == 0) continue;
    if (cut && !volume.cut.empty()) {
      add_corners(kept_planes(volume), bounds);
      continue;
    }
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

}  // namespace

void Bounds::add(glm::vec3 point) {
  lo = glm::min(lo, point);
  hi = glm::max(hi, point);
}

Bounds scene_bounds(const Scene& scene) {
  return content_box(scene, false);
}

Bounds kept_bounds(const Scene& scene) {
  return content_box(scene, true);
}

}  // namespace strata
