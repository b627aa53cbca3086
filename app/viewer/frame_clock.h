// The viewer's clock and what counts as a camera move (its files share them).
#pragma once

#include <chrono>

#include "engine/scene/camera.h"

namespace strata::app {

using Clock = std::chrono::steady_clock;

inline double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

inline bool same_view(const Camera& a, const Camera& b) {
  return a.view == b.view;
}

}  // namespace strata::app
