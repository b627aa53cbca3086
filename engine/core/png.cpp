#include "engine/core/png.h"

#include <stb_image.h>
#include <stb_image_write.h>

#include "engine/core/error.h"

namespace strata {

void write_png(const std::string& path, uint32_t width, uint32_t height,
               std::span<const uint8_t> rgba) {
  if (rgba.size() != size_t{width} * height * 4) {
    throw Error(path + ": " + std::to_string(rgba.size()) + " bytes is not a " +
                std::to_string(width) + "x" + std::to_string(height) + " rgba8 image");
  }
  if (!stbi_write_png(path.c_str(), static_cast<int>(width), static_cast<int>(height), 4,
                      rgba.data(), static_cast<int>(width * 4))) {
    throw Error(path + ": cannot write PNG (does the folder exist and is it writable?)");
  }
}

Rgba8Image read_png(const std::string& path) {
  int w = 0, h = 0, channels = 0;
  stbi_uc* data = stbi_load(path.c_str(), &w, &h, &channels, 4);
  if (!data) throw Error(path + ": cannot read PNG: " + stbi_failure_reason());
  Rgba8Image image{static_cast<uint32_t>(w), static_cast<uint32_t>(h),
                   std::vector<uint8_t>(data, data + size_t(w) * h * 4)};
  stbi_image_free(data);
  return image;
}

}  // namespace strata
