#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "app/commands.h"

namespace strata::app {
namespace {

std::string number_text(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

CLI::Validator range_check(double lo, double hi, bool open_low, bool whole) {
  const std::string range = (open_low ? "(" : "[") + number_text(lo) + ", " + number_text(hi) + "]";
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
