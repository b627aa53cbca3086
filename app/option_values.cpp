// Option values the commands share the reading of: lists of numbers, sizes, windows, backgrounds
// and camera positions, each refused as a usage error that names the option.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "app/commands.h"
#include "labeling/camera_path.h"

namespace strata::app {

std::vector<float> parse_numbers(const std::string& text, size_t count, const char* option,
                                 const char* form) {
  std::vector<float> out;
  size_t start = 0;
  for (;;) {
    const size_t comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? comma : comma - start);
    char* end = nullptr;
    const float v = std::strtof(part.c_str(), &end);
    if (part.empty() || end != part.c_str() + part.size() || !(std::abs(v) <= 1e9f)) break;
    out.push_back(v);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (out.size() != count || std::count(text.begin(), text.end(), ',') != std::ptrdiff_t(count - 1))
    throw UsageError(std::string(option) + ": '" + text + "' is not " + form);
  return out;
}

glm::vec2 parse_window(const std::string& text) {
  const char* form =
      "CENTER,WIDTH (the volume's values, a ramp from CENTER - WIDTH/2 to CENTER + WIDTH/2; in HU "
      "e.g. 900,1200 for bone alone or 40,400 for the skin; width > 0)";
  const std::vector<float> v = parse_numbers(text, 2, "--window", form);
  if (!(v[1] > 0.0f)) throw UsageError("--window: '" + text + "' is not " + form);
  return {v[0], v[1]};
}

Camera option_camera(const Scene& scene, const std::string& name, const char* option) {
  try {
    return camera_position(scene, name);
  } catch (const Error& e) {
    throw UsageError(std::string(option) + ": " + e.what());
  }
}

Background parse_background(const std::string& text) {
  if (text == "black") return {};
  if (text == "white") return {glm::vec3(1.0f)};
  if (text == "transparent") return {glm::vec3(0.0f), true};
  const bool hex = text.size() == 7 && text[0] == '#' &&
                   std::all_of(text.begin() + 1, text.end(),
                               [](char c) { return std::isxdigit(static_cast<unsigned char>(c)); });
  if (!hex) {
    throw UsageError("--background: '" + text +
                     "' is not a background (black, white, transparent or #rrggbb)");
  }
  const unsigned long rgb = std::stoul(text.substr(1), nullptr, 16);
  return {glm::vec3(float((rgb >> 16) & 255u), float((rgb >> 8) & 255u), float(rgb & 255u)) /
          255.0f};
}

graph::Extent parse_size(const std::string& text, const char* option) {
  unsigned w = 0, h = 0;
  char x = 0, extra = 0;
  const int n = std::sscanf(text.c_str(), "%u%c%u%c", &w, &x, &h, &extra);
  if (n == 1) h = w;
  if ((n != 1 && !(n == 3 && x == 'x')) || w == 0 || h == 0 || w > 16384 || h > 16384) {
    throw UsageError(std::string(option) + ": '" + text + "' is not a size (N or WxH, 1 to 16384)");
  }
  return {w, h};
}

void check_image_size(const Context& ctx, graph::Extent size, const char* option) {
  const uint32_t limit = ctx.properties().limits.maxImageDimension2D;
  if (size.width > limit || size.height > limit) {
    throw UsageError(std::string(option) + ": " + std::to_string(size.width) + "x" +
                     std::to_string(size.height) + " is larger than the device's " +
                     std::to_string(limit) + " pixels a side (maxImageDimension2D)");
  }
}

}  // namespace strata::app
