// Keeping drawn labels apart: the drawn layout is a constraint. After the forces propose where
// each label moves this frame, the labels are settled one at a time in a priority order against
// the boxes drawn so far: a label moves only where its box is free of every drawn box and inside
// the image (and off the keep-out rectangles: a picture's title and legend, the viewer's panel);
// where its way is taken it stays, and after ForcesParams::wait seconds of waiting it
// fades out where it is and fades in at its target once that is free. A label whose box now
// clashes with one settled before it (anchors moving on screen bring boxes together) or leaves
// the image goes at once. So no two drawn boxes overlap and none is cut, in any frame. A label
// appears only with room around its box (appear_margin) and, once it went, not before
// min_hidden seconds: hysteresis, so that a label at the edge of room does not flicker.
// Written once in the common subset of GLSL and GLM: label_forces.comp settles on the GPU and
// passes/label_forces.cpp runs the same arithmetic as the CPU reference.
#ifndef STRATA_SHARED_KEEP_APART_H
#define STRATA_SHARED_KEEP_APART_H

#include "forces.h"

#define KEEP_APART_GROUP 256      // label_forces.comp: one workgroup settles every label ...
#define KEEP_APART_CHUNK 128      // ... scanning them all in chunks of this many
#define FORCES_BINDING_ORDER 4    // uint[]: the placement's insertion order (label indices)
#define FORCES_BINDING_SCRATCH 5  // KeepApartGpu[]: the settling's working state per label

// The classes, settled in this order (then by the placement's order).
#define KEEP_APART_STAYING 0u  // drawn, and shown by the placement
#define KEEP_APART_LEAVING 1u  // drawn, and hidden by the placement: fades out where it is
#define KEEP_APART_COMING 2u   // not drawn, shown by the placement: fades in at its target
#define KEEP_APART_NONE 3u     // neither: takes no part
#define KEEP_APART_CLASS_STRIDE (2u * LABEL_MAX)  // keys: class * stride + position in the order
#define KEEP_APART_NO_RANK 0xFFFFFFFFu

// PlacementGpu.pad of a drawn label: hidden, and may appear once it has been for min_hidden
// (the viewer's view is not settled while one is).
#define PLACEMENT_PENDING 1u

// Clash bits of a label's boxes.
#define KEEP_APART_WAY 1u   // where it would move (or appear) is taken by a drawn box, or is cut
#define KEEP_APART_STAY 2u  // where it is clashes with a box settled before it, or is cut
#define KEEP_APART_PUSH 4u  // where it would slide out of that clash (keep_apart_push) clashes with
                            // any other label's boxes of this frame, or is cut

STRATA_BEGIN

// What the settling keeps per label.
struct KeepApartGpu {
  LabelStateGpu moved;  // the label's state after forces_update
  vec4 way;       // keep_apart_way's box
  vec4 stay;      // keep_apart_stay's box
  vec4 obstacle;  // the box the others must keep clear of (x0, y0, x1, y1), or keep_apart_none():
                  // keep_apart_stay's until the label's turn, then keep_apart_obstacle's
  uint key;       // the label's place in the settling order (its position in the order first)
  uint rank;      // its turn, or KEEP_APART_NO_RANK: it takes no part, or no box of its can clash
                  // with another's (it settles on its own, as it would in its turn)
  uint pad0, pad1;
};

// Boxes are (x0, y0, x1, y1). An empty box: clashes with nothing.
STRATA_INLINE vec4 keep_apart_none() {
  return vec4(0.0f, 0.0f, -1.0f, -1.0f);
}

STRATA_INLINE vec4 box_around(vec2 centre, vec2 size) {
  return vec4(centre - 0.5f * size, centre + 0.5f * size);
}

// Two boxes clash where they overlap, or in motion where they come closer than `clearance`
// (ForcesParams: a hundredth of a pixel, so that no rounding between the GPU's floats and a
// layout file's numbers makes boxes that touch overlap; a still's boxes lie on whole and half
// pixels, where touching is exact). An empty box clashes with nothing.
STRATA_INLINE bool boxes_clash(vec4 a, vec4 b, float clearance) {
  return min(a.z, b.z) - max(a.x, b.x) > -clearance && min(a.w, b.w) - max(a.y, b.y) > -clearance &&
         a.x <= a.z && b.x <= b.z;
}

// Keep-out rectangle i of params (x0, y0, x1, y1).
STRATA_INLINE vec4 keep_out_box(ForcesParams params, uint i) {
  uint lo = params.keep_out[2u * i], hi = params.keep_out[2u * i + 1u];
  return vec4(float(lo & 0xFFFFu), float(lo >> 16u), float(hi & 0xFFFFu), float(hi >> 16u));
}

