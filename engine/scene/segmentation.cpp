#include "engine/scene/segmentation.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>

#include "engine/core/error.h"

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
  const auto fits = [&](const Volume& layer, int index) {
    for (const SegmentRegion& r : segmentation.regions)
      if (r.layer == index && r.value == region.number) return false;
    for (size_t i = 0; i < inside.size(); ++i)
      if (inside[i] && layer_at(layer, i) != 0) return false;
    return true;
  };
  int target = 0;
  while (target < int(segmentation.layers.size()) && !fits(segmentation.layers[target], target))
    ++target;
  if (target == int(segmentation.layers.size())) segmentation.layers.push_back(empty_layer(shape));
  Volume& layer = segmentation.layers[target];
  for (size_t i = 0; i < inside.size(); ++i)
    if (inside[i]) set_layer_at(layer, i, uint16_t(region.number));
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
    warnings.push_back(label_map.source.string() + ": " + std::to_string(unnamed.size()) +
                       " value(s) with voxels that the names table does not name are left out: " +
                       list);
  }
  for (const auto& [value, entry] : named) {
    (void)value;
    const NamedValue& e = names.entries[size_t(entry)];
    segmentation.regions.push_back({e.value, 0, e.value, e.name, e.colour});
  }
  // The table's order, not the values' (a table lists its regions as its tool shows them).
  std::stable_sort(segmentation.regions.begin(), segmentation.regions.end(),
                   [&](const SegmentRegion& a, const SegmentRegion& b) {
                     return named[a.value] < named[b.value];
                   });
  segmentation.layers.push_back(std::move(layer));
  return segmentation;
}

}  // namespace strata
