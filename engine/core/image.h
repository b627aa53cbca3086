// Pictures for labels: PNG or JPEG files read as rgba8, and resampled to the size a label shows
// them at; and rendered images written as PNG or JPEG.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>

#include "engine/core/png.h"

namespace strata {

// Neither side of a picture may be longer (a label shows it some tens of pixels high; this only
// keeps a mistaken file from taking gigabytes).
inline constexpr uint32_t kMaxImageSide = 8192;

// A PNG (stb_image) or JPEG (libjpeg-turbo) file, told apart by its first bytes, as straight-alpha
// rgba8. Throws Error "<file>: <reason>" for a missing file, another format, a corrupt or
// truncated file, or a side over kMaxImageSide.
Rgba8Image read_image(const std::filesystem::path& path);

// rgba8 pixels as PNG (.png) or JPEG (.jpg, .jpeg; quality 92, alpha dropped), by the file's
// extension, case-insensitive; PNG into a device or pipe (/dev/null). Throws Error "<file>:
// <reason>" for another extension or a file that cannot be written.
void write_image(const std::filesystem::path& path, uint32_t width, uint32_t height,
                 std::span<const uint8_t> rgba);
// Whether write_image writes `path`; else an Error naming the extensions (checked before a
// long render, so a typo costs no time).
void check_image_extension(const std::filesystem::path& path);
// Whether write_image keeps alpha in `path` (PNG: yes; JPEG: no). Throws as check_image_extension.
bool image_keeps_alpha(const std::filesystem::path& path);

// `image` (straight alpha) resampled to width x height, premultiplied: a triangle filter as wide
// as one source texel or one target pixel, whichever is larger (bilinear when enlarging, an
// average over each pixel's footprint when shrinking).
Rgba8Image resized_premultiplied(const Rgba8Image& image, uint32_t width, uint32_t height);

}  // namespace strata
