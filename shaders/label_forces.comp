#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/keep_apart.h"

// One workgroup: each label's drawn position moves toward its placement (eq. 3.6-3.8); with
// keep_apart, the labels then settle in their order (keep_apart.h). A label none of whose boxes
// (where it would move, where it is) can clash with another label's settles at once: nothing
// another label does changes its clash bits, nor does it change theirs. The others take turns,
// each turn's boxes tested by the whole group against the boxes of the labels still taking
// turns. Invocation t owns the labels t, t + KEEP_APART_GROUP, ...: only it writes their state,
// and only it reads and writes their obstacle during the turns; it keeps label t's boxes and
// turn in registers (the turns wait on nothing but the group's barriers then, up to
// KEEP_APART_GROUP labels).
layout(local_size_x = KEEP_APART_GROUP) in;
layout(binding = FORCES_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = FORCES_BINDING_TARGETS, std430) readonly buffer Targets { PlacementGpu targets[]; };
layout(binding = FORCES_BINDING_STATE, std430) buffer States { LabelStateGpu states[]; };
layout(binding = FORCES_BINDING_DRAWN, std430) writeonly buffer Drawn { PlacementGpu drawn[]; };
layout(binding = FORCES_BINDING_ORDER, std430) readonly buffer Order { uint order[]; };
layout(binding = FORCES_BINDING_SCRATCH, std430) coherent buffer Scratch { KeepApartGpu scratch[]; };
layout(push_constant) uniform Push { ForcesParams params; };

const uint kNone = KEEP_APART_NONE * KEEP_APART_CLASS_STRIDE;  // keys from here take no part
const uint kNoLabel = 0xFFFFFFFFu;

shared uint turns;                        // labels taking turns
shared uint turn_label[LABEL_MAX / 2u];   // two 16-bit label indices per entry, by turn
shared uint clashes[3];  // turn r's clash bits in slot r % 3 (turn r clears the next turn's)
shared vec4 turn_way, turn_stay, turn_push;
shared uint chunk_key[KEEP_APART_CHUNK];  // stage(): a chunk of the labels' keys and boxes
shared vec4 chunk_way[KEEP_APART_CHUNK], chunk_stay[KEEP_APART_CHUNK];
shared uint push_from[3];  // turn r's first settled label clashing with turn_stay, by slot

// Label t's (the invocation's own): its boxes and turn, as scratch holds them.
vec4 my_way = keep_apart_none(), my_stay = keep_apart_none(), my_obstacle = keep_apart_none();
uint my_rank = KEEP_APART_NO_RANK;

// The group's barrier, after which what any invocation wrote to scratch is visible to all.
void sync() {
  memoryBarrierBuffer();
  memoryBarrierShared();
  barrier();
}

