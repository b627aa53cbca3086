#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/keep_apart.h"

// One workgroup: each label's drawn position moves toward its placement (eq. 3.6-3.8); with
// keep_apart, the labels then take turns in their settling order (keep_apart.h), each turn's
// boxes tested against every other label's box by the whole group at once. Invocation t owns the
// labels t, t + KEEP_APART_GROUP, ...: only it writes their state and their obstacle.
layout(local_size_x = KEEP_APART_GROUP) in;
layout(binding = FORCES_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = FORCES_BINDING_TARGETS, std430) readonly buffer Targets { PlacementGpu targets[]; };
layout(binding = FORCES_BINDING_STATE, std430) buffer States { LabelStateGpu states[]; };
layout(binding = FORCES_BINDING_DRAWN, std430) writeonly buffer Drawn { PlacementGpu drawn[]; };
layout(binding = FORCES_BINDING_ORDER, std430) readonly buffer Order { uint order[]; };
layout(binding = FORCES_BINDING_SCRATCH, std430) coherent buffer Scratch { KeepApartGpu scratch[]; };
layout(push_constant) uniform Push { ForcesParams params; };

shared uint taking_part;
shared uint clashes[2];  // this turn's clash bits (alternating, so that the next turn's start clear)
shared vec4 turn_way, turn_stay;

void sync() {
  memoryBarrierBuffer();
  memoryBarrierShared();
  barrier();
}

void move_alone(uint i) {
  LabelStateGpu state = states[i];
  if (params.trial == 0u) {
    state = forces_update(labels[i], targets[i], state, params);
    states[i] = state;
  }
  drawn[i] = forces_drawn(targets[i], state);
}

// A label taking no part in the turns (neither drawn nor shown).
void settle_alone(uint i) {
  LabelStateGpu state = keep_apart_settle(labels[i], targets[i], states[i], params, 0u);
  states[i] = state;
  drawn[i] = forces_drawn(targets[i], state);
}

// Each label's key (class, then position in the order) and the box it has now.
void start(uint t) {
  for (uint i = t; i < params.label_count; i += KEEP_APART_GROUP) {
    scratch[i].key = params.order_count + i;
  }
  if (t == 0u) {
    taking_part = 0u;
    clashes[0] = 0u;
  }
  sync();
  for (uint k = t; k < params.order_count; k += KEEP_APART_GROUP) {
    if (order[k] < params.label_count) scratch[order[k]].key = k;
  }
  sync();
  for (uint i = t; i < params.label_count; i += KEEP_APART_GROUP) {
    uint c = keep_apart_class(labels[i], targets[i], states[i]);
    scratch[i].key = c * KEEP_APART_CLASS_STRIDE + scratch[i].key;
    scratch[i].obstacle = keep_apart_stay(labels[i], states[i], params);
    if (c != KEEP_APART_NONE) atomicAdd(taking_part, 1u);
  }
  sync();
}

// Each label's turn: how many labels taking part come before it.
void rank(uint t) {
  const uint none = KEEP_APART_NONE * KEEP_APART_CLASS_STRIDE;
  for (uint i = t; i < params.label_count; i += KEEP_APART_GROUP) {
    uint key = scratch[i].key;
    uint r = KEEP_APART_NO_RANK;
    if (key < none) {
      r = 0u;
      for (uint j = 0u; j < params.label_count; ++j) r += scratch[j].key < key ? 1u : 0u;
      scratch[r].by_rank = i;
    }
    scratch[i].rank = r;
  }
  sync();
}

void take_turns(uint t) {
  for (uint r = 0u; r < taking_part; ++r) {
    const uint i = scratch[r].by_rank;
    const bool owner = i % KEEP_APART_GROUP == t;
    uint cut = 0u;  // (the owner's; the shared boxes are the next turn's once it ends)
    if (owner) {
      turn_way = keep_apart_way(labels[i], targets[i], states[i], params);
      turn_stay = scratch[i].obstacle;
      cut = keep_apart_cut(turn_way, turn_stay, params);
    }
    sync();
    uint bits = 0u;
    for (uint j = t; j < params.label_count; j += KEEP_APART_GROUP) {
      if (j == i) continue;
      vec4 other = scratch[j].obstacle;
      if (boxes_clash(turn_way, other)) bits |= KEEP_APART_WAY;
      if (scratch[j].rank < r && boxes_clash(turn_stay, other)) bits |= KEEP_APART_STAY;
    }
    if (bits != 0u) atomicOr(clashes[r & 1u], bits);
    sync();
    if (owner) {
      LabelStateGpu state =
          keep_apart_settle(labels[i], targets[i], states[i], params, clashes[r & 1u] | cut);
      states[i] = state;
      drawn[i] = forces_drawn(targets[i], state);
      scratch[i].obstacle = keep_apart_obstacle(labels[i], state);
      clashes[(r + 1u) & 1u] = 0u;
    }
  }
}

void main() {
  const uint t = gl_LocalInvocationID.x;
  if (params.trial != 0u || params.keep_apart == 0u) {
    for (uint i = t; i < params.label_count; i += KEEP_APART_GROUP) move_alone(i);
    return;
  }
  start(t);
  rank(t);
  for (uint i = t; i < params.label_count; i += KEEP_APART_GROUP) {
    if (scratch[i].rank == KEEP_APART_NO_RANK) settle_alone(i);
  }
  take_turns(t);
}
