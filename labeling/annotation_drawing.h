// A picture's title and legend (labeling/annotations.h) drawn over an RGBA8 picture on the CPU:
// the boxes as label boxes are drawn (shaders/shared/label_drawing.h's label_frame), the swatches,
// then the text from the fonts' glyph coverage. Stills and video frames get them after they are
// read back, so the GPU's frame is the same with or without them.
#pragma once

#include <cstdint>
#include <span>

#include <glm/glm.hpp>

#include "labeling/annotations.h"

namespace strata {

// `layout` drawn over `rgba` (straight alpha, row-major, size.x * size.y pixels), its text set in
// `fonts` (the ones it was laid out with). Drawing outside the picture is cut.
void draw_annotations(std::span<uint8_t> rgba, glm::uvec2 size, const AnnotationLayout& layout,
                      const AnnotationFonts& fonts);

}  // namespace strata
