#include "engine/scene/segmentation.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <thread>

#include "engine/core/error.h"
#include "engine/scene/atlas.h"

namespace strata {
namespace {

uint16_t layer_at(const Volume& layer, size_t index) {
  uint16_t value;
  std::memcpy(&value, layer.voxels.data() + 2 * index, 2);
  return value;
}

void set_layer_at(Volume& layer, size_t index, uint16_t value) {
  std::memcpy(layer.voxels.data() + 2 * index, &value, 2);
}

// A label map's value at `index` as a whole number; false where it is not one (a fraction, NaN).
bool whole_value(const Volume& v, size_t index, int64_t& out) {
  switch (v.type) {
    case VoxelType::uint8:
      out = std::to_integer<int>(v.voxels[index]);
      return true;
    case VoxelType::int16: {
      int16_t raw;
      std::memcpy(&raw, v.voxels.data() + 2 * index, 2);
      out = raw;
      return true;
    }
    case VoxelType::uint16:
      out = layer_at(v, index);
      return true;
    default: {
      float f;
      std::memcpy(&f, v.voxels.data() + 4 * index, 4);
      if (!(std::fabs(f) < 2147483648.0f) || f != std::floor(f)) return false;
      out = static_cast<int64_t>(f);
      return true;
    }
  }
}

}  // namespace

Volume empty_layer(const Volume& grid) {
  Volume layer;
  layer.name = grid.name;
  layer.source = grid.source;
  layer.type = VoxelType::uint16;
  layer.dims = grid.dims;
  layer.spacing = grid.spacing;
  layer.origin = grid.origin;
  layer.direction = grid.direction;
  layer.transform = grid.transform;
  layer.voxels.assign(layer.voxel_count() * 2, std::byte{0});
  return layer;
}

void add_region_voxels(Segmentation& segmentation, const Volume& grid,
                       const std::vector<uint8_t>& inside, SegmentRegion region) {
  if (region.number < 1 || region.number > kMaxRegionValue)
    throw Error(segmentation.source.string() + ": region '" + region.name + "': number " +
                std::to_string(region.number) + " is outside 1.." +
                std::to_string(kMaxRegionValue));
  const Volume& shape = segmentation.layers.empty() ? grid : segmentation.layers.front();
  if (inside.size() != shape.voxel_count())
    throw Error(segmentation.source.string() + ": region '" + region.name + "' has " +
                std::to_string(inside.size()) + " voxels, the grid " +
                std::to_string(shape.voxel_count()));
  // A region is a small part of the grid: its voxels are found once, eight bytes at a time, and
  // only they are looked at in each layer.
  std::vector<size_t> voxels;
  size_t i = 0;
  for (; i + 8 <= inside.size(); i += 8) {
    uint64_t word;
    std::memcpy(&word, inside.data() + i, 8);
    if (word == 0) continue;
    for (size_t k = i; k < i + 8; ++k)
      if (inside[k]) voxels.push_back(k);
  }
  for (; i < inside.size(); ++i)
    if (inside[i]) voxels.push_back(i);
  const auto fits = [&](const Volume& layer, int index) {
    for (const SegmentRegion& r : segmentation.regions)
      if (r.layer == index && r.value == region.number) return false;
    return std::none_of(voxels.begin(), voxels.end(),
                        [&](size_t v) { return layer_at(layer, v) != 0; });
  };
  int target = 0;
  while (target < int(segmentation.layers.size()) && !fits(segmentation.layers[target], target))
    ++target;
  if (target == int(segmentation.layers.size())) segmentation.layers.push_back(empty_layer(shape));
  Volume& layer = segmentation.layers[target];
  for (size_t v : voxels) set_layer_at(layer, v, uint16_t(region.number));
  region.layer = target;
  region.value = region.number;
  segmentation.regions.push_back(std::move(region));
}

Segmentation segmentation_from_label_map(Volume label_map, const NamesTable& names,
                                         std::vector<std::string>& warnings) {
  Segmentation segmentation;
  segmentation.source = label_map.source;
  std::map<int64_t, int> named;  // value -> entry
  for (size_t i = 0; i < names.entries.size(); ++i) {
    const NamedValue& entry = names.entries[i];
    if (entry.value == 0) continue;  // background
    if (entry.value < 0 || entry.value > kMaxRegionValue)
      throw Error(label_map.source.string() + ": region '" + entry.name + "': value " +
                  std::to_string(entry.value) + " is outside 1.." +
                  std::to_string(kMaxRegionValue));
    named.emplace(entry.value, int(i));
  }
  Volume layer = empty_layer(label_map);
  std::map<int64_t, size_t> unnamed;  // value with voxels the table does not name -> count
  for (size_t i = 0; i < label_map.voxel_count(); ++i) {
    int64_t value = 0;
    if (!whole_value(label_map, i, value))
      throw Error(label_map.source.string() + ": not a label map: voxel " + std::to_string(i) +
                  " holds a value that is not a whole number");
    if (value == 0) continue;
    if (named.count(value)) {
      set_layer_at(layer, i, uint16_t(value));
    } else {
      ++unnamed[value];
    }
  }
  if (!unnamed.empty()) {
    std::string list;
    int shown = 0;
    for (const auto& [value, count] : unnamed) {
      if (shown++ == 8) {
        list += ", ...";
        break;
      }
      list += (list.empty() ? "" : ", ") + std::to_string(value);
    }
    warnings.push_back(
        label_map.source.string() + ": " + std::to_string(unnamed.size()) +
        " value(s) with voxels that the names table does not name are left out: " + list);
  }
  // The table's order, not the values' (a table lists its regions as its tool shows them).
  for (size_t i = 0; i < names.entries.size(); ++i) {
    const NamedValue& e = names.entries[i];
    if (e.value != 0 && named.at(e.value) == int(i))
      segmentation.regions.push_back({e.value, 0, e.value, e.name, e.colour});
  }
  segmentation.layers.push_back(std::move(layer));
  return segmentation;
}

namespace {

// One region's voxels in its layer: count, bounding box (voxel indices, inclusive).
struct RegionExtent {
  size_t voxels = 0;
  glm::ivec3 lo{std::numeric_limits<int>::max()};
  glm::ivec3 hi{-1};
};

std::vector<RegionExtent> region_extents(const Segmentation& segmentation) {
  std::vector<RegionExtent> extents(segmentation.regions.size());
  for (size_t l = 0; l < segmentation.layers.size(); ++l) {
    std::vector<int> region_of(kMaxRegionValue + 1, -1);
    for (size_t r = 0; r < segmentation.regions.size(); ++r)
      if (segmentation.regions[r].layer == int(l))
        region_of[segmentation.regions[r].value] = int(r);
    const Volume& layer = segmentation.layers[l];
    const glm::ivec3 dims(layer.dims);
    size_t i = 0;
    for (int z = 0; z < dims.z; ++z) {
      for (int y = 0; y < dims.y; ++y) {
        for (int x = 0; x < dims.x; ++x, ++i) {
          const uint16_t value = layer_at(layer, i);
          if (value == 0 || region_of[value] < 0) continue;
          RegionExtent& e = extents[size_t(region_of[value])];
          ++e.voxels;
          e.lo = glm::min(e.lo, glm::ivec3(x, y, z));
          e.hi = glm::max(e.hi, glm::ivec3(x, y, z));
        }
      }
    }
  }
  return extents;
}

// A region's box with one empty voxel around it: cell values 0 outside, 1 inside, then the part
// number (2, 3, ...) once the parts are found.
struct Box {
  glm::ivec3 origin{0};  // voxel index of cell (0, 0, 0)
  glm::ivec3 size{0};
  std::vector<int32_t> cells;
  size_t index(int x, int y, int z) const { return (size_t(z) * size.y + y) * size.x + x; }
};

Box region_box(const Volume& layer, uint16_t value, const RegionExtent& extent) {
  Box box;
  box.origin = extent.lo - 1;
  box.size = extent.hi - extent.lo + 3;
  box.cells.assign(size_t(box.size.x) * box.size.y * box.size.z, 0);
  const glm::ivec3 dims(layer.dims);
  for (int z = extent.lo.z; z <= extent.hi.z; ++z)
    for (int y = extent.lo.y; y <= extent.hi.y; ++y)
      for (int x = extent.lo.x; x <= extent.hi.x; ++x)
        if (layer_at(layer, (size_t(z) * dims.y + y) * dims.x + x) == value)
          box.cells[box.index(x - box.origin.x, y - box.origin.y, z - box.origin.z)] = 1;
  return box;
}

// Numbers the 6-connected parts (2, 3, ...) and returns the number of the largest (the first
// found of equal ones) and how many parts there are.
std::pair<int32_t, int> largest_part(Box& box) {
  const int64_t sx = 1, sy = box.size.x, sz = int64_t(box.size.x) * box.size.y;
  const int64_t steps[6] = {sx, -sx, sy, -sy, sz, -sz};
  std::vector<int64_t> stack;
  int32_t next = 2, best = 0;
  size_t best_size = 0;
  for (size_t start = 0; start < box.cells.size(); ++start) {
    if (box.cells[start] != 1) continue;
    size_t size = 0;
    box.cells[start] = next;
    stack.push_back(int64_t(start));
    while (!stack.empty()) {
      const int64_t at = stack.back();
      stack.pop_back();
      ++size;
      // The padding keeps every inside cell's neighbours within the box.
      for (int64_t step : steps) {
        if (box.cells[size_t(at + step)] != 1) continue;
        box.cells[size_t(at + step)] = next;
        stack.push_back(at + step);
      }
    }
    if (size > best_size) best_size = size, best = next;
    ++next;
  }
  return {best, next - 2};
}

// Squared distance transform along one line of `count` samples `stride` apart, `spacing` mm
// apart: the lower envelope of parabolas (Felzenszwalb and Huttenlocher's method).
void distance_line(double* d, size_t count, size_t stride, double spacing, std::vector<double>& f,
                   std::vector<int>& v, std::vector<double>& z) {
  constexpr double kFar = 1e300;
  f.resize(count);
  v.resize(count);
  z.resize(count + 1);
  for (size_t i = 0; i < count; ++i) f[i] = d[i * stride];
  const auto at = [&](int q) { return q * spacing; };
  int k = -1;
  for (int q = 0; q < int(count); ++q) {
    if (f[q] >= kFar) continue;
    double s = -kFar;
    while (k >= 0) {
      const int p = v[k];
      s = ((f[q] + at(q) * at(q)) - (f[p] + at(p) * at(p))) / (2.0 * (at(q) - at(p)));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = k == 0 ? -kFar : s;
    z[k + 1] = kFar;
  }
  if (k < 0) return;  // no finite sample on this line
  int j = 0;
  for (int q = 0; q < int(count); ++q) {
    while (z[j + 1] < at(q)) ++j;
    const double delta = at(q) - at(v[j]);
    d[q * stride] = delta * delta + f[v[j]];
  }
}

// The deepest voxel of part `part` of the box: the farthest from any cell outside the part,
// ties broken toward the part's centroid (both in mm).
glm::ivec3 deepest_voxel(const Box& box, int32_t part, glm::dvec3 spacing) {
  std::vector<double> d(box.cells.size());
  glm::dvec3 sum(0.0);
  size_t count = 0;
  for (int z = 0; z < box.size.z; ++z)
    for (int y = 0; y < box.size.y; ++y)
      for (int x = 0; x < box.size.x; ++x) {
        const bool in = box.cells[box.index(x, y, z)] == part;
        d[box.index(x, y, z)] = in ? 1e300 : 0.0;
        if (in) sum += glm::dvec3(x, y, z), ++count;
      }
  std::vector<double> f, z;
  std::vector<int> v;
  const glm::ivec3 n = box.size;
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j) distance_line(&d[box.index(0, j, k)], n.x, 1, spacing.x, f, v, z);
  for (int k = 0; k < n.z; ++k)
    for (int i = 0; i < n.x; ++i)
      distance_line(&d[box.index(i, 0, k)], n.y, size_t(n.x), spacing.y, f, v, z);
  for (int j = 0; j < n.y; ++j)
    for (int i = 0; i < n.x; ++i)
      distance_line(&d[box.index(i, j, 0)], n.z, size_t(n.x) * n.y, spacing.z, f, v, z);
  const glm::dvec3 centroid = sum / double(count);
  glm::ivec3 best(0);
  double best_depth = -1.0, best_off = 0.0;
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const size_t at = box.index(i, j, k);
        if (box.cells[at] != part || d[at] < best_depth) continue;
        const glm::dvec3 off = (glm::dvec3(i, j, k) - centroid) * spacing;
        const double off2 = glm::dot(off, off);
        if (d[at] == best_depth && off2 >= best_off) continue;
        best_depth = d[at], best_off = off2, best = glm::ivec3(i, j, k);
      }
  return best + box.origin;
}

RegionSummary summarise(const Segmentation& segmentation, const SegmentRegion& region,
                        const RegionExtent& extent) {
  RegionSummary summary;
  const Volume& layer = segmentation.layers[size_t(region.layer)];
  summary.voxels = extent.voxels;
  summary.millilitres =
      double(extent.voxels) * layer.spacing.x * layer.spacing.y * layer.spacing.z / 1000.0;
  if (extent.voxels == 0) return summary;
  Box box = region_box(layer, uint16_t(region.value), extent);
  const auto [part, parts] = largest_part(box);
  summary.parts = parts;
  const glm::ivec3 deepest = deepest_voxel(box, part, glm::dvec3(layer.spacing));
  summary.anchor = glm::vec3(layer.index_to_world() * glm::vec4(glm::vec3(deepest), 1.0f));
  return summary;
}

}  // namespace

