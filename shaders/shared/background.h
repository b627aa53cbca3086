// The picture's background (engine/core/background.h) under the layers' composite, written once
// for the resolve's final image, the label composite and their CPU references.
#ifndef STRATA_SHARED_BACKGROUND_H
#define STRATA_SHARED_BACKGROUND_H

#include "common.h"

STRATA_BEGIN

// `layers`: premultiplied, composited front to back; `background`: an opaque colour (a = 1) or
// none (all 0). Premultiplied, and exactly opaque over a colour.
STRATA_INLINE vec4 over_background(vec4 layers, vec4 background) {
  if (background.a > 0.0f) return vec4(vec3(layers) + (1.0f - layers.a) * vec3(background), 1.0f);
  return layers;
}

// A pixel as the picture stores it: straight alpha. The colour is divided by its alpha before it
// is rounded to 8 bits, so a soft edge keeps its colour instead of darkening toward black.
STRATA_INLINE vec4 straight_alpha(vec4 c) {
  return c.a > 0.0f ? vec4(vec3(c) / c.a, c.a) : vec4(0.0f);
}

STRATA_END

#endif
