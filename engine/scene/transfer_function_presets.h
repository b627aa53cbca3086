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

// Whether the preset named `name` is one for CT (false for an MR preset or no preset).
bool preset_is_ct(std::string_view name);

}  // namespace strata