// Inside the image and off the keep-out rectangles. A box may reach into a rectangle by the
// clearance: the placement puts boxes touching one, and rounding must not make them clash.
STRATA_INLINE bool box_inside(vec4 box, ForcesParams params) {
  bool inside =
      box.x >= 0.0f && box.y >= 0.0f && box.z <= params.image_width && box.w <= params.image_height;
  for (uint i = 0u; i < params.keep_out_count; ++i) {
    if (boxes_clash(box, keep_out_box(params, i), -params.clearance)) inside = false;
  }
  return inside;
}

// (An internal label, drawn on its anchor, takes no part: it has no other place to go.)
STRATA_INLINE uint keep_apart_class(LabelGpu label, PlacementGpu target, LabelStateGpu state) {
  if ((label.flags & LABEL_INTERNAL) != 0u) return KEEP_APART_NONE;
  bool shown = (label.flags & LABEL_ENABLED) != 0u && target.shown == PLACEMENT_SHOWN;
  if (state.opacity > 0.0f) return shown ? KEEP_APART_STAYING : KEEP_APART_LEAVING;
  return shown ? KEEP_APART_COMING : KEEP_APART_NONE;
}

// A box centre moved into the image (the clearance inside its edges, so that rounding does not
// leave it a hair outside), by at most what the forces move a label in a frame: a label at the
// edge whose anchor runs out of the image slides along with the edge while it can.
STRATA_INLINE vec2 keep_apart_inward(vec2 centre, vec2 size, ForcesParams params) {
  float most = params.speed * float(params.steps) * params.step_seconds;
  float c = params.clearance;
  vec2 lo = centre - 0.5f * size;
  vec2 hi = centre + 0.5f * size;
  vec2 image = vec2(params.image_width, params.image_height);
  vec2 shift = vec2(0.0f);
  if (lo.x < 0.0f) shift.x = c - lo.x;
  if (hi.x > image.x) shift.x = image.x - c - hi.x;
  if (lo.y < 0.0f) shift.y = c - lo.y;
  if (hi.y > image.y) shift.y = image.y - c - hi.y;
  return centre + clamp(shift, vec2(-most), vec2(most));
}

// Where a drawn label is if it stays: its offset from where its anchor is now (an enabled label),
// or where it was drawn; moved inward at the image's edge.
STRATA_INLINE vec2 keep_apart_stay_centre(LabelGpu label, LabelStateGpu state,
                                          ForcesParams params) {
  bool follows = (label.flags & LABEL_ENABLED) != 0u && (state.flags & LABEL_STATE_PLACED) != 0u;
  vec2 centre = follows ? state_to_screen(label, state.position, params) : state.drawn;
  return keep_apart_inward(centre, label.size, params);
}

// The box a drawn label keeps if it stays; none for one not drawn.
STRATA_INLINE vec4 keep_apart_stay(LabelGpu label, LabelStateGpu state, ForcesParams params) {
  if (!(state.opacity > 0.0f)) return keep_apart_none();
  return box_around(keep_apart_stay_centre(label, state, params), label.size);
}

// A state's drawn position moved to `centre` (its position by as much).
STRATA_INLINE LabelStateGpu keep_apart_moved_to(LabelStateGpu state, vec2 centre) {
  state.position = state.position + (centre - state.drawn);
  state.drawn = centre;
  return state;
}

// The box a label heads into this frame: where the forces move a staying one, the target of one
// coming with the room it needs around it; none for the others.
// (`moved`: forces_update's state, as for every function below that takes it.)
STRATA_INLINE vec4 keep_apart_way(LabelGpu label, PlacementGpu target, LabelStateGpu state,
                                  LabelStateGpu moved, ForcesParams params) {
  uint c = keep_apart_class(label, target, state);
  if (c == KEEP_APART_STAYING) {
    return box_around(keep_apart_inward(moved.drawn, label.size, params), label.size);
  }
  if (c == KEEP_APART_COMING) {
    return box_around(state_to_screen(label, moved.target, params),
                      label.size + vec2(2.0f * params.appear_margin));
  }
  return keep_apart_none();
}

// The clash bits a label's boxes have from the image alone.
STRATA_INLINE uint keep_apart_cut(vec4 way, vec4 stay, ForcesParams params) {
  return (box_inside(way, params) ? 0u : KEEP_APART_WAY) |
         (box_inside(stay, params) ? 0u : KEEP_APART_STAY);
}

// The time since the label was last drawn, after a frame that left it at `next`.
STRATA_INLINE LabelStateGpu keep_apart_hidden(LabelStateGpu state, LabelStateGpu next,
                                              ForcesParams params) {
  bool was_hidden = !(state.opacity > 0.0f) && !(next.opacity > 0.0f);
  next.hidden = was_hidden ? state.hidden + float(params.steps) * params.step_seconds : 0.0f;
  return next;
}

