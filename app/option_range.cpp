#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "app/commands.h"
#include "engine/scene/value_limits.h"

namespace strata::app {
namespace {

CLI::Validator range_check(double lo, double hi, bool open_low, bool whole) {
  const std::string range =
      (open_low ? "(" : "[") + value_limits::shown(lo) + ", " + value_limits::shown(hi) + "]";
  const std::string kind = whole ? "a whole number" : "a number";
  auto check = [=](std::string& input) -> std::string {
    const char* begin = input.c_str();
    char* end = nullptr;
    const double v = input.empty() ? NAN : std::strtod(begin, &end);
    const bool read = !input.empty() && end == begin + input.size();
    const bool inside = read && std::isfinite(v) && (open_low ? v > lo : v >= lo) && v <= hi &&
                        (!whole || v == std::floor(v));
    if (inside) return {};
    return (input.empty() ? "''" : input) + " is not " + kind + " in " + range;
  };
  return CLI::Validator(check, (whole ? "INTEGER in " : "NUMBER in ") + range);
}

}  // namespace

CLI::Validator finite_range(double lo, double hi, bool open_low) {
  return range_check(lo, hi, open_low, false);
}

CLI::Validator whole_range(double lo, double hi) {
  return range_check(lo, hi, false, true);
}

}  // namespace strata::app
