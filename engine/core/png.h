#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace strata {

// Writes tightly packed rgba8 pixels; throws Error naming the file when it cannot.
void write_png(const std::string& path, uint32_t width, uint32_t height,
               std::span<const uint8_t> rgba);

struct Rgba8Image {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<uint8_t> pixels;
};

// Reads any PNG as rgba8; throws Error naming the file and stb's reason.
Rgba8Image read_png(const std::string& path);

}  // namespace strata
