// Labels on the GPU: per-frame label data (uploaded by the placement driver each frame), the
// placement result per label, and the glyphs of their text. Written once for C++ and GLSL.
#ifndef STRATA_SHARED_LABELS_H
#define STRATA_SHARED_LABELS_H

#include "common.h"

// Labels a frame can have: placement's pair regions grow with its square (see
// placement_pair_slot), the tidy-up's and the label drawing's per-label arrays with it.
#define LABEL_MAX 4096

// LabelGpu.flags
#define LABEL_ENABLED 1u   // the anchor is in view and in front of the camera: place and draw it
#define LABEL_INTERNAL 2u  // internal labelling: the label is drawn centred on its anchor

// PlacementGpu.shown
#define PLACEMENT_HIDDEN 0u  // not placed (disabled, or no allowed position in hard mode)
#define PLACEMENT_SHOWN 1u

STRATA_BEGIN

struct LabelGpu {
  vec2 anchor;         // pixels, x right, y down (pixel centres at +0.5)
  vec2 size;           // label box width and height in pixels
  vec2 previous;       // the label's position in the previous frame (box centre, pixels)
  float anchor_depth;  // eye depth of the anchor
  uint layer;          // depth layer the label is placed and drawn on
  uint flags;          // LABEL_*
  uint glyph_first;    // the label's glyphs in the glyph buffer
  uint glyph_count;
  float hold;        // eq. 3.1 adds this to every position but `held`: a label moves only for
                     // a position better by more (0: no held position)
  vec2 held;         // the position the label was heading for in the previous frame (box
                     // centre, pixels)
  float padding;     // pixels added to the constraint margin around this label's box (hard
                     // mode: a label needs a larger clear zone to appear than to stay)
  uint image_quads;  // 1: the quad after the label's glyphs is its picture, in the image atlas
};

// The result for one label: written by the placement, read by drawing and by the host.
struct PlacementGpu {
  vec2 position;                       // box centre, pixels
  float cost;                          // eq. 3.1 at that position
  uint shown;                          // PLACEMENT_*
  float opacity STRATA_DEFAULT(1.0f);  // 1 when shown; between 0 and 1 while fading in or out
  uint pad STRATA_DEFAULT(0u);
};

// A glyph's quad, or a label picture's (LabelGpu::image_quads).
struct GlyphGpu {
  vec4 atlas;  // u0, v0, u1, v1 in the font atlas, or the image atlas (normalised)
  vec4 box;    // x0, y0, x1, y1 in pixels relative to the label box's top-left corner
};
STRATA_END

#endif
