// The tidy-up's steps but the search (placement_tidy.comp, placement_tidy_large.comp): its start,
// the conflicts, owners and select steps of each round, and the placements' output.
shared uint s_any;
shared ivec4 s_conflicts;  // TIDY_PHASE_CONFLICTS: the workgroup's label's, summed

// TIDY_PHASE_START: each label's state from the loop's result, and round 0 marked to run.
void tidy_start(uint t, uint n) {
  if (t <= params.tidy_rounds) rounds[t] = t == 0u ? 1u : 0u;
  if (t == 0u && params.tidy_rounds > 0u) write_round_args(0u);  // (the rest start at zero)
  if (t >= n) return;
  tidy[t].label = tidy_label(labels[t], results[t]);
  tidy[t].free = tidy_free_cost(tidy[t].label, labels[t]);
  tidy[t].rank = LABEL_MAX;  // (not in the order)
  tidy[t].take = 0u;
  for (uint k = 0u; k < params.order_count; ++k) {
    if (order[k] == t) tidy[t].rank = k;
  }
}

// TIDY_PHASE_CONFLICTS and TIDY_PHASE_SELECT of round r: one workgroup per label i, its
// invocations splitting the other labels between them.
void tidy_label_step(uint phase, uint r) {
  const uint i = gl_WorkGroupID.x, lane = gl_LocalInvocationID.x;
  if (lane == 0u) {
    s_any = 0u;
    s_conflicts = ivec4(0);
  }
  barrier();
  bool any = false;
  if (phase == TIDY_PHASE_CONFLICTS) {
    const ivec4 c = tidy_conflicts_of(i, lane, gl_WorkGroupSize.x);
    if (c != ivec4(0)) {
      atomicAdd(s_conflicts.x, c.x);
      atomicAdd(s_conflicts.y, c.y);
      atomicAdd(s_conflicts.z, c.z);
      atomicAdd(s_conflicts.w, c.w);
    }
  } else {
    any = tidy_partner(i) != TIDY_NO_PARTNER && tidy_blocked(i, lane, gl_WorkGroupSize.x);
  }
  if (any) atomicOr(s_any, 1u);
  barrier();
  if (lane != 0u) return;
  if (phase == TIDY_PHASE_CONFLICTS) {
    // (the label's state after the round before, stored: the steps after this one read
    // `label`; `take` stays until the owners step, so every workgroup of this one sees the same)
    if (tidy[i].take != 0u) {
      tidy[i].label = tidy[i].next;
      tidy[i].free = tidy_free_cost(tidy[i].next, labels[i]);
    }
    tidy[i].best = TIDY_NONE;
    tidy[i].conflicts = s_conflicts;
    tidy[i].conflicted = movable(i) && s_conflicts != ivec4(0) ? 1u : 0u;
  } else if (tidy_partner(i) != TIDY_NO_PARTNER && s_any == 0u) {
    // Owner i's change is applied: its labels take their next states.
    tidy[i].take = 1u;
    tidy[tidy_partner(i)].take = 1u;
    atomicAdd(rounds[r + 1u], 1u);
    if (r + 1u < params.tidy_rounds) write_round_args(r + 1u);
  }
}

// TIDY_PHASE_OWNERS: per label, the change it owns and its state after it.
void tidy_owners(uint t) {
  tidy[t].partner = tidy_owned_partner(t);
  tidy[t].next = tidy_after(t);
  tidy[t].take = 0u;
}

void main() {
  const uint t = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                 gl_LocalInvocationID.x;
  const uint n = params.label_count;
  const uint phase = params.phase;  // (the same for the whole dispatch, as is the round's count)
  if (phase == TIDY_PHASE_START) {
    tidy_start(t, n);
  } else if (phase == TIDY_PHASE_OUTPUT) {
    load_states(n, phase);
    if (t < n) placements[t] = tidy_placement(t, results[t]);
  } else if (rounds[params.step] != 0u) {  // (a round after one that applied nothing: none)
    load_states(n, phase);
    if (phase == TIDY_PHASE_CONFLICTS || phase == TIDY_PHASE_SELECT) {
      tidy_label_step(phase, params.step);
    } else if (t < n) {
      tidy_owners(t);
    }
  }
}
