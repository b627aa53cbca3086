#include "engine/scene/atlas.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <unordered_map>

#include "engine/core/error.h"
#include "engine/core/text_file.h"

namespace strata {
namespace {

int label_at(const Volume& v, size_t index) {
  if (v.type == VoxelType::uint8) return std::to_integer<int>(v.voxels[index]);
  if (v.type == VoxelType::int16 || v.type == VoxelType::uint16) {
    uint16_t raw;
    std::memcpy(&raw, v.voxels.data() + 2 * index, 2);
    return v.type == VoxelType::int16 ? static_cast<int16_t>(raw) : raw;
  }
  float f;
  std::memcpy(&f, v.voxels.data() + 4 * index, 4);
  return static_cast<int>(std::lround(f));
}

void require_label_volume(const Volume& v) {
  if (v.voxels.size() != v.voxel_count() * voxel_size(v.type) || v.voxel_count() == 0) {
    throw Error(v.source.string() + ": not a label volume (no voxels)");
  }
}

// The region's voxels as a padded binary grid: one empty voxel around the bounding box, so the
// surface closes where the region touches the volume's edge.
struct Grid {
  glm::ivec3 origin{0};  // voxel index of grid cell (0, 0, 0)
  glm::ivec3 size{0};
  std::vector<uint8_t> inside;
  bool at(int x, int y, int z) const { return inside[(size_t(z) * size.y + y) * size.x + x] != 0; }
};

Grid region_grid(const Volume& v, int index) {
  glm::ivec3 lo(std::numeric_limits<int>::max()), hi(-1);
  const glm::ivec3 dims(v.dims);
  for (int z = 0; z < dims.z; ++z) {
    for (int y = 0; y < dims.y; ++y) {
      for (int x = 0; x < dims.x; ++x) {
        if (label_at(v, (size_t(z) * dims.y + y) * dims.x + x) != index) continue;
        lo = glm::min(lo, glm::ivec3(x, y, z));
        hi = glm::max(hi, glm::ivec3(x, y, z));
      }
    }
  }
  Grid g;
  if (hi.x < 0) return g;
  g.origin = lo - 1;
  g.size = hi - lo + 3;
  g.inside.assign(size_t(g.size.x) * g.size.y * g.size.z, 0);
  for (int z = lo.z; z <= hi.z; ++z) {
    for (int y = lo.y; y <= hi.y; ++y) {
      for (int x = lo.x; x <= hi.x; ++x) {
        if (label_at(v, (size_t(z) * dims.y + y) * dims.x + x) != index) continue;
        const glm::ivec3 p = glm::ivec3(x, y, z) - g.origin;
        g.inside[(size_t(p.z) * g.size.y + p.y) * g.size.x + p.x] = 1;
      }
    }
  }
  return g;
}

// Naive surface nets: one vertex per cell (the cube between 8 voxel centres) that the boundary
// crosses, at the mean of its crossing edges' midpoints; one quad per voxel edge whose ends
// differ, joining the four cells around that edge. Watertight, and needs no case tables.
void surface_nets(const Grid& g, std::vector<glm::vec3>& positions,
                  std::vector<uint32_t>& indices) {
  const glm::ivec3 cells = g.size - 1;
  std::vector<int32_t> vertex_of(size_t(cells.x) * cells.y * cells.z, -1);
  const auto cell_index = [&](int x, int y, int z) {
    return (size_t(z) * cells.y + y) * cells.x + x;
  };
  static constexpr std::array<std::array<int, 2>, 12> kEdges = {{{0, 1},
                                                                 {2, 3},
                                                                 {4, 5},
                                                                 {6, 7},
                                                                 {0, 2},
                                                                 {1, 3},
                                                                 {4, 6},
                                                                 {5, 7},
                                                                 {0, 4},
                                                                 {1, 5},
                                                                 {2, 6},
                                                                 {3, 7}}};
  const auto corner = [](int c) { return glm::ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1); };
  for (int z = 0; z < cells.z; ++z) {
    for (int y = 0; y < cells.y; ++y) {
      for (int x = 0; x < cells.x; ++x) {
        glm::vec3 sum(0.0f);
        int crossings = 0;
        for (const auto& e : kEdges) {
          const glm::ivec3 a = glm::ivec3(x, y, z) + corner(e[0]);
          const glm::ivec3 b = glm::ivec3(x, y, z) + corner(e[1]);
          if (g.at(a.x, a.y, a.z) == g.at(b.x, b.y, b.z)) continue;
          sum += 0.5f * glm::vec3(a + b);
          ++crossings;
        }
        if (crossings == 0) continue;
        vertex_of[cell_index(x, y, z)] = static_cast<int32_t>(positions.size());
        positions.push_back(sum / float(crossings));
      }
    }
  }
  // Each voxel edge along `axis` from p to p + e_axis is shared by the four cells at p - u - w,
  // p - u, p - w, p (u, w: the other two axes). Inside-to-outside along +axis faces +axis.
  for (int axis = 0; axis < 3; ++axis) {
    const glm::ivec3 e = glm::ivec3(axis == 0, axis == 1, axis == 2);
    const glm::ivec3 u = glm::ivec3(axis == 1, axis == 2, axis == 0);
    const glm::ivec3 w = glm::ivec3(axis == 2, axis == 0, axis == 1);
    // The padding keeps every crossing edge off the grid's faces, so its four cells exist.
    for (int z = 0; z < g.size.z; ++z) {
      for (int y = 0; y < g.size.y; ++y) {
        for (int x = 0; x < g.size.x; ++x) {
          const glm::ivec3 p(x, y, z), q = p + e;
          if (q.x >= g.size.x || q.y >= g.size.y || q.z >= g.size.z) continue;
          const bool a = g.at(p.x, p.y, p.z), b = g.at(q.x, q.y, q.z);
          if (a == b) continue;
          const glm::ivec3 c[4] = {p - u - w, p - w, p, p - u};
          uint32_t v[4];
          for (int i = 0; i < 4; ++i)
            v[i] = static_cast<uint32_t>(vertex_of[cell_index(c[i].x, c[i].y, c[i].z)]);
          // u x w = -e, so c[0..3] turn clockwise seen from +e: reverse them when the
          // outward normal is +e (inside at p).
          if (a) {
            indices.insert(indices.end(), {v[0], v[2], v[1], v[0], v[3], v[2]});
          } else {
            indices.insert(indices.end(), {v[0], v[1], v[2], v[0], v[2], v[3]});
          }
        }
      }
    }
  }
}

// Taubin's lambda|mu smoothing: a shrinking Laplacian step, then an inflating one, so the mesh
// loses its voxel steps without shrinking.
void taubin_smooth(std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                   int iterations) {
  std::vector<std::vector<uint32_t>> neighbours(positions.size());
  for (size_t t = 0; t < indices.size(); t += 3) {
    for (int i = 0; i < 3; ++i) {
      const uint32_t a = indices[t + i], b = indices[t + (i + 1) % 3];
      neighbours[a].push_back(b);
      neighbours[b].push_back(a);
    }
  }
  for (auto& n : neighbours) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }
  std::vector<glm::vec3> next(positions.size());
  const auto step = [&](float factor) {
    for (size_t i = 0; i < positions.size(); ++i) {
      glm::vec3 mean(0.0f);
      for (uint32_t n : neighbours[i]) mean += positions[n];
      next[i] = neighbours[i].empty()
                    ? positions[i]
                    : positions[i] + factor * (mean / float(neighbours[i].size()) - positions[i]);
    }
    positions.swap(next);
  };
  for (int i = 0; i < iterations; ++i) {
    step(0.5f);
    step(-0.53f);
  }
}

