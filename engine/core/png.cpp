#include "engine/core/png.h"

#include <vector>

#include <stb_image.h>
#include <stb_image_write.h>

#include "engine/core/atomic_file.h"
#include "engine/core/error.h"

namespace strata {

std::vector<uint8_t> encode_png(uint32_t width, uint32_t height, std::span<const uint8_t> rgba) {
  if (rgba.size() != size_t{width} * height * 4) {
    throw Error(std::to_string(rgba.size()) + " bytes is not a " + std::to_string(width) + "x" +
                std::to_string(height) + " rgba8 image");
  }
  std::vector<uint8_t> encoded;
  if (!stbi_write_png_to_func(append_encoded, &encoded, static_cast<int>(width),
                              static_cast<int>(height), 4, rgba.data(),
                              static_cast<int>(width * 4))) {
    throw Error("cannot encode PNG");
  }
  return encoded;
}

void write_png(const std::string& path, uint32_t width, uint32_t height,
               std::span<const uint8_t> rgba) {
  // Encoded in memory, then written whole or not at all (atomic_file.h): stb's own file writer
  // ignores failed writes (a full disk would leave a cut file and a "wrote" message).
  std::vector<uint8_t> encoded;
  try {
    encoded = encode_png(width, height, rgba);
  } catch (const Error& e) {
    throw Error(path + ": " + e.what());
  }
  write_file_checked(path, encoded, "PNG");
}

void append_encoded(void* bytes, void* data, int size) {
  auto* out = static_cast<std::vector<uint8_t>*>(bytes);
  out->insert(out->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
}

void write_file_checked(const std::string& path, std::span<const uint8_t> bytes, const char* what) {
  write_file_atomically(path, {reinterpret_cast<const char*>(bytes.data()), bytes.size()}, what);
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