std::vector<RegionSummary> summarise_regions(const Segmentation& segmentation) {
  std::vector<size_t> all(segmentation.regions.size());
  for (size_t r = 0; r < all.size(); ++r) all[r] = r;
  return summarise_regions(segmentation, all);
}

std::vector<RegionSummary> summarise_regions(const Segmentation& segmentation,
                                             const std::vector<size_t>& which) {
  const std::vector<RegionExtent> extents = region_extents(segmentation);
  std::vector<RegionSummary> summaries(which.size());
  std::atomic<size_t> next{0};
  const auto work = [&] {
    for (size_t i; (i = next++) < summaries.size();)
      summaries[i] = summarise(segmentation, segmentation.regions.at(which[i]), extents[which[i]]);
  };
  const unsigned threads =
      std::clamp<unsigned>(std::thread::hardware_concurrency(), 1, unsigned(summaries.size()) + 1);
  std::vector<std::jthread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  return summaries;
}

bool region_contains(const Segmentation& segmentation, const SegmentRegion& region,
                     glm::vec3 world) {
  const Volume& layer = segmentation.layers.at(size_t(region.layer));
  const glm::vec3 index =
      glm::round(glm::vec3(glm::inverse(layer.index_to_world()) * glm::vec4(world, 1.0f)));
  if (glm::any(glm::lessThan(index, glm::vec3(0.0f))) ||
      glm::any(glm::greaterThanEqual(index, glm::vec3(layer.dims))))
    return false;
  const glm::uvec3 i(index);
  return layer_at(layer, (size_t(i.z) * layer.dims.y + i.y) * layer.dims.x + i.x) == region.value;
}


