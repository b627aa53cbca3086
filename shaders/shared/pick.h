// Picking: the world point under a pixel where the frame's own walk (shared/resolve_walk.h: the
// same transfer functions, meshes and empty-space skipping) first took the accumulated alpha to
// depth_alpha, which the renderer records in its depth image. Written once for GLSL and C++: the
// GPU pass (pick.comp) and its CPU reference (pick_reference in passes/picking.cpp).
#ifndef STRATA_SHARED_PICK_H
#define STRATA_SHARED_PICK_H

#include "volume_render.h"

#define PICK_GROUP 64
#define PICK_MAX 256                // pixels one frame picks at most
#define PICK_BINDING_FRAME 0        // FrameGpu (uniform)
#define PICK_BINDING_DEPTH 1        // r32f image: eye depth, 0 where nothing passed depth_alpha
#define PICK_BINDING_PIXELS 2       // vec2[]: the pixels, in the depth image's pixel units
#define PICK_BINDING_POINTS 3       // vec4[]: world xyz, w 1 (a hit) or 0 (nothing there)

STRATA_BEGIN

struct PickParams {
  uint count;   // pixels to pick
  uint width;   // the depth image's size (the frame's own may be smaller: a low-resolution cast)
  uint height;
  uint pad;
};

// The pixel of the depth image that holds `pixel` (clamped to the image).
STRATA_INLINE ivec2 pick_texel(vec2 pixel, uint width, uint height) {
  return clamp(ivec2(floor(pixel)), ivec2(0), ivec2(int(width) - 1, int(height) - 1));
}

// The world point of a pick at depth-image texel t whose depth is `depth`: on the ray through the
// texel's centre (in the frame's own pixel units), or w = 0 where nothing was opaque enough.
STRATA_INLINE vec4 pick_point(FrameGpu f, ivec2 t, float depth, uint width, uint height) {
  if (!(depth > 0.0f)) return vec4(0.0f);
  vec2 scale = vec2(float(f.width) / float(width), float(f.height) / float(height));
  Ray ray = frame_pixel_ray(f, (vec2(t) + 0.5f) * scale);
  return vec4(ray.origin + ray.direction * depth, 1.0f);
}

STRATA_END

#endif
