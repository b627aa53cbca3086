#include "engine/core/image_atlas.h"

#include <algorithm>
#include <numeric>

#include "engine/core/error.h"

namespace strata {

namespace {

constexpr uint32_t kBorder = 1;
constexpr uint32_t kMinWidth = 256;
constexpr uint32_t kMaxSide = 4096;  // every Vulkan device's maxImageDimension2D is at least that

}  // namespace

ImageAtlas pack_image_atlas(std::span<const Rgba8Image> images) {
  ImageAtlas atlas;
  if (images.empty()) return atlas;
  uint32_t widest = 0;
  for (const Rgba8Image& image : images) widest = std::max(widest, image.width);
  atlas.width = std::max(kMinWidth, widest + 2 * kBorder);
  std::vector<size_t> order(images.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return images[a].height > images[b].height; });

  // Where each image's texels go (border excluded).
  std::vector<glm::uvec2> origins(images.size());
  glm::uvec2 cursor(0);
  uint32_t shelf_height = 0;
  for (const size_t i : order) {
    const glm::uvec2 outer(images[i].width + 2 * kBorder, images[i].height + 2 * kBorder);
    if (cursor.x + outer.x > atlas.width) cursor = {0, cursor.y + shelf_height}, shelf_height = 0;
    origins[i] = cursor + kBorder;
    cursor.x += outer.x;
    shelf_height = std::max(shelf_height, outer.y);
  }
  atlas.height = cursor.y + shelf_height;
  if (atlas.width > kMaxSide || atlas.height > kMaxSide) {
    throw Error("label images: " + std::to_string(images.size()) + " pictures need a " +
                std::to_string(atlas.width) + "x" + std::to_string(atlas.height) +
                " atlas (at most " + std::to_string(kMaxSide) + " a side): make them smaller");
  }

  atlas.texels.assign(size_t{atlas.width} * atlas.height * 4, 0);
  const glm::vec2 texel_size(1.0f / float(atlas.width), 1.0f / float(atlas.height));
  for (size_t i = 0; i < images.size(); ++i) {
    const Rgba8Image& image = images[i];
    const glm::ivec2 origin(origins[i]);
    // The image and its border: each border texel copies the nearest edge texel.
    for (int y = -int(kBorder); y < int(image.height + kBorder); ++y) {
      for (int x = -int(kBorder); x < int(image.width + kBorder); ++x) {
        const size_t from = (size_t(std::clamp(y, 0, int(image.height) - 1)) * image.width +
                             size_t(std::clamp(x, 0, int(image.width) - 1))) *
                            4;
        const size_t to = (size_t(origin.y + y) * atlas.width + size_t(origin.x + x)) * 4;
        std::copy_n(image.pixels.begin() + std::ptrdiff_t(from), 4,
                    atlas.texels.begin() + std::ptrdiff_t(to));
      }
    }
    const glm::vec2 lo = glm::vec2(origin) * texel_size;
    const glm::vec2 hi = glm::vec2(origin + glm::ivec2(image.width, image.height)) * texel_size;
    atlas.rects.emplace_back(lo, hi);
  }
  return atlas;
}

}  // namespace strata