// The group's barrier for the turns, which share only shared memory (each invocation's scratch
// entries are its own then): no device-wide fence per turn.
void sync_shared() {
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

void settle(uint i, uint clash_bits) {
  LabelStateGpu state = keep_apart_settle(labels[i], targets[i], states[i], scratch[i].moved,
                                          params, clash_bits, keep_apart_none());
  states[i] = state;
  drawn[i] = keep_apart_drawn(labels[i], targets[i], state, params);
  scratch[i].obstacle = keep_apart_obstacle(labels[i], state);
}

// Each label's key (class, then position in the order) and its boxes.
void start(uint t) {
  for (uint i = t; i < params.label_count; i += KEEP_APART_GROUP) {
    scratch[i].key = params.order_count + i;
  }
  if (t == 0u) {
    turns = 0u;
    clashes[0] = 0u;
    push_from[0] = kNoLabel;
  }
  sync();
  for (uint k = t; k < params.order_count; k += KEEP_APART_GROUP) {
    if (order[k] < params.label_count) scratch[order[k]].key = k;
  }
  sync();
  for (uint i = t; i < params.label_count; i += KEEP_APART_GROUP) {
    uint c = keep_apart_class(labels[i], targets[i], states[i]);
    scratch[i].key = c * KEEP_APART_CLASS_STRIDE + scratch[i].key;
    const LabelStateGpu moved = forces_update(labels[i], targets[i], states[i], params);
    scratch[i].moved = moved;
    scratch[i].way = keep_apart_way(labels[i], targets[i], states[i], moved, params);
    scratch[i].stay = keep_apart_stay(labels[i], states[i], params);
    scratch[i].obstacle = scratch[i].stay;
  }
  if (t < params.label_count) {
    my_way = scratch[t].way;
    my_stay = my_obstacle = scratch[t].stay;
  }
  sync();
}

// The labels [base, base + KEEP_APART_CHUNK) staged in shared memory for the group's scans over
// every label (each invocation reads all of them: from shared memory, not one after another from
// the buffer).
void stage(uint t, uint base) {
  sync();
  if (t < KEEP_APART_CHUNK && base + t < params.label_count) {
    chunk_key[t] = scratch[base + t].key;
    chunk_way[t] = scratch[base + t].way;
    chunk_stay[t] = scratch[base + t].stay;
  }
  sync();
}

// Which labels take turns: those taking part with a box that may clash with another's. The
// others settle now (their state and obstacle are final; their key leaves the ranking). (rank
// holds whether a label is alone while the chunks are scanned.)
void sort_out(uint t) {
  for (uint i = t; i < params.label_count; i += KEEP_APART_GROUP) {
    scratch[i].rank = KEEP_APART_NO_RANK;
  }
  for (uint base = 0u; base < params.label_count; base += KEEP_APART_CHUNK) {
    stage(t, base);
    const uint end = min(base + KEEP_APART_CHUNK, params.label_count);
    for (uint i = t; i < params.label_count; i += KEEP_APART_GROUP) {
      if (scratch[i].key >= kNone || scratch[i].rank != KEEP_APART_NO_RANK) continue;
      const vec4 way = scratch[i].way, stay = scratch[i].stay;
      const float c = params.clearance;
      bool alone = true;
      for (uint j = base; j < end; ++j) {
        if (j == i || chunk_key[j - base] >= kNone) continue;
        const vec4 other_way = chunk_way[j - base], other_stay = chunk_stay[j - base];
        alone = alone && !(boxes_clash(way, other_way, c) || boxes_clash(way, other_stay, c) ||
                           boxes_clash(stay, other_way, c) || boxes_clash(stay, other_stay, c));
      }
      if (!alone) scratch[i].rank = 0u;
    }
  }
  sync();
  for (uint i = t; i < params.label_count; i += KEEP_APART_GROUP) {
    if (scratch[i].key >= kNone || scratch[i].rank == KEEP_APART_NO_RANK) {
      settle(i, keep_apart_cut(scratch[i].way, scratch[i].stay, params));
      scratch[i].key = kNone;
      if (i == t) my_obstacle = scratch[i].obstacle;
    }
  }
}

// Each turn: how many labels taking turns come before it.
void rank(uint t) {
  for (uint base = 0u; base < params.label_count; base += KEEP_APART_CHUNK) {
    stage(t, base);
    const uint end = min(base + KEEP_APART_CHUNK, params.label_count);
    for (uint i = t; i < params.label_count; i += KEEP_APART_GROUP) {
      const uint key = scratch[i].key;
      if (key >= kNone) continue;
      uint before = 0u;
      for (uint j = base; j < end; ++j) before += chunk_key[j - base] < key ? 1u : 0u;
      scratch[i].rank += before;
    }
  }
  sync();
  for (uint i = t; i < params.label_count; i += KEEP_APART_GROUP) {
    if (scratch[i].key >= kNone) continue;
    const uint r = scratch[i].rank;
    if (i == t) my_rank = r;
    atomicOr(turn_label[r / 2u], i << (16u * (r % 2u)));
    atomicAdd(turns, 1u);
  }
  sync();
}

// Whether this turn's boxes clash with label j's obstacle (j taking turns, not `i`): its way with
// any, where it is with one settled before turn r (then j may be what it slides away from).
uint clash_bits(uint j, uint rank_j, vec4 obstacle, uint i, uint r) {
  if (j == i || rank_j == KEEP_APART_NO_RANK) return 0u;
  uint bits = boxes_clash(turn_way, obstacle, params.clearance) ? KEEP_APART_WAY : 0u;
  if (rank_j < r && boxes_clash(turn_stay, obstacle, params.clearance)) {
    bits |= KEEP_APART_STAY;
    atomicMin(push_from[r % 3u], j);
  }
  return bits;
}

// Whether where the label would slide to clashes with label j's boxes of this frame.
uint push_bits(uint j, vec4 way, vec4 stay, uint i) {
  if (j == i) return 0u;
  const float c = params.clearance;
  return boxes_clash(turn_push, way, c) || boxes_clash(turn_push, stay, c) ? KEEP_APART_PUSH : 0u;
}

// A turn's slide (keep_apart_push): away from the first settled label that clashes with where
// the label is, tested against every other label's boxes. Returns the box (none if too far).
vec4 try_push(uint t, uint i, uint r) {
  const uint from = push_from[r % 3u];
  if (from % KEEP_APART_GROUP == t) {
    turn_push = keep_apart_push(turn_stay, from == t ? my_obstacle : scratch[from].obstacle, params);
  }
  sync_shared();
  uint bits = t < params.label_count ? push_bits(t, my_way, my_stay, i) : 0u;
  for (uint j = t + KEEP_APART_GROUP; j < params.label_count; j += KEEP_APART_GROUP) {
    bits |= push_bits(j, scratch[j].way, scratch[j].stay, i);
  }
  if (bits != 0u) atomicOr(clashes[r % 3u], bits);
  sync_shared();
  return turn_push;
}

void take_turns(uint t) {
  for (uint r = 0u; r < turns; ++r) {
    const uint i = (turn_label[r / 2u] >> (16u * (r % 2u))) & 0xFFFFu;
    const bool owner = i % KEEP_APART_GROUP == t;
    LabelGpu label;
    PlacementGpu target;
    LabelStateGpu state, moved;
    if (owner) {
      const vec4 way = i == t ? my_way : scratch[i].way;
      const vec4 stay = i == t ? my_stay : scratch[i].stay;
      turn_way = way;
      turn_stay = stay;
      const uint cut = keep_apart_cut(way, stay, params);
      if (cut != 0u) atomicOr(clashes[r % 3u], cut);
      clashes[(r + 1u) % 3u] = 0u;  // (last read in turn r - 2, before turn r - 1's barrier)
      push_from[(r + 1u) % 3u] = kNoLabel;
      label = labels[i];  // (loaded while the group waits)
      target = targets[i];
      state = states[i];
      moved = scratch[i].moved;
    }
    sync_shared();
    uint bits = t < params.label_count ? clash_bits(t, my_rank, my_obstacle, i, r) : 0u;
    for (uint j = t + KEEP_APART_GROUP; j < params.label_count; j += KEEP_APART_GROUP) {
      bits |= clash_bits(j, scratch[j].rank, scratch[j].obstacle, i, r);
    }
    if (bits != 0u) atomicOr(clashes[r % 3u], bits);
    sync_shared();
    // Its way taken, and where it is clashing with a box: it may slide out (the same for all).
    const bool push = (clashes[r % 3u] & KEEP_APART_WAY) != 0u && push_from[r % 3u] != kNoLabel;
    const vec4 pushed = push ? try_push(t, i, r) : keep_apart_none();
    if (owner) {
      uint c = clashes[r % 3u];
      if (push && !box_inside(pushed, params)) c |= KEEP_APART_PUSH;
      state = keep_apart_settle(label, target, state, moved, params, c, pushed);
      states[i] = state;
      drawn[i] = keep_apart_drawn(label, target, state, params);
      const vec4 obstacle = keep_apart_obstacle(label, state);
      if (i == t) {
        my_obstacle = obstacle;
      } else {
        scratch[i].obstacle = obstacle;
      }
    }
  }
}

void main() {
  const uint t = gl_LocalInvocationID.x;
  if (params.trial != 0u || params.keep_apart == 0u) {
    for (uint i = t; i < params.label_count; i += KEEP_APART_GROUP) move_alone(i);
    return;
  }
  for (uint k = t; k < LABEL_MAX / 2u; k += KEEP_APART_GROUP) turn_label[k] = 0u;
  start(t);
  sort_out(t);
  rank(t);
  take_turns(t);
}
