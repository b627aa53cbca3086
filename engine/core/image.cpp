#include "engine/core/image.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <string>
#include <vector>

#include <jpeglib.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include "engine/core/error.h"
#include "engine/core/text_file.h"

namespace strata {

namespace {

bool starts_with(const std::string& bytes, std::string_view signature) {
  return bytes.size() >= signature.size() && bytes.compare(0, signature.size(), signature) == 0;
}

void check_size(uint64_t width, uint64_t height) {
  if (width == 0 || height == 0 || width > kMaxImageSide || height > kMaxImageSide) {
    throw Error(std::to_string(width) + "x" + std::to_string(height) + " pixels (expected 1 to " +
                std::to_string(kMaxImageSide) + " a side)");
  }
}

Rgba8Image decode_png(const std::string& bytes) {
  int w = 0, h = 0, channels = 0;
  const auto* data = reinterpret_cast<const stbi_uc*>(bytes.data());
  if (!stbi_info_from_memory(data, int(bytes.size()), &w, &h, &channels)) {
    throw Error(std::string("corrupt PNG: ") + stbi_failure_reason());
  }
  check_size(uint64_t(w), uint64_t(h));
  stbi_uc* pixels = stbi_load_from_memory(data, int(bytes.size()), &w, &h, &channels, 4);
  if (!pixels) throw Error(std::string("corrupt PNG: ") + stbi_failure_reason());
  Rgba8Image image{uint32_t(w), uint32_t(h),
                   std::vector<uint8_t>(pixels, pixels + size_t(w) * size_t(h) * 4)};
  stbi_image_free(pixels);
  return image;
}

// libjpeg reports errors by calling error_exit, which must not return: it jumps back to
// decode_jpeg. A warning (a truncated file, corrupt data libjpeg would fill with grey) is an error
// too: a label's picture half grey is worse than a message.
struct JpegErrors {
  jpeg_error_mgr manager;
  std::jmp_buf jump;
  std::array<char, JMSG_LENGTH_MAX + 64> message;
};

[[noreturn]] void jpeg_fail(j_common_ptr info) {
  auto* errors = reinterpret_cast<JpegErrors*>(info->err);
  std::array<char, JMSG_LENGTH_MAX> reason{};
  (*info->err->format_message)(info, reason.data());
  std::snprintf(errors->message.data(), errors->message.size(), "corrupt JPEG: %s", reason.data());
  std::longjmp(errors->jump, 1);
}

void jpeg_message(j_common_ptr info, int level) {
  if (level < 0) jpeg_fail(info);
}

// Decodes into `image`; false with errors.message set when libjpeg fails. No object with a
// destructor lives in this frame, so the long jump skips none.
bool decode_jpeg(const std::string& bytes, Rgba8Image& image, JpegErrors& errors) {
  jpeg_decompress_struct info{};
  info.err = jpeg_std_error(&errors.manager);
  errors.manager.error_exit = jpeg_fail;
  errors.manager.emit_message = jpeg_message;
  if (setjmp(errors.jump)) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  jpeg_create_decompress(&info);
  jpeg_mem_src(&info, reinterpret_cast<const unsigned char*>(bytes.data()),
               static_cast<unsigned long>(bytes.size()));
  jpeg_read_header(&info, TRUE);
  if (info.image_width == 0 || info.image_height == 0 || info.image_width > kMaxImageSide ||
      info.image_height > kMaxImageSide) {
    std::snprintf(errors.message.data(), errors.message.size(),
                  "%ux%u pixels (expected 1 to %u a side)", unsigned(info.image_width),
                  unsigned(info.image_height), unsigned(kMaxImageSide));
    jpeg_destroy_decompress(&info);
    return false;
  }
  info.out_color_space = JCS_EXT_RGBA;  // (libjpeg-turbo: grey and YCbCr to rgba8 alike)
  jpeg_start_decompress(&info);
  image.width = info.output_width;
  image.height = info.output_height;
  image.pixels.resize(size_t{image.width} * image.height * 4);
  while (info.output_scanline < info.output_height) {
    JSAMPROW row = image.pixels.data() + size_t{info.output_scanline} * image.width * 4;
    jpeg_read_scanlines(&info, &row, 1);
  }
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  return true;
}

}  // namespace

Rgba8Image read_image(const std::filesystem::path& path) {
  const std::string bytes = read_file_bytes(path);
  try {
    if (starts_with(bytes, "\x89PNG\r\n\x1a\n")) return decode_png(bytes);
    if (starts_with(bytes, "\xFF\xD8\xFF")) {
      Rgba8Image image;
      JpegErrors errors{};
      if (!decode_jpeg(bytes, image, errors)) throw Error(errors.message.data());
      return image;
    }
  } catch (const Error& e) {
    throw Error(path.string() + ": " + e.what());
  }
  throw Error(path.string() + ": not a PNG or JPEG file");
}

namespace {

enum class ImageFormat { png, jpeg };

ImageFormat image_format(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (extension == ".png") return ImageFormat::png;
  if (extension == ".jpg" || extension == ".jpeg") return ImageFormat::jpeg;
  // A device or pipe (-o /dev/null: render, but keep nothing) takes the PNG.
  std::error_code error;
  const auto type = std::filesystem::status(path, error).type();
  if (type == std::filesystem::file_type::character || type == std::filesystem::file_type::fifo)
    return ImageFormat::png;
  throw Error(path.string() + ": cannot write images as '" + extension +
              "' (the extension must be .png, .jpg or .jpeg)");
}

}  // namespace

void check_image_extension(const std::filesystem::path& path) {
  image_format(path);
}

bool image_keeps_alpha(const std::filesystem::path& path) {
  return image_format(path) == ImageFormat::png;
}

void write_image(const std::filesystem::path& path, uint32_t width, uint32_t height,
                 std::span<const uint8_t> rgba) {
  if (image_format(path) == ImageFormat::png) {
    write_png(path.string(), width, height, rgba);
    return;
  }
  if (rgba.size() != size_t{width} * height * 4) {
    throw Error(path.string() + ": " + std::to_string(rgba.size()) + " bytes is not a " +
                std::to_string(width) + "x" + std::to_string(height) + " rgba8 image");
  }
  std::vector<uint8_t> rgb(size_t{width} * height * 3);
  for (size_t p = 0; p < size_t{width} * height; ++p) {
    for (int c = 0; c < 3; ++c) rgb[p * 3 + c] = rgba[p * 4 + c];
  }
  constexpr int kQuality = 92;
  std::vector<uint8_t> encoded;
  if (!stbi_write_jpg_to_func(append_encoded, &encoded, int(width), int(height), 3, rgb.data(),
                              kQuality)) {
    throw Error(path.string() + ": cannot encode JPEG");
  }
  write_file_checked(path.string(), encoded, "JPEG");
}

namespace {

// Per target pixel along one axis: the source texels it reads and their weights (summing to 1),
// texels past the edge clamped to it.
struct Tap {
  uint32_t texel;
  float weight;
};

std::vector<std::vector<Tap>> triangle_taps(uint32_t source, uint32_t target) {
  const float scale = float(source) / float(target);
  const float radius = std::max(1.0f, scale);
  std::vector<std::vector<Tap>> taps(target);
  for (uint32_t i = 0; i < target; ++i) {
    const float centre = (float(i) + 0.5f) * scale;
    float sum = 0.0f;
    for (int j = int(std::floor(centre - radius)); j <= int(std::ceil(centre + radius)); ++j) {
      const float w = 1.0f - std::abs(float(j) + 0.5f - centre) / radius;
      if (w <= 0.0f) continue;
      taps[i].push_back({uint32_t(std::clamp(j, 0, int(source) - 1)), w});
      sum += w;
    }
    for (Tap& t : taps[i]) t.weight /= sum;
  }
  return taps;
}

}  // namespace

Rgba8Image resized_premultiplied(const Rgba8Image& image, uint32_t width, uint32_t height) {
  if (image.width == 0 || image.height == 0 || width == 0 || height == 0) {
    throw Error("resized_premultiplied: empty image or size");
  }
  std::vector<float> premultiplied(image.pixels.size());
  for (size_t p = 0; p < image.pixels.size(); p += 4) {
    const float a = float(image.pixels[p + 3]) / 255.0f;
    for (size_t c = 0; c < 3; ++c) premultiplied[p + c] = float(image.pixels[p + c]) / 255.0f * a;
    premultiplied[p + 3] = a;
  }
  // Rows first (source height x target width), then columns.
  const auto across = triangle_taps(image.width, width);
  std::vector<float> rows(size_t{image.height} * width * 4, 0.0f);
  for (uint32_t y = 0; y < image.height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      for (const Tap& t : across[x]) {
        for (size_t c = 0; c < 4; ++c) {
          rows[(size_t{y} * width + x) * 4 + c] +=
              t.weight * premultiplied[(size_t{y} * image.width + t.texel) * 4 + c];
        }
      }
    }
  }
  const auto down = triangle_taps(image.height, height);
  Rgba8Image out{width, height, std::vector<uint8_t>(size_t{width} * height * 4)};
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      for (size_t c = 0; c < 4; ++c) {
        float v = 0.0f;
        for (const Tap& t : down[y]) v += t.weight * rows[(size_t{t.texel} * width + x) * 4 + c];
        out.pixels[(size_t{y} * width + x) * 4 + c] =
            static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
      }
    }
  }
  return out;
}

}  // namespace strata
