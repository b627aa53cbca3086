// Transfer functions for a volume that comes without one: CT presets in Hounsfield units, MR
// presets relative to the scan's bright tissue (MR intensities have no absolute scale). Each is
// translucent enough that labels in deeper layers stay meaningful.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "engine/scene/scene.h"

namespace strata {

struct TransferFunctionPreset {
  const char* name;         // "ct-skin", ...
  const char* description;  // for --help and the viewer
  bool ct;                  // defined in Hounsfield units (else relative to bright tissue)
};

const std::vector<TransferFunctionPreset>& transfer_function_presets();

// The preset named `name` made for `volume`'s value range; an Error listing the names if there is
// no such preset.
TransferFunction make_transfer_function_preset(std::string_view name, const Volume& volume);

// The preset that suits the data, and why: CT when the values reach down to air in Hounsfield
// units (below -500; CT's air is -1000), else MR.
struct PresetChoice {
  std::string name;
  std::string reason;
};
PresetChoice choose_transfer_function_preset(const Volume& volume);

// A transfer function whose positions are the volume's own values (units "HU" or "raw") made one
// of 0..1 of `volume`'s value range, which the renderer takes.
TransferFunction in_value_range(const TransferFunction& in_values, const Volume& volume);

// The other way: a function in 0..1 of `volume`'s value range made one in its values, units "HU"
// where the values are Hounsfield units (choose_transfer_function_preset), else "raw"; what a
// scene file saves, so it shows the same tissue on another scan.
TransferFunction in_volume_values(const TransferFunction& in_range, const Volume& volume);

// Window and level in the volume's values: a grey ramp over [center - width / 2, center + width /
// 2], transparent black below it, opaque white above (units "raw"). In a volume rendering all
// above the ramp's start shows, so a bone window starts above soft tissue (HU: 900/1200, 300 to
// 1500), unlike radiology's slice windows (bone 400/1800 shows the skin).
TransferFunction window_transfer_function(float center, float width);

// Whether the preset named `name` is one for CT (false for an MR preset or no preset).
bool preset_is_ct(std::string_view name);

}  // namespace strata
