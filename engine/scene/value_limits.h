// The numbers a scene may hold and still make a meaningful picture. A float holds 3e38, but a
// volume with 3e38 mm between voxels has infinite bounds, and an anchor 3e38 mm away gives a
// camera at NaN. These limits are far outside what real data holds (a spacing of 1 nm is electron
// microscopy, 10 m a voxel is no medical image; a whole body is 2 m long), so a value outside them
// is a broken or wrongly scaled file: every reader refuses it, naming the file and the field.
// docs/scene-format.md ("Limits") lists them.
#pragma once

#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include <glm/glm.hpp>

namespace strata::value_limits {

inline constexpr double kMinSpacingMm = 1e-6;
inline constexpr double kMaxSpacingMm = 1e4;
// Volume origins (and so a transform's result), label anchors and eyes: 1 km from the origin.
inline constexpr double kMaxCoordinateMm = 1e6;
// What is derived from them (a volume's far corner, a mesh after its transform, the scene's box).
inline constexpr double kMaxSceneCoordinateMm = 1e7;
// A voxel must span this many steps of a float at its position: a volume 1e6 mm from the origin
// with 1e-3 mm voxels would put all of them on a few float values (float resolves 0.06 mm there).
inline constexpr double kMinFloatStepsPerVoxel = 8.0;

inline constexpr double kMinFovDegrees = 0.1;
inline constexpr double kMaxFovDegrees = 179.0;
inline constexpr double kMaxFarMm = 1e9;
// The projection is a float matrix; its element f / (n - f) rounds to -1 once f / n nears 2^24
// (1.7e7), and the renderer's rays through the far plane (the inverse projection at depth 1)
// become 0 / 0. 1e6 keeps four bits of that element's precision to spare.
inline constexpr double kMaxFarNearRatio = 1e6;

// A number as messages show it (%g: 3e+38, 1e-06, 10000).
inline std::string shown(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// "spacing 3e+38 mm is outside 1e-06..10000", or nothing when the spacing is plausible.
inline std::optional<std::string> spacing_problem(double spacing) {
  // (as floats: a file's float 1e-6 is 9.99999997e-07)
  if (spacing >= double(float(kMinSpacingMm)) && spacing <= kMaxSpacingMm) return std::nullopt;
  return "spacing " + shown(spacing) + " mm is outside " + shown(kMinSpacingMm) + ".." +
         shown(kMaxSpacingMm);
}

// "<what> 0 0 3e+38 mm is outside -1e+06..1e+06" (per coordinate), or nothing.
inline std::optional<std::string> position_problem(std::string_view what, glm::dvec3 p,
                                                   double limit = kMaxCoordinateMm) {
  for (int axis = 0; axis < 3; ++axis) {
    if (std::fabs(p[axis]) <= limit) continue;
    return std::string(what) + " " + shown(p.x) + " " + shown(p.y) + " " + shown(p.z) +
           " mm is outside " + shown(-limit) + ".." + shown(limit);
  }
  return std::nullopt;
}

}  // namespace strata::value_limits
