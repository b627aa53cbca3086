// The viewer's debug views (the thesis program's --show-buffers): one of the frame's internal
// buffers as an rgba8 image, chosen when the frame is recorded. Written once for C++ and GLSL:
// the first part (constants, bindings, colour maps) is an ordinary shared header; the second,
// compiled when the includer defines DEBUG_VIEW_PIXEL before including this header a second
// time, is the per-pixel view that debug_view.comp and the CPU reference
// (passes/debug_view.cpp) both run.
#ifndef STRATA_SHARED_DEBUG_VIEW_H
#define STRATA_SHARED_DEBUG_VIEW_H

#include "placement.h"
#include "volume_render.h"

#define DEBUG_VIEW_GROUP 16  // 16 x 16 pixels per workgroup

// DebugViewParams.mode
#define DEBUG_MODE_SALIENCY 0u     // the placement's saliency (eq. 3.5), grey
#define DEBUG_MODE_COSTS 1u        // one layer's integral costs (eq. 3.3/3.4), heat ramp
#define DEBUG_MODE_CONSTRAINTS 2u  // one label's constraint image (thesis 4.1.1)
#define DEBUG_MODE_LAYER 3u        // one depth layer over a checkerboard
#define DEBUG_MODE_FRAGMENTS 4u    // the HA-Buffer's fragments per pixel, heat ramp

#define DEBUG_VIEW_BINDING_OUTPUT 0      // rgba8 image, written
#define DEBUG_VIEW_BINDING_SALIENCY 1    // float per pixel
#define DEBUG_VIEW_BINDING_COSTS 2       // float per layer per pixel: costs[layer][y][x]
#define DEBUG_VIEW_BINDING_LABELS 3      // LabelGpu[]
#define DEBUG_VIEW_BINDING_PLACEMENTS 4  // PlacementGpu[], one per label
#define DEBUG_VIEW_BINDING_ORDER 5       // uint[]: label indices in insertion order
#define DEBUG_VIEW_BINDING_LAYERS 6      // rgba16f array image, premultiplied
#define DEBUG_VIEW_BINDING_FRAME 7       // FrameGpu (uniform): the HA-Buffer's slot count
#define DEBUG_VIEW_BINDING_KEYS 8        // the HA-Buffer's 64-bit keys, as uvec2 (low, high word)

#define DEBUG_VIEW_CHECKER 8             // checkerboard squares behind a layer, pixels
#define DEBUG_NOT_CANDIDATE 0xFFFFFFFFu  // constraints: the label's box cannot be there
#define DEBUG_NO_BUDGET 3.0e38f          // constraint_bits: find every bit

STRATA_BEGIN

struct DebugViewParams {
  uint width;
  uint height;
  uint mode;         // DEBUG_MODE_*
  uint layer;        // costs, layer: the depth layer (the last one if past it)
  uint label;        // constraints: the label, an index into the labels buffer
  uint layer_count;  // at least 1
  uint label_count;  // entries of the labels and placements buffers
  uint order_count;  // entries of the order buffer this frame
  float scale;       // saliency, costs, fragments: value times scale, clamped to [0, 1], is shown
  float margin;      // constraints: PlacementSettings::margin
};

// Black, red, yellow, white over t in [0, 1] (a black-body ramp: 0 stays black).
STRATA_INLINE vec3 debug_heat(float t) {
  float s = 3.0f * clamp(t, 0.0f, 1.0f);
  return clamp(vec3(s, s - 1.0f, s - 2.0f), vec3(0.0f), vec3(1.0f));
}

STRATA_INLINE vec3 debug_checker(uvec2 p) {
  uvec2 square = p / uvec2(DEBUG_VIEW_CHECKER);
  return vec3(((square.x + square.y) & 1u) == 0u ? 0.4f : 0.6f);
}

// A constraint image pixel: black where the label cannot be (DEBUG_NOT_CANDIDATE), dark grey
// where nothing constrains it, else red for a placed label's shadow, green for a placed
// connector's, blue for a covered anchor, added (yellow: both shadows).
STRATA_INLINE vec3 debug_constraint_colour(uint bits) {
  if (bits == DEBUG_NOT_CANDIDATE) return vec3(0.0f);
  if (bits == 0u) return vec3(0.25f);
  return vec3((bits & CONSTRAINT_LABEL) != 0u ? 1.0f : 0.0f,
              (bits & CONSTRAINT_CONNECTOR) != 0u ? 1.0f : 0.0f,
              (bits & CONSTRAINT_ANCHOR) != 0u ? 1.0f : 0.0f);
}

// The HA-Buffer's slot of (pixel, age): habuffer.glsl's habuffer_slot, which is GLSL only.
STRATA_INLINE uint debug_habuffer_slot(uint pixel, uint age, uint table_size) {
  return (pixel + age * 0x9E3779B1u) % table_size;
}

STRATA_END

#endif

#ifdef DEBUG_VIEW_PIXEL
// The view's pixel. What the includer provides (the shader from its bindings, the CPU reference
// from spans, as members of the struct it includes this in) is debug_view_access.h; it calls
// view_setup() before debug_view_pixel().
#ifndef __cplusplus
#include "debug_view_access.h"  // (C++: the reference's struct is checked against it)
#endif

