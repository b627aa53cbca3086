// Forces (thesis 3.4, eq. 3.6-3.8): each label's drawn position moves toward the position the
// placement chose for it, so labels glide instead of jumping from frame to frame. Written once in
// the common subset of GLSL and GLM: label_forces.comp runs it per label on the GPU and
// passes/label_forces.cpp runs the same arithmetic as the CPU reference.
#ifndef STRATA_SHARED_FORCES_H
#define STRATA_SHARED_FORCES_H

#include "labels.h"

#define FORCES_GROUP 64
#define FORCES_BINDING_LABELS 0   // LabelGpu[]: this frame's anchors and flags
#define FORCES_BINDING_TARGETS 1  // PlacementGpu[]: the placement's positions (the targets)
#define FORCES_BINDING_STATE 2    // LabelStateGpu[]: drawn positions, kept across frames
#define FORCES_BINDING_DRAWN 3    // PlacementGpu[]: where the labels are drawn this frame

// LabelStateGpu.flags
#define LABEL_STATE_PLACED 1u  // the label has a drawn position (it was shown before)

STRATA_BEGIN

// What persists of a label between frames.
struct LabelStateGpu {
  vec2 position;  // drawn box centre: an offset from the anchor, or pixels (ForcesParams)
  vec2 drawn;     // where the box centre was drawn (pixels; the anchor while never placed):
                  // the next frame's previous position (eq. 3.1's eta term)
  uint flags;     // LABEL_STATE_*
  uint pad0;
  uint pad1;
  uint pad2;
};

struct ForcesParams {
  uint label_count;
  uint steps;            // sub-steps this frame (each moves at most `epsilon`: no overshoot)
  float step_seconds;    // the frame's duration / steps
  float speed;           // pixels per second at full force (eq. 3.7's unit force)
  float epsilon;         // pixels: closer than this the force shrinks with the distance
  float snap;            // pixels: closer than this the label is put on its target
  uint anchor_relative;  // 1: positions are offsets from the anchor, 0: pixels on screen
  uint pad;
};

// Eq. 3.6-3.8 for one sub-step: the label at l moves toward p by the unit force (attenuated as
// d / epsilon within epsilon of p) times the time step.
STRATA_INLINE vec2 force_step(vec2 l, vec2 p, float seconds, float speed, float epsilon) {
  vec2 d = p - l;
  float distance = length(d);
  vec2 force = distance >= epsilon ? d / distance : d / epsilon;
  return l + (seconds * speed) * force;
}

// The label's state after this frame. A label seen for the first time starts on its target; a
// hidden or disabled one keeps where it was.
STRATA_INLINE LabelStateGpu forces_update(LabelGpu label, PlacementGpu target, LabelStateGpu state,
                                          ForcesParams params) {
  if ((state.flags & LABEL_STATE_PLACED) == 0u) state.drawn = label.anchor;
  if ((label.flags & LABEL_ENABLED) == 0u || target.shown != PLACEMENT_SHOWN) return state;
  vec2 goal = params.anchor_relative != 0u ? target.position - label.anchor : target.position;
  vec2 l = goal;
  if ((state.flags & LABEL_STATE_PLACED) != 0u) {
    l = state.position;
    for (uint s = 0u; s < params.steps; ++s) {
      l = force_step(l, goal, params.step_seconds, params.speed, params.epsilon);
      if (length(goal - l) < params.snap) l = goal;
    }
  }
  state.position = l;
  state.flags |= LABEL_STATE_PLACED;
  state.drawn = params.anchor_relative != 0u ? label.anchor + l : l;
  return state;
}

// Where the label is drawn this frame: its state's position, shown when the placement shows it.
STRATA_INLINE PlacementGpu forces_drawn(PlacementGpu target, LabelStateGpu state) {
  PlacementGpu drawn = target;
  if ((state.flags & LABEL_STATE_PLACED) != 0u) drawn.position = state.drawn;
  return drawn;
}

STRATA_END

#endif
