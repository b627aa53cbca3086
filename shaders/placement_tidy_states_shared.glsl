// The tidy-up steps' label states in shared memory (placement_tidy.comp, up to TIDY_SHARED_MAX
// labels).
// A round's dispatches read every label's state many times over (each change is weighed against
// all labels): with up to TIDY_SHARED_MAX labels (placement_tidy.comp) each workgroup copies
// what its phase reads into shared memory first. (Read from the buffer, a round took 40 us or
// more on an H100, latency-bound.) With more (placement_tidy_large.comp, TIDY_STATES_IN_BUFFER)
// the phases read the buffer: no phase writes what it reads (the search writes the bests, the
// owners the partners and next states, the apply states it does not read), so the copy is only a
// cache. (Two shaders, so that the small case's reads are plain shared-memory loads with no
// choice made per read.)
shared TidyLabel s_label[TIDY_SHARED_MAX];
shared float s_free[TIDY_SHARED_MAX];
shared uint s_rank[TIDY_SHARED_MAX];
TidyLabel tidy_state(uint k) { return s_label[k]; }
float tidy_free(uint k) { return s_free[k]; }
uint tidy_rank(uint k) { return s_rank[k]; }
shared TidyLabel s_next[TIDY_SHARED_MAX];
shared uint64_t s_best[TIDY_SHARED_MAX];
shared uint s_partner[TIDY_SHARED_MAX];
uint64_t tidy_best(uint k) { return s_best[k]; }
TidyLabel tidy_next(uint k) { return s_next[k]; }
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
