#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace strata {

// Writes `bytes` to the file whole or not at all (atomic_file.h); throws Error "<file>: cannot
// write <what>: <reason>".
void write_file_checked(const std::string& path, std::span<const uint8_t> bytes, const char* what);
// stb's write callback: appends to the std::vector<uint8_t> at `bytes`.
void append_encoded(void* bytes, void* data, int size);

// Tightly packed rgba8 pixels as a PNG file's bytes; throws Error when the size is wrong.
std::vector<uint8_t> encode_png(uint32_t width, uint32_t height, std::span<const uint8_t> rgba);

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
