// Label pictures packed into one rgba8 texture for the label drawing (passes/label_drawing.h), as
// the glyphs are into the font atlas.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "engine/core/png.h"

namespace strata {

struct ImageAtlas {
  uint32_t width = 1;
  uint32_t height = 1;
  std::vector<uint8_t> texels = std::vector<uint8_t>(4, 0);  // rgba8 premultiplied, row-major
  std::vector<glm::vec4> rects;  // per image: u0, v0, u1, v1 of its texels (normalised)
};

// Shelf packing, tallest first. Each image keeps a border of copies of its edge texels, so that
// bilinear filtering up to its edge reads only its own texels. `images` are premultiplied and
// already at the size they are drawn (resized_premultiplied): the drawing reads them a texel per
// pixel. No images: a 1x1 transparent atlas.
ImageAtlas pack_image_atlas(std::span<const Rgba8Image> images);

}  // namespace strata
