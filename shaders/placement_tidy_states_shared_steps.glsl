// The tidy-up steps' copy of the labels' states, the bests, next states and partners included.
shared TidyLabel s_next[TIDY_SHARED_MAX];
TidyLabel tidy_next(uint k) { return s_next[k]; }
shared uint64_t s_best[TIDY_SHARED_MAX];
uint64_t tidy_best(uint k) { return s_best[k]; }
shared uint s_partner[TIDY_SHARED_MAX];
uint tidy_partner(uint k) { return s_partner[k]; }

// The workgroup's copy of the labels' states (the bests only after the search has them).
void load_states(uint n, uint phase) {
  for (uint k = gl_LocalInvocationID.x; k < n; k += gl_WorkGroupSize.x) {
    const bool taken = tidy_takes(phase) && tidy[k].take != 0u;
    if (taken) {  // (not ?: as in tidy_state of placement_tidy_states_buffer.glsl)
      s_label[k] = tidy[k].next;
    } else {
      s_label[k] = tidy[k].label;
    }
    // (the conflicts step reads no free costs)
    s_free[k] = taken && phase == TIDY_PHASE_OUTPUT ? tidy_free_cost(tidy[k].next, labels[k])
                                                    : tidy[k].free;
    s_rank[k] = tidy[k].rank;
    if (phase != TIDY_PHASE_CONFLICTS && phase != TIDY_PHASE_SEARCH) s_best[k] = tidy[k].best;
    if (phase == TIDY_PHASE_SELECT) {
      s_next[k] = tidy[k].next;
      s_partner[k] = tidy[k].partner;
    }
  }
  barrier();
}