// Where a box that clashes with `other` slides to be clear of it: the shortest move along an axis
// (left, right, up, down, in this order on a tie), if that is no more than the forces move a
// label in a frame; else none. Two labels whose anchors bring their boxes together so push apart,
// while they can, instead of one going.
STRATA_INLINE vec4 keep_apart_push(vec4 box, vec4 other, ForcesParams params) {
  float most = params.speed * float(params.steps) * params.step_seconds;
  float gap = 2.0f * params.clearance;
  float left = other.x - gap - box.z;  // (<= 0 for boxes that clash)
  float right = other.z + gap - box.x;
  float up = other.y - gap - box.w;
  float down = other.w + gap - box.y;
  vec2 shift = vec2(left, 0.0f);
  float best = -left;
  if (right < best) {
    shift = vec2(right, 0.0f);
    best = right;
  }
  if (-up < best) {
    shift = vec2(0.0f, up);
    best = -up;
  }
  if (down < best) {
    shift = vec2(0.0f, down);
    best = down;
  }
  if (!(best <= most)) return keep_apart_none();
  return box + vec4(shift, shift);
}

STRATA_INLINE vec2 box_centre(vec4 box) {
  return 0.5f * vec2(box.x + box.z, box.y + box.w);
}

// A label's state after its turn, from its clash bits and where it would slide out of a clash
// (keep_apart_push's box): it moves, stays, slides, waits, fades or goes.
STRATA_INLINE LabelStateGpu keep_apart_move(LabelGpu label, PlacementGpu target,
                                            LabelStateGpu state, LabelStateGpu moved,
                                            ForcesParams params, uint clashes, vec4 pushed) {
  bool slides = (clashes & KEEP_APART_STAY) != 0u && (clashes & KEEP_APART_PUSH) == 0u &&
                pushed.x <= pushed.z;
  uint c = keep_apart_class(label, target, state);
  moved.blocked = 0.0f;
  if (c == KEEP_APART_NONE) return moved;
  if (c == KEEP_APART_COMING) {  // appears at its target, when that is free
    moved.position = moved.target;
    moved.drawn = state_to_screen(label, moved.target, params);
    moved.speed = 0.0f;
    bool rested = (state.flags & LABEL_STATE_PLACED) == 0u || state.hidden >= params.min_hidden;
    if ((clashes & KEEP_APART_WAY) != 0u || !rested) moved.opacity = 0.0f;
    return moved;
  }
  if (c == KEEP_APART_LEAVING) {  // fades out where it is: at once where that clashes
    moved = keep_apart_moved_to(
        moved, slides ? box_centre(pushed) : keep_apart_stay_centre(label, state, params));
    if ((clashes & KEEP_APART_STAY) != 0u && !slides) moved.opacity = 0.0f;
    return moved;
  }
  if ((clashes & KEEP_APART_WAY) == 0u) {
    return keep_apart_moved_to(moved, keep_apart_inward(moved.drawn, label.size, params));
  }
  // Its way is taken: it stays, and waits.
  LabelStateGpu stays = moved;
  stays.position = state.position;
  stays.drawn = state_to_screen(label, state.position, params);
  stays = keep_apart_moved_to(
      stays, slides ? box_centre(pushed) : keep_apart_stay_centre(label, state, params));
  stays.speed = 0.0f;
  bool wants_to_move = moved.position.x != state.position.x || moved.position.y != state.position.y;
  stays.blocked = wants_to_move ? state.blocked + float(params.steps) * params.step_seconds : 0.0f;
  if ((clashes & KEEP_APART_STAY) != 0u && !slides) {
    stays.opacity = 0.0f;
  } else if (stays.blocked >= params.wait) {
    stays.opacity = faded(state.opacity, -params.fade);
  }
  return stays;
}

STRATA_INLINE LabelStateGpu keep_apart_settle(LabelGpu label, PlacementGpu target,
                                              LabelStateGpu state, LabelStateGpu moved,
                                              ForcesParams params, uint clashes, vec4 pushed) {
  return keep_apart_hidden(
      state, keep_apart_move(label, target, state, moved, params, clashes, pushed), params);
}

// The box the others keep clear of after a label's turn: where it is drawn, while it is.
STRATA_INLINE vec4 keep_apart_obstacle(LabelGpu label, LabelStateGpu state) {
  if (!(state.opacity > 0.0f)) return keep_apart_none();
  return box_around(state.drawn, label.size);
}

// Where and how opaque the label is drawn (forces_drawn), and whether it is pending.
STRATA_INLINE PlacementGpu keep_apart_drawn(LabelGpu label, PlacementGpu target,
                                            LabelStateGpu state, ForcesParams params) {
  PlacementGpu drawn = forces_drawn(target, state);
  bool coming = keep_apart_class(label, target, state) == KEEP_APART_COMING;
  bool resting = (state.flags & LABEL_STATE_PLACED) != 0u && state.hidden < params.min_hidden;
  drawn.pad = coming && resting ? PLACEMENT_PENDING : 0u;
  return drawn;
}

STRATA_END

#endif