std::vector<glm::vec3> vertex_normals(const std::vector<glm::vec3>& positions,
                                      const std::vector<uint32_t>& indices) {
  std::vector<glm::vec3> normals(positions.size(), glm::vec3(0.0f));
  for (size_t t = 0; t < indices.size(); t += 3) {
    const glm::vec3 a = positions[indices[t]], b = positions[indices[t + 1]],
                    c = positions[indices[t + 2]];
    const glm::vec3 n = glm::cross(b - a, c - a);  // area-weighted
    for (int i = 0; i < 3; ++i) normals[indices[t + i]] += n;
  }
  for (glm::vec3& n : normals) {
    const float len = glm::length(n);
    n = len > 0.0f ? n / len : glm::vec3(0.0f, 0.0f, 1.0f);
  }
  return normals;
}

}  // namespace

std::vector<AtlasRegion> load_atlas_names(const std::filesystem::path& path) {
  std::istringstream in(read_text_file(path));
  std::vector<AtlasRegion> regions;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream fields(line);
    AtlasRegion r;
    if (!(fields >> r.index >> r.name)) {
      throw Error(path.string() + ": line " + std::to_string(number) +
                  ": expected 'index name [colour]', got '" + line + "'");
    }
    fields >> r.colour;
    regions.push_back(std::move(r));
  }
  if (regions.empty()) throw Error(path.string() + ": no regions in atlas names file");
  return regions;
}

