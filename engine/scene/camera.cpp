#include "engine/scene/camera.h"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/scene/value_limits.h"

namespace strata {

glm::mat4 Camera::projection(float aspect) const {
  glm::mat4 p = glm::perspectiveRH_ZO(glm::radians(fov_y_degrees), aspect, near_plane, far_plane);
  p[1][1] *= -1.0f;  // Vulkan's clip space has y down
  return p;
}

glm::vec3 Camera::eye() const {
  return glm::vec3(glm::inverse(view)[3]);
}

std::optional<LensProblem> lens_problem(const Camera& camera) {
  using namespace value_limits;
  const double fov = camera.fov_y_degrees, near = camera.near_plane, far = camera.far_plane;
  if (!(fov >= kMinFovDegrees && fov <= kMaxFovDegrees))
    return LensProblem{"fov_y", "expected degrees from " + shown(kMinFovDegrees) + " to " +
                                    shown(kMaxFovDegrees) + ", got " + shown(fov)};
  if (!(near > 0.0)) return LensProblem{"near", "expected a number > 0"};
  if (!(far > near)) return LensProblem{"far", "expected a number > near"};
  if (!(far <= kMaxFarMm))
    return LensProblem{"far", "far plane " + shown(far) + " mm is past " + shown(kMaxFarMm)};
  if (!(far / near <= kMaxFarNearRatio))
    return LensProblem{"far", "far / near = " + shown(far) + " / " + shown(near) + " = " +
                                  shown(far / near) + ", more than " + shown(kMaxFarNearRatio) +
                                  ": the depth range is too deep for a float projection "
                                  "(raise near or lower far)"};
  return std::nullopt;
}

ProjectedPoint project(const Camera& camera, glm::vec3 world, glm::uvec2 size) {
  ProjectedPoint out;
  const glm::vec4 eye = camera.view * glm::vec4(world, 1.0f);
  out.eye_depth = -eye.z;
  if (!(out.eye_depth > camera.near_plane && out.eye_depth < camera.far_plane)) return out;
  const glm::vec4 clip = camera.projection(float(size.x) / float(size.y)) * eye;
  const glm::vec2 ndc = glm::vec2(clip) / clip.w;
  out.pixel = (ndc * 0.5f + 0.5f) * glm::vec2(size);
  out.visible = out.pixel.x >= 0.0f && out.pixel.y >= 0.0f && out.pixel.x < float(size.x) &&
                out.pixel.y < float(size.y);
  return out;
}

}  // namespace strata