// The constraint image is the placement's own code (placement_cost.h) with what that expects of
// its includer made from the labels, placements and order buffers: the picked label against
// every label before it in the order, at the positions they were placed at, and every enabled
// label's anchor, exactly as place_label.comp tests each candidate of that label.
PlacementParams params;  // what placement_cost.h reads: the viewport, the margin, three weights
LabelGpu view_label;     // the picked label ...
uint view_position;      // ... and its order position (order_count: not in the order)

uint placed_count() {
  return view_position;
}
#ifndef __cplusplus
PairRegionsGpu pair_regions(LabelGpu k, LabelGpu j, vec3 placed_j, float margin);
#endif
PairRegionsGpu placed_regions(uint k) {
  uint j = order_at(k);
  PlacementGpu placed = placement_at(j);
  return pair_regions(view_label, label_at(j),
                      vec3(placed.position, placed.shown == PLACEMENT_SHOWN ? 1.0f : 0.0f),
                      params.margin);
}
uint anchor_count() {
  return view.label_count;
}
// (a disabled label's anchor lies where no box reaches)
vec2 anchor_at(uint k) {
  LabelGpu other = label_at(k);
  return (other.flags & LABEL_ENABLED) != 0u ? other.anchor : vec2(-DEBUG_NO_BUDGET);
}
// (eq. 3.1's integral term, which the constraint image does not need)
float table_at(uint, int, int) {
  return 0.0f;
}
// (the constraint image shows every candidate the rules allow, the viewer's panel's too)
uvec4 keep_out_at(uint) {
  return uvec4(0u);
}

#include "placement_cost.h"

void view_setup() {
  // Every field the shared code may read is set: an unset one is undefined, and a GPU compiler
  // may fold it into anything (NVIDIA did, for `hard` in candidate_allowed).
  params.weights = CostWeightsGpu(0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f);
  params.hard = 0u;
  params.write_constraints = 0u;
  params.width = view.width;
  params.height = view.height;
  params.layer_count = view.layer_count;
  params.label_count = view.label_count;
  params.margin = view.margin;
  params.edge = 0.0f;  // (a still's candidates)
  params.keep_out_count = 0u;
  view_position = view.order_count;
  if (view.label >= view.label_count) return;
  view_label = label_at(view.label);
  for (uint k = 0u; k < view.order_count; ++k) {
    if (order_at(k) == view.label) {
      view_position = k;
      break;
    }
  }
}

// The constraint bits of the picked label with its box at candidate pixel p (as the placement's
// constraint image holds them), or DEBUG_NOT_CANDIDATE.
uint view_constraint_bits(uvec2 p) {
  if (view_position >= view.order_count || !candidate_allowed(view_label, p)) {
    return DEBUG_NOT_CANDIDATE;
  }
  vec2 origin = box_origin(p, view_label.size);
  return constraint_bits(view_label, origin + view_label.size * 0.5f, 0u, DEBUG_NO_BUDGET);
}

// The constraint colour, white at the candidate the label was placed at.
vec3 view_constraints(uvec2 p) {
  uint bits = view_constraint_bits(p);
  if (bits != DEBUG_NOT_CANDIDATE) {
    PlacementGpu placed = placement_at(view.label);
    vec2 centre = box_origin(p, view_label.size) + view_label.size * 0.5f;
    if (placed.shown == PLACEMENT_SHOWN &&
        all(lessThanEqual(abs(centre - placed.position), vec2(0.25f)))) {
      return vec3(1.0f);
    }
  }
  return debug_constraint_colour(bits);
}

// The fragments of a pixel: its probe sequence up to the first empty slot, as the resolve walks
// it (habuffer_resolve.comp), counting the keys that are the pixel's at that age.
uint habuffer_fragments(uint pixel) {
  uint size = table_size();
  uint count = 0u;
  for (uint age = 1u; size != 0u && age <= uint(VR_MAX_AGE); ++age) {
    uvec2 key = key_at(debug_habuffer_slot(pixel, age, size));
    if (key == uvec2(0u)) break;
    if (key.x == ((age << 24u) | pixel)) ++count;
  }
  return count;
}

vec4 debug_view_pixel(uvec2 p) {
  uint pixel = p.y * view.width + p.x;
  uint layer = min(view.layer, view.layer_count - 1u);
  if (view.mode == DEBUG_MODE_SALIENCY) {
    return vec4(vec3(clamp(saliency_at(pixel) * view.scale, 0.0f, 1.0f)), 1.0f);
  }
  if (view.mode == DEBUG_MODE_COSTS)
    return vec4(debug_heat(cost_at(layer, pixel) * view.scale), 1.0f);
  if (view.mode == DEBUG_MODE_CONSTRAINTS) return vec4(view_constraints(p), 1.0f);
  if (view.mode == DEBUG_MODE_LAYER) {
    vec4 c = layer_at(p, layer);
    return vec4(vec3(c) + (1.0f - c.w) * debug_checker(p), 1.0f);
  }
  return vec4(debug_heat(float(habuffer_fragments(pixel)) * view.scale), 1.0f);
}
#endif