std::vector<Label> atlas_labels(const Volume& labels, const std::vector<AtlasRegion>& regions) {
  require_label_volume(labels);
  std::unordered_map<int, std::pair<glm::dvec3, size_t>> sums;
  const glm::ivec3 dims(labels.dims);
  for (int z = 0; z < dims.z; ++z) {
    for (int y = 0; y < dims.y; ++y) {
      for (int x = 0; x < dims.x; ++x) {
        const int value = label_at(labels, (size_t(z) * dims.y + y) * dims.x + x);
        if (value == 0) continue;
        auto& [sum, count] = sums[value];
        sum += glm::dvec3(x, y, z);
        ++count;
      }
    }
  }
  std::vector<Label> out;
  const glm::mat4 to_world = labels.index_to_world();
  for (const AtlasRegion& r : regions) {
    const auto it = sums.find(r.index);
    if (it == sums.end()) continue;
    const glm::vec3 centroid(it->second.first / double(it->second.second));
    Label label;
    label.id = r.index;
    label.text = r.name;
    std::replace(label.text.begin(), label.text.end(), '_', ' ');
    label.anchor = glm::vec3(to_world * glm::vec4(centroid, 1.0f));
    out.push_back(std::move(label));
  }
  return out;
}

Volume atlas_mask(const Volume& labels, const AtlasRegion& region) {
  require_label_volume(labels);
  Volume mask = labels;
  mask.name = region.name;
  mask.type = VoxelType::uint8;
  mask.voxels.assign(labels.voxel_count(), std::byte{0});
  mask.transfer_function = -1;
  for (size_t i = 0; i < labels.voxel_count(); ++i) {
    if (label_at(labels, i) == region.index) mask.voxels[i] = std::byte{255};
  }
  mask.value_range = {0.0f, 255.0f};
  return mask;
}

TransferFunction mask_transfer_function(const std::string& name, glm::vec4 colour) {
  const glm::vec4 clear(glm::vec3(colour), 0.0f);
  return {name, {}, {{0.0f, clear}, {0.4f, clear}, {0.6f, colour}, {1.0f, colour}}};
}

Mesh atlas_surface(const Volume& labels, const AtlasRegion& region, int smoothing_iterations) {
  require_label_volume(labels);
  const Grid grid = region_grid(labels, region.index);
  Mesh mesh;
  mesh.name = region.name;
  mesh.source = labels.source;
  if (grid.inside.empty()) return mesh;
  surface_nets(grid, mesh.positions, mesh.indices);
  taubin_smooth(mesh.positions, mesh.indices, smoothing_iterations);
  // Grid coordinates -> voxel indices -> world.
  const glm::mat4 to_world = labels.index_to_world();
  for (glm::vec3& p : mesh.positions) {
    p = glm::vec3(to_world * glm::vec4(p + glm::vec3(grid.origin), 1.0f));
  }
  // A mirroring index-to-world flips the winding: keep triangles facing outward.
  if (glm::determinant(glm::mat3(to_world)) < 0.0f) {
    for (size_t t = 0; t < mesh.indices.size(); t += 3)
      std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
  }
  mesh.normals = vertex_normals(mesh.positions, mesh.indices);
  return mesh;
}

std::string atlas_region_at(const SceneAtlas& atlas, glm::vec3 world) {
  const Volume& v = atlas.labels;
  const glm::vec4 index = glm::inverse(v.index_to_world()) * glm::vec4(world, 1.0f);
  const glm::vec3 nearest = glm::round(glm::vec3(index));
  if (nearest.x < 0.0f || nearest.y < 0.0f || nearest.z < 0.0f || nearest.x >= float(v.dims.x) ||
      nearest.y >= float(v.dims.y) || nearest.z >= float(v.dims.z)) {
    return {};
  }
  const int region =
      int(std::lround(v.value(uint32_t(nearest.x), uint32_t(nearest.y), uint32_t(nearest.z))));
  const auto it = atlas.names.find(region);
  if (region == 0 || it == atlas.names.end()) return {};
  std::string name = it->second;
  std::replace(name.begin(), name.end(), '_', ' ');
  return name;
}

std::string atlas_region_at(const Scene& scene, glm::vec3 world) {
  for (const SceneAtlas& atlas : scene.atlases) {
    if (std::string name = atlas_region_at(atlas, world); !name.empty()) return name;
  }
  return {};
}

}  // namespace strata
