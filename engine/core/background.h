// What a picture shows where nothing of the scene or its labels covers it (--background): an opaque
// colour, or nothing (a PNG with alpha). The placement never sees it: it reads the scene over
// black, so a layout is the same on any background.
#pragma once

#include <glm/glm.hpp>

namespace strata {

struct Background {
  glm::vec3 color{0.0f};     // straight RGB in [0, 1]; unused when transparent
  bool transparent = false;  // the picture keeps its alpha (straight, not premultiplied)
};

// As the shaders take it (shaders/shared/background.h): the colour with a = 1, or all 0 for none.
inline glm::vec4 background_rgba(const Background& background) {
  return background.transparent ? glm::vec4(0.0f) : glm::vec4(background.color, 1.0f);
}

// Whether solid connectors get the dashed ones' dark halo: on a light background (or none, which
// any page may show through) a white line alone is lost. Black keeps the thesis's look.
inline bool connector_halos(const Background& background) {
  const float luminance = glm::dot(background.color, glm::vec3(0.2126f, 0.7152f, 0.0722f));
  return background.transparent || luminance > 0.5f;
}

}  // namespace strata
