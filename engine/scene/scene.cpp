#include "engine/scene/scene.h"

#include <algorithm>
#include <cstring>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/core/error.h"
#include "engine/scene/fitted_camera.h"

namespace strata {

const char* to_string(VoxelType type) {
  switch (type) {
    case VoxelType::uint8:
      return "uint8";
    case VoxelType::int16:
      return "int16";
    case VoxelType::uint16:
      return "uint16";
    case VoxelType::float32:
      return "float32";
  }
  return "?";
}

size_t voxel_size(VoxelType type) {
  switch (type) {
    case VoxelType::uint8:
      return 1;
    case VoxelType::int16:
    case VoxelType::uint16:
      return 2;
    case VoxelType::float32:
      return 4;
  }
  return 0;
}

glm::mat4 Volume::index_to_patient() const {
  glm::mat4 m(1.0f);
  for (int axis = 0; axis < 3; ++axis) m[axis] = glm::vec4(direction[axis] * spacing[axis], 0.0f);
  m[3] = glm::vec4(origin, 1.0f);
  return m;
}

std::pair<glm::vec3, glm::vec3> Volume::world_bounds() const {
  const glm::mat4 m = index_to_world();
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 ijk((corner & 1) ? float(dims.x - 1) : 0.0f,
                        (corner & 2) ? float(dims.y - 1) : 0.0f,
                        (corner & 4) ? float(dims.z - 1) : 0.0f);
    const glm::vec3 p = glm::vec3(m * glm::vec4(ijk, 1.0f));
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  return {lo, hi};
}

float Volume::value(uint32_t i, uint32_t j, uint32_t k) const {
  const size_t index = (size_t{k} * dims.y + j) * dims.x + i;
  const std::byte* p = voxels.data() + index * voxel_size(type);
  switch (type) {
    case VoxelType::uint8:
      return static_cast<float>(std::to_integer<uint8_t>(*p));
    case VoxelType::int16: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    case VoxelType::uint16: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    case VoxelType::float32: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
  return 0.0f;
}

glm::vec4 TransferFunction::sample(float t) const {
  if (stops.empty()) return glm::vec4(0.0f);
  if (t <= stops.front().position) return stops.front().color;
  if (t >= stops.back().position) return stops.back().color;
  const auto upper = std::upper_bound(stops.begin(), stops.end(), t,
                                      [](float v, const Stop& s) { return v < s.position; });
  const Stop& b = *upper;
  const Stop& a = *(upper - 1);
  const float span = b.position - a.position;
  return span > 0.0f ? glm::mix(a.color, b.color, (t - a.position) / span) : b.color;
}

std::vector<glm::vec4> crop_planes(glm::vec3 lo, glm::vec3 hi) {
  std::vector<glm::vec4> planes;
  for (int axis = 0; axis < 3; ++axis) {
    glm::vec3 n(0.0f);
    n[axis] = 1.0f;
    planes.push_back(glm::vec4(n, -lo[axis]));  // p >= lo
    planes.push_back(glm::vec4(-n, hi[axis]));  // p <= hi
  }
  return planes;
}

glm::vec4 clip_plane(glm::vec3 point, glm::vec3 normal) {
  const glm::vec3 n = glm::normalize(normal);
  return glm::vec4(n, -glm::dot(n, point));
}

bool cut_away(const Volume& volume, glm::vec3 p) {
  for (const glm::vec4& plane : volume.cut)
    if (glm::dot(glm::vec3(plane), p) + plane.w < 0.0f) return true;
  return false;
}

std::vector<bool> inside_volume(const Volume& volume, const std::vector<glm::vec3>& points) {
  const glm::mat4 world_to_index = glm::inverse(volume.index_to_world());
  std::vector<bool> inside;
  for (const glm::vec3& p : points) {
    const glm::vec3 i = glm::vec3(world_to_index * glm::vec4(p, 1.0f));
    inside.push_back(glm::all(glm::greaterThanEqual(i, glm::vec3(-0.5f))) &&
                     glm::all(glm::lessThanEqual(i, glm::vec3(volume.dims) - 0.5f)));
  }
  return inside;
}

std::vector<bool> anchors_cut_away(const Scene& scene, const std::vector<glm::vec3>& anchors) {
  std::vector<bool> cut(anchors.size(), false), kept(anchors.size(), false);
  for (const Volume& v : scene.volumes) {
    const std::vector<bool> inside = inside_volume(v, anchors);
    for (size_t a = 0; a < anchors.size(); ++a)
      if (inside[a]) (cut_away(v, anchors[a]) ? cut : kept)[a] = true;
  }
  for (size_t a = 0; a < anchors.size(); ++a) cut[a] = cut[a] && !kept[a];
  return cut;
}

const CameraPose* find_position(const Scene& scene, std::string_view name) {
  const auto named = [&](std::string_view wanted) -> const CameraPose* {
    for (const CameraPose& pose : scene.camera_positions)
      if (pose.name == wanted) return &pose;
    return nullptr;
  };
  if (const CameraPose* pose = named(name)) return pose;
  const std::optional<std::string> standard = standard_view_name(name);
  return standard ? named(*standard) : nullptr;
}

Camera camera_for(const Scene& scene, const std::string& name) {
  Camera camera = scene.camera;
  if (name.empty()) return camera;
  if (const CameraPose* pose = find_position(scene, name)) {
    camera.view = pose->view;
    return camera;
  }
  std::string names;
  for (const CameraPose& pose : scene.camera_positions)
    names += (names.empty() ? "" : ", ") + pose.name;
  throw Error(scene.source.string() + ": no camera position named '" + name +
              "' (the scene has: " + (names.empty() ? "none" : names) + ")");
}

}  // namespace strata
