// Picking: the world point under a pixel where the picture as drawn first becomes opaque enough.
// Where no ghosting lens opens the pixel that is the resolve's own depth (the depth image). In a
// lens the pixel's ray is walked again as the resolve walks it (shared/resolve_walk.h: the same
// transfer functions, meshes and empty-space skipping), with each layer kept as far as ghosting
// (shared/ghost.h) keeps it there, to the first eye depth where the drawn alpha reaches
// depth_alpha, from the first layer whose drawn alpha can reach it (pick_start); the keeps come from the labels' openings on each layer at the pixel and the
// layers' alphas there, as labels.ghost reads them from the layers image (ghost_keeps). Written
// once for GLSL and C++: the GPU pass (pick.comp) and its CPU reference (pick_reference in
// passes/picking.cpp, which takes the layers' alphas from its own walk: the same values in a frame
// cast at full size).
#ifndef STRATA_SHARED_PICK_H
#define STRATA_SHARED_PICK_H

#include "ghost.h"
#include "volume_render.h"

#define PICK_GROUP 64
#define PICK_MAX 256                 // pixels one frame picks at most
#define PICK_BINDING_PIXELS 14       // vec2[]: the pixels, in the labelled frame's pixel units
#define PICK_BINDING_POINTS 15       // vec4[]: world xyz, w 1 (a hit) or 0 (nothing there)
#define PICK_BINDING_LABELS 16       // LabelGpu[]: as labels.ghost reads them
#define PICK_BINDING_PLACEMENTS 17   // PlacementGpu[]: the drawn placements
#define PICK_BINDING_DEPTH 18        // r32f: the resolve's depth (the labelled frame's size)
#define PICK_BINDING_LAYERS 19       // rgba16f array: the layers before labels.ghost opens them
// (and the scene as the resolve binds it: VR_BINDING_FRAME, _VOLUMES, _KEYS, _PAYLOAD, _ATLAS,
// _TRANSFER and _OCCUPANCY)

STRATA_BEGIN

struct PickParams {
  uint count;  // pixels to pick
  uint pad0;
  uint pad1;
  uint pad2;
  // labels.ghost's parameters; width and height: the labelled frame's (the frame itself may be
  // cast smaller: interactive rendering); layer_count: unused (the frame's); label_count 0 or
  // strength 0: no ghosting
  GhostParams ghost;
};

// The labelled frame's pixel that holds `pixel` (clamped to the frame).
STRATA_INLINE ivec2 pick_texel(vec2 pixel, uint width, uint height) {
  return clamp(ivec2(floor(pixel)), ivec2(0), ivec2(int(width) - 1, int(height) - 1));
}

// The cast frame's pixel the upscale takes the labelled frame's pixel t's depth from
// (shared/upscale.h, upscale_nearest: every divisor-th pixel each way cast; the same pixel where
// both are the same size).
STRATA_INLINE ivec2 pick_cast_pixel(FrameGpu f, ivec2 t, uint width, uint height) {
  uvec2 divisor = (uvec2(width, height) + uvec2(f.width, f.height) - 1u) / uvec2(f.width, f.height);
  return ivec2(min(uvec2(t) / max(divisor, uvec2(1u)), uvec2(f.width, f.height) - 1u));
}

// A layer's alpha as the rgba16f layers image holds it, which is what labels.ghost reads.
STRATA_INLINE float pick_stored_alpha(float alpha) {
  return unpackHalf2x16(packHalf2x16(vec2(alpha, 0.0f))).x;
}

// Where a walk with ghosting's keeps starts (resolve_walk.h, VR_RESOLVE_LAYER_KEEP): the first
// layer whose drawn alpha at its end, from the layers' stored alphas, comes within PICK_START_MARGIN
// of depth_alpha (layer_count: none does, nothing to walk), and what the drawn layers in front of
// it let through. The layers in front cannot reach depth_alpha, so the walk need not sample them.
#define PICK_START_MARGIN 0.004f  // beyond rgba16f's rounding of the layers' alphas, summed
struct PickStart {
  uint layer;
  float clear;
};

STRATA_INLINE PickStart pick_start(GhostKeeps keeps, float alpha[VR_MAX_LAYERS], uint layer_count,
                                   float depth_alpha) {
  PickStart s;
  s.layer = layer_count;
  s.clear = 1.0f;
  for (uint l = 0u; l < layer_count; ++l) {
    float after = s.clear * (1.0f - keeps.layer[l] * alpha[l]);
    if (1.0f - after >= depth_alpha - PICK_START_MARGIN) {
      s.layer = l;
      return s;
    }
    s.clear = after;
  }
  return s;
}

// The world point of a pick at eye depth `depth` on the ray through the centre of the cast
// frame's pixel c, or w = 0 where nothing was opaque enough (depth 0).
STRATA_INLINE vec4 pick_point(FrameGpu f, ivec2 c, float depth) {
  if (!(depth > 0.0f)) return vec4(0.0f);
  Ray ray = frame_pixel_ray(f, vec2(c) + 0.5f);
  return vec4(ray.origin + ray.direction * depth, 1.0f);
}

STRATA_END

#endif
