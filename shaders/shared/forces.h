// Forces (thesis 3.4, eq. 3.6-3.8): each label's drawn position moves toward the position the
// placement chose for it, so labels glide instead of jumping from frame to frame. Written once in
// the common subset of GLSL and GLM: label_forces.comp runs it per label on the GPU and
// passes/label_forces.cpp runs the same arithmetic as the CPU reference.
#ifndef STRATA_SHARED_FORCES_H
#define STRATA_SHARED_FORCES_H

#include "placement.h"

#define FORCES_GROUP 64
#define FORCES_BINDING_LABELS 0   // LabelGpu[]: this frame's anchors and flags
#define FORCES_BINDING_TARGETS 1  // PlacementGpu[]: the placement's positions (the targets)
#define FORCES_BINDING_STATE 2    // LabelStateGpu[]: drawn positions, kept across frames
#define FORCES_BINDING_DRAWN 3    // PlacementGpu[]: where the labels are drawn this frame
#define FORCES_BINDING_PLACED 6  // LabelGpu[]: the labels as a placement beside the frames saw them
#define FORCES_BINDING_FOLLOWED 7  // PlacementGpu[]: that placement's targets, in this frame

// LabelStateGpu.flags
#define LABEL_STATE_PLACED 1u  // the label has a drawn position (it was shown before)
#define LABEL_STATE_SHOWN 2u   // the placement showed the label in the last frame
#define LABEL_STATE_SEEN 4u    // the label has been through a frame since the last reset

STRATA_BEGIN

// What persists of a label between frames.
struct LabelStateGpu {
  vec2 position;  // drawn box centre: an offset from the anchor, or pixels (ForcesParams)
  vec2 drawn;     // where the box centre was drawn (pixels; the anchor while never placed)
  uint flags;     // LABEL_STATE_*
  float cost;     // eq. 3.1 at the target, without the hold (sizes the next frame's hold)
  vec2 target;    // where the label is heading: the placement's position, held as `position` is
  float opacity;  // 0: invisible, 1: fully drawn; fades toward 1 while shown, toward 0 when not
  float speed;    // pixels per second the label moved at in its last sub-step (the easing's start)
  float blocked;  // seconds the label has waited for its way to be free (keep_apart.h)
  float hidden;   // seconds since the label was last drawn (keep_apart.h; 0 while drawn)
};

// One frame's forces in pixels and seconds (forces_params converts ForceSettings' relative units).
struct ForcesParams {
  uint label_count;
  uint steps;            // sub-steps this frame (each moves at most `epsilon`: no overshoot)
  float step_seconds;    // the frame's duration / steps
  float speed;           // pixels per second at full force (eq. 3.7's unit force)
  float epsilon;         // pixels: closer than this the force shrinks with the distance
  float snap;            // pixels: closer than this the label is put on its target
  uint anchor_relative;  // 1: positions are offsets from the anchor, 0: pixels on screen
  float fade;            // opacity change this frame (1: at once)
  float hold_share;      // the hold: this share of the target's cost ...
  float hold_cost;       // ... plus this
  float appear_padding;  // pixels of padding for a label hidden in the last frame (hard mode)
  uint trial;  // 1: a trial frame (the viewer's optimisation on idle): the state stays as it was
  float acceleration;  // pixels per second per second a label speeds up by at most (0: at once)
  uint keep_apart;     // 1: drawn boxes are kept apart and inside the image (keep_apart.h)
  uint order_count;    // labels in the placement's insertion order (the settling's priority)
  float image_width;   // pixels
  float image_height;
  float wait;  // seconds a label waits for its way before it fades out to appear at its target
  float appear_margin;  // pixels of room a label needs around its box to appear (keep_apart.h)
  float min_hidden;     // seconds a label that was drawn stays hidden before it appears again
  float clearance;      // pixels two drawn boxes keep apart (keep_apart.h: boxes_clash)
  uint keep_out_count;  // rectangles drawn boxes keep off, as off the image's edges (keep_apart.h):
  uint keep_out[2u * PLACEMENT_KEEP_OUT_MAX];  // each x0 | y0 << 16, then x1 | y1 << 16, in pixels
};

// An opacity moved by `change`, kept in [0, 1]; within 1/512 of either end (less than a step of
// an 8-bit image) it is that end, so a fade ends after whole frames despite rounding.
STRATA_INLINE float faded(float opacity, float change) {
  float o = clamp(opacity + change, 0.0f, 1.0f);
  return o < 1.0f / 512.0f ? 0.0f : (o > 1.0f - 1.0f / 512.0f ? 1.0f : o);
}

// Eq. 3.6-3.8 for one sub-step: how far the label at l moves toward p, the unit force (attenuated
// as d / epsilon within epsilon of p) times the time step.
STRATA_INLINE vec2 force_step(vec2 l, vec2 p, float seconds, float speed, float epsilon) {
  vec2 d = p - l;
  float distance = length(d);
  vec2 force = distance >= epsilon ? d / distance : d / epsilon;
  return (seconds * speed) * force;
}

