// Interactive rendering on a slow device: while the camera moves the renderer casts rays for
// every `divisor`-th pixel each way only, into the top-left corner of its images, and this
// upscale fills the full images from them (bilinear for colours, nearest for depth), so the
// labels and everything after the renderer work at full resolution.
#ifndef STRATA_SHARED_UPSCALE_H
#define STRATA_SHARED_UPSCALE_H

#include "common.h"

#define UPSCALE_GROUP 8
#define UPSCALE_BINDING_LOW_LAYERS 0  // image2DArray rgba16f: the cast pixels, top left
#define UPSCALE_BINDING_LOW_FINAL 1   // image2D rgba8
#define UPSCALE_BINDING_LOW_DEPTH 2   // image2D r32f
#define UPSCALE_BINDING_LAYERS 3      // the full images
#define UPSCALE_BINDING_FINAL 4
#define UPSCALE_BINDING_DEPTH 5

STRATA_BEGIN

struct UpscaleParams {
  uvec2 size;  // the full images'
  uvec2 low;   // the cast pixels': ceil(size / divisor)
  uint divisor;
  uint layer_count;
};

// The cast pixels a full pixel is made of: the two corners of its bilinear cell (clamped to the
// cast pixels) and the weight of the second.
struct UpscaleTap {
  ivec2 p0;
  ivec2 p1;
  vec2 t;
};

STRATA_INLINE UpscaleTap upscale_tap(uvec2 pixel, UpscaleParams p) {
  vec2 at = (vec2(pixel) + vec2(0.5f)) / float(p.divisor) - vec2(0.5f);
  vec2 hi = vec2(p.low) - vec2(1.0f);
  at = clamp(at, vec2(0.0f), hi);
  UpscaleTap tap;
  tap.p0 = ivec2(floor(at));
  tap.p1 = ivec2(min(vec2(tap.p0) + vec2(1.0f), hi));
  tap.t = at - vec2(tap.p0);
  return tap;
}

// The cast pixel nearest to a full pixel (depth is not interpolated across edges).
STRATA_INLINE ivec2 upscale_nearest(uvec2 pixel, UpscaleParams p) {
  return ivec2(min(pixel / p.divisor, p.low - uvec2(1u)));
}

STRATA_END

#endif
