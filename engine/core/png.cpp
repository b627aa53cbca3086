#include "engine/core/png.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

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
  // Encoded in memory, then written and closed with every error checked: stb's own file writer
  // ignores failed writes (a full disk would leave a cut file and a "wrote" message).
  std::vector<uint8_t> encoded;
  if (!stbi_write_png_to_func(append_encoded, &encoded, static_cast<int>(width),
                              static_cast<int>(height), 4, rgba.data(),
                              static_cast<int>(width * 4))) {
    throw Error(path + ": cannot encode PNG");
  }
  write_file_checked(path, encoded, "PNG");
}

void append_encoded(void* bytes, void* data, int size) {
  auto* out = static_cast<std::vector<uint8_t>*>(bytes);
  out->insert(out->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
}

void write_file_checked(const std::string& path, std::span<const uint8_t> bytes, const char* what) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) {
    throw Error(path + ": cannot write " + what + ": " + std::strerror(errno) +
                " (does the folder exist and is it writable?)");
  }
  const size_t written = std::fwrite(bytes.data(), 1, bytes.size(), file);
  const int write_error = written == bytes.size() ? 0 : errno;
  const int close_error = std::fclose(file) == 0 ? 0 : errno;
  if (write_error != 0 || close_error != 0 || written != bytes.size()) {
    const int error = write_error != 0 ? write_error : close_error;
    throw Error(path + ": cannot write " + what + ": " +
                (error != 0 ? std::strerror(error) : "short write"));
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