// The easing of a start: a sub-step `step` after one at `speed` pixels per second, cut to what
// `acceleration` allows in `seconds` (none: 0). A stop is eased already: within epsilon the force
// shrinks with the distance. Returns the step (xy) and the speed it moves at (z). (Steps, not
// positions: (l + step) - l is step to a shader compiler, not to the CPU reference.)
STRATA_INLINE vec3 eased_step(vec2 step, float speed, float seconds, float acceleration) {
  if (!(seconds > 0.0f)) return vec3(0.0f);
  float moved = length(step);
  float most = (speed + acceleration * seconds) * seconds;
  if (acceleration > 0.0f && moved > most) {
    step = step * (most / moved);
    moved = most;
  }
  return vec3(step.x, step.y, moved / seconds);
}

// A position of the state (offset or pixels) as pixels on screen for the label's anchor now.
STRATA_INLINE vec2 state_to_screen(LabelGpu label, vec2 p, ForcesParams params) {
  return params.anchor_relative != 0u ? label.anchor + p : p;
}

// What the placement of the next frame takes from the last one. A label shown in the last frame
// is held: its target (as an offset from its anchor's new position, or on screen) is eq. 3.1's
// previous position, and the held position that a move away from must win the hold; where it is
// drawn, maybe still on its way there, does not matter (the target would otherwise be pulled back
// toward the label in transit, and chase it). A label hidden since it was drawn has its last
// drawn position (or offset) as its previous position, and in hard mode a padding.
STRATA_INLINE LabelGpu forces_previous(LabelGpu label, LabelStateGpu state, ForcesParams params) {
  if ((state.flags & LABEL_STATE_SEEN) != 0u && (state.flags & LABEL_STATE_SHOWN) == 0u) {
    label.padding = params.appear_padding;
  }
  if ((state.flags & LABEL_STATE_PLACED) == 0u) return label;
  if ((state.flags & LABEL_STATE_SHOWN) != 0u) {
    label.held = state_to_screen(label, state.target, params);
    label.hold = params.hold_cost + params.hold_share * max(state.cost, 0.0f);
    label.previous = label.held;
  } else {
    label.previous = params.anchor_relative != 0u ? label.anchor + state.position : state.drawn;
  }
  return label;
}

// The label's state after this frame. A label seen for the first time starts on its target; a
// hidden or disabled one keeps where it was (an anchored one stays on its anchor) and fades out.
// The placement's position is the held one when the placement kept it: the exact held offset
// is kept then, not the candidate pixel nearest to it, so a held label does not drift.
STRATA_INLINE LabelStateGpu forces_update(LabelGpu label, PlacementGpu target, LabelStateGpu state,
                                          ForcesParams params) {
  if ((state.flags & LABEL_STATE_PLACED) == 0u) state.drawn = label.anchor;
  state.flags |= LABEL_STATE_SEEN;
  bool shown = (label.flags & LABEL_ENABLED) != 0u && target.shown == PLACEMENT_SHOWN;
  if (!shown) {
    state.flags &= ~LABEL_STATE_SHOWN;
    state.speed = 0.0f;
    state.opacity = faded(state.opacity, -params.fade);
    if ((label.flags & LABEL_ENABLED) != 0u && (state.flags & LABEL_STATE_PLACED) != 0u) {
      state.drawn = state_to_screen(label, state.position, params);
    }
    return state;
  }
  bool kept =
      (state.flags & LABEL_STATE_SHOWN) != 0u && label.hold > 0.0f && holds(label, target.position);
  vec2 goal =
      kept ? state.target
           : (params.anchor_relative != 0u ? target.position - label.anchor : target.position);
  vec2 l = goal;
  float speed = 0.0f;
  if ((state.flags & LABEL_STATE_PLACED) != 0u) {
    l = state.position;
    speed = state.speed;
    for (uint s = 0u; s < params.steps; ++s) {
      vec3 eased =
          eased_step(force_step(l, goal, params.step_seconds, params.speed, params.epsilon), speed,
                     params.step_seconds, params.acceleration);
      l = l + vec2(eased.x, eased.y);
      speed = eased.z;
      if (length(goal - l) < params.snap) {
        l = goal;
        speed = 0.0f;
      }
    }
  }
  state.speed = speed;
  state.position = l;
  state.target = goal;
  state.cost = target.cost;
  state.flags |= LABEL_STATE_PLACED | LABEL_STATE_SHOWN;
  state.opacity = faded(state.opacity, params.fade);
  state.drawn = state_to_screen(label, l, params);
  return state;
}

// A target of a placement made beside the frames, some frames ago, in this frame: anchored labels
// keep its offset from their anchor, which has moved since; labels on screen keep its position.
// A label that placement did not see (not enabled then) has no target.
STRATA_INLINE PlacementGpu follow_anchor(PlacementGpu target, LabelGpu placed, LabelGpu label,
                                         ForcesParams params) {
  if ((placed.flags & LABEL_ENABLED) == 0u) target.shown = PLACEMENT_HIDDEN;
  if (params.anchor_relative != 0u) target.position += label.anchor - placed.anchor;
  return target;
}

// Where the label is drawn this frame, and how opaque: its state's position while it is shown or
// still fading out.
STRATA_INLINE PlacementGpu forces_drawn(PlacementGpu target, LabelStateGpu state) {
  PlacementGpu drawn = target;
  if ((state.flags & LABEL_STATE_PLACED) != 0u) drawn.position = state.drawn;
  drawn.opacity = state.opacity;
  drawn.shown = state.opacity > 0.0f ? PLACEMENT_SHOWN : PLACEMENT_HIDDEN;
  return drawn;
}

STRATA_END

#endif