void check_segmentation_fits(const Segmentation& segmentation, const Volume& scan) {
  if (segmentation.layers.empty()) return;
  const Volume& grid = segmentation.layers.front();
  const std::string both = segmentation.source.string() + " and " + scan.source.string();
  for (int a = 0; a < 3; ++a) {
    const glm::vec3 axis = glm::mat3(grid.transform) * grid.direction[a];
    float best = 0.0f;
    for (int b = 0; b < 3; ++b)
      best = std::max(
          best, std::fabs(glm::dot(glm::normalize(axis),
                                   glm::normalize(glm::mat3(scan.transform) * scan.direction[b]))));
    if (best < std::cos(glm::radians(1.0f)))
      throw Error(both + ": their orientations disagree (the segmentation's axis " +
                  std::to_string(a) + " is " + std::to_string(glm::degrees(std::acos(best))) +
                  " degrees from every axis of the scan): was it written for another scan?");
  }
  // The boxes of the voxels (centres widened by half a voxel) must overlap.
  const auto box = [](const Volume& v) {
    auto [lo, hi] = v.world_bounds();
    glm::vec3 half(0.0f);
    for (int k = 0; k < 3; ++k)
      half += 0.5f * v.spacing[k] * glm::abs(glm::mat3(v.transform) * v.direction[k]);
    return std::pair{lo - half, hi + half};
  };
  const auto [a_lo, a_hi] = box(grid);
  const auto [b_lo, b_hi] = box(scan);
  if (glm::any(glm::lessThan(a_hi, b_lo)) || glm::any(glm::lessThan(b_hi, a_lo)))
    throw Error(both + ": the segmentation's grid does not overlap the scan (world boxes " +
                "differ entirely): was it written for another scan?");
}

Volume region_mask(const Segmentation& segmentation, const SegmentRegion& region) {
  const Volume& layer = segmentation.layers.at(size_t(region.layer));
  Volume mask = layer;
  mask.name = region.name;
  mask.type = VoxelType::uint8;
  mask.voxels.assign(layer.voxel_count(), std::byte{0});
  for (size_t i = 0; i < layer.voxel_count(); ++i)
    if (layer_at(layer, i) == region.value) mask.voxels[i] = std::byte{255};
  mask.value_range = {0.0f, 255.0f};
  mask.transfer_function = -1;
  return mask;
}

Mesh region_surface(const Segmentation& segmentation, const SegmentRegion& region) {
  Mesh mesh = atlas_surface(segmentation.layers.at(size_t(region.layer)),
                            AtlasRegion{region.value, region.name, 0});
  mesh.source = segmentation.source;
  return mesh;
}

}  // namespace strata
