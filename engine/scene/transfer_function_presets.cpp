#include "engine/scene/transfer_function_presets.h"

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"

namespace strata {
namespace {

// A stop at a data value: Hounsfield units for CT presets, a multiple of the bright-tissue level
// for MR presets.
struct ValueStop {
  float value;
  glm::vec4 color;
};

struct PresetData {
  TransferFunctionPreset preset;
  std::vector<ValueStop> stops;
};

// Opacities are per millimetre-sized sample, like the demo's head-t1.json: a few percent for
// tissue that should stay see-through, so the layers behind it (and their labels) remain.
const std::vector<PresetData>& preset_data() {
  static const std::vector<PresetData> presets = {
      {{"ct-skin", "CT: the skin as a faint surface, bone behind it", true},
       {{-1000, {0, 0, 0, 0}},
        {-500, {0, 0, 0, 0}},
        {-300, {0.85f, 0.62f, 0.52f, 0.02f}},
        {-100, {0.92f, 0.72f, 0.62f, 0.08f}},
        {100, {0.90f, 0.66f, 0.56f, 0.02f}},
        {300, {0.95f, 0.90f, 0.80f, 0.03f}},
        {700, {1.00f, 0.98f, 0.92f, 0.25f}},
        {3000, {1, 1, 1, 0.40f}}}},
      {{"ct-soft-tissue", "CT: muscle and organs, fat faint, bone", true},
       {{-1000, {0, 0, 0, 0}},
        {-200, {0, 0, 0, 0}},
        {-100, {0.90f, 0.80f, 0.55f, 0.01f}},
        {20, {0.80f, 0.38f, 0.32f, 0.03f}},
        {80, {0.88f, 0.45f, 0.38f, 0.08f}},
        {200, {0.92f, 0.75f, 0.65f, 0.03f}},
        {400, {0.97f, 0.93f, 0.85f, 0.15f}},
        {3000, {1, 1, 1, 0.35f}}}},
      {{"ct-bone", "CT: bone only", true},
       {{-1000, {0, 0, 0, 0}},
        {150, {0, 0, 0, 0}},
        {250, {0.90f, 0.80f, 0.62f, 0.04f}},
        {500, {0.96f, 0.92f, 0.82f, 0.30f}},
        {1500, {1, 1, 1, 0.60f}},
        {3000, {1, 1, 1, 0.60f}}}},
      {{"ct-lung", "CT: lung tissue and airways, the body faint", true},
       {{-1000, {0, 0, 0, 0}},
        {-950, {0, 0, 0, 0}},
        {-850, {0.85f, 0.50f, 0.50f, 0.02f}},
        {-600, {0.92f, 0.62f, 0.60f, 0.05f}},
        {-400, {0, 0, 0, 0}},
        {-100, {0, 0, 0, 0}},
        {0, {0.85f, 0.65f, 0.55f, 0.005f}},
        {300, {0.95f, 0.92f, 0.85f, 0.01f}},
        {700, {1, 1, 1, 0.10f}},
        {3000, {1, 1, 1, 0.20f}}}},
      {{"mr-head", "MR (T1): faint skin, brain tissue", false},
       {{0.00f, {0, 0, 0, 0}},
        {0.20f, {0, 0, 0, 0}},
        {0.32f, {0.55f, 0.45f, 0.50f, 0.01f}},
        {0.44f, {0.85f, 0.70f, 0.72f, 0.06f}},
        {0.61f, {0.95f, 0.85f, 0.82f, 0.12f}},
        {0.73f, {0.98f, 0.93f, 0.88f, 0.10f}},
        {0.82f, {0.95f, 0.75f, 0.62f, 0.03f}},
        {1.46f, {1.00f, 0.80f, 0.65f, 0.05f}}}},
      {{"mr-brain", "MR (T1): grey and white matter, the scalp almost gone", false},
       {{0.00f, {0, 0, 0, 0}},
        {0.40f, {0, 0, 0, 0}},
        {0.50f, {0.75f, 0.55f, 0.58f, 0.02f}},
        {0.62f, {0.90f, 0.78f, 0.76f, 0.10f}},
        {0.72f, {0.98f, 0.94f, 0.90f, 0.16f}},
        {0.80f, {0.98f, 0.92f, 0.86f, 0.05f}},
        {0.90f, {1.00f, 0.85f, 0.70f, 0.005f}},
        {1.46f, {1.00f, 0.85f, 0.70f, 0.005f}}}},
  };
  return presets;
}

// MR intensities have no unit: the 99th percentile of the voxels above the background (the lowest
// 1% of the range) stands for bright tissue (white matter, fat on T1).
float bright_level(const Volume& volume) {
  const float lo = volume.value_range.x, hi = volume.value_range.y;
  if (!(hi > lo)) return hi;
  constexpr int kBins = 4096;
  std::vector<uint64_t> histogram(kBins, 0);
  uint64_t count = 0;
  const float background = lo + 0.01f * (hi - lo);
  for (uint32_t k = 0; k < volume.dims.z; ++k) {
    for (uint32_t j = 0; j < volume.dims.y; ++j) {
      for (uint32_t i = 0; i < volume.dims.x; ++i) {
        const float v = volume.value(i, j, k);
        if (!(v > background)) continue;
        ++histogram[size_t(std::min(kBins - 1, int((v - lo) / (hi - lo) * float(kBins))))];
        ++count;
      }
    }
  }
  uint64_t seen = 0;
  for (int b = 0; b < kBins; ++b) {
    seen += histogram[b];
    if (count > 0 && double(seen) >= 0.99 * double(count))
      return lo + (float(b) + 0.5f) / float(kBins) * (hi - lo);
  }
  return hi;
}

glm::vec4 color_at(const std::vector<ValueStop>& stops, float value) {
  if (value <= stops.front().value) return stops.front().color;
  for (size_t i = 1; i < stops.size(); ++i) {
    if (value <= stops[i].value) {
      const float t = (value - stops[i - 1].value) / (stops[i].value - stops[i - 1].value);
      return glm::mix(stops[i - 1].color, stops[i].color, t);
    }
  }
  return stops.back().color;
}

}  // namespace

const std::vector<TransferFunctionPreset>& transfer_function_presets() {
  static const std::vector<TransferFunctionPreset> presets = [] {
    std::vector<TransferFunctionPreset> out;
    for (const PresetData& p : preset_data()) out.push_back(p.preset);
    return out;
  }();
  return presets;
}

TransferFunction make_transfer_function_preset(std::string_view name, const Volume& volume) {
  const PresetData* found = nullptr;
  std::string names;
  for (const PresetData& p : preset_data()) {
    if (name == p.preset.name) found = &p;
    names += std::string(names.empty() ? "" : ", ") + p.preset.name;
  }
  if (!found)
    throw Error("no transfer-function preset '" + std::string(name) + "' (" + names + ")");

  const float scale = found->preset.ct ? 1.0f : bright_level(volume);
  TransferFunction in_values;
  in_values.name = found->preset.name;
  in_values.units = "raw";
  for (const ValueStop& s : found->stops) in_values.stops.push_back({s.value * scale, s.color});
  return in_value_range(in_values, volume);
}

// The values as the volume's normalised [0, 1] (its value range), cut to that range: a stop at
// each end with the colour there, the stops strictly inside kept.
TransferFunction in_value_range(const TransferFunction& in_values, const Volume& volume) {
  std::vector<ValueStop> stops;
  for (const TransferFunction::Stop& s : in_values.stops) stops.push_back({s.position, s.color});
  const float lo = volume.value_range.x, hi = volume.value_range.y;
  TransferFunction tf;
  tf.name = in_values.name;
  tf.source = in_values.source;
  tf.stops.push_back({0.0f, color_at(stops, lo)});
  if (hi > lo) {
    for (const ValueStop& s : stops) {
      const float t = (s.value - lo) / (hi - lo);
      if (t > 0.0f && t < 1.0f) tf.stops.push_back({t, s.color});
    }
  }
  tf.stops.push_back({1.0f, color_at(stops, hi)});
  return tf;
}

TransferFunction in_volume_values(const TransferFunction& in_range, const Volume& volume) {
  TransferFunction out = in_range;
  const float lo = volume.value_range.x, span = volume.value_range.y - lo;
  for (TransferFunction::Stop& stop : out.stops) stop.position = lo + stop.position * span;
  out.units = preset_is_ct(choose_transfer_function_preset(volume).name) ? "HU" : "raw";
  out.source.clear();
  return out;
}

TransferFunction window_transfer_function(float center, float width) {
  TransferFunction tf;
  char name[64];
  std::snprintf(name, sizeof name, "window %g/%g", center, width);
  tf.name = name;
  tf.units = "raw";
  tf.stops = {{center - 0.5f * width, glm::vec4(0.0f)}, {center + 0.5f * width, glm::vec4(1.0f)}};
  return tf;
}

bool preset_is_ct(std::string_view name) {
  for (const TransferFunctionPreset& p : transfer_function_presets())
    if (name == p.name) return p.ct;
  return false;
}

PresetChoice choose_transfer_function_preset(const Volume& volume) {
  char range[96];
  std::snprintf(range, sizeof range, "values %g to %g", volume.value_range.x, volume.value_range.y);
  if (volume.value_range.x < -500.0f) {
    return {"ct-skin", std::string(range) + ": CT in Hounsfield units"};
  }
  return {"mr-head", std::string(range) + ": not Hounsfield units, taken as MR"};
}

}  // namespace strata
