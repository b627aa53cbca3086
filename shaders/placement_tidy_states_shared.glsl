// The labels' states in shared memory, up to TIDY_SHARED_MAX labels (TIDY_STATES_SHARED:
// placement_tidy.comp, placement_tidy_search.comp). A round's dispatches read every label's state
// many times over (each change is weighed against all labels), so each workgroup copies what its
// phase reads into shared memory first (read from the buffer, a round was latency-bound:
// docs/performance.md). Past that count (placement_tidy_states_buffer.glsl) the phases read the
// buffer: no phase writes what it reads (the search writes the bests, the owners the partners and
// next states, the apply states it does not read), so the copy is only a cache. (Two variants, so
// that the small case's reads are plain shared-memory loads with no choice made per read.)
shared TidyLabel s_label[TIDY_SHARED_MAX];
shared float s_free[TIDY_SHARED_MAX];
shared uint s_rank[TIDY_SHARED_MAX];
TidyLabel tidy_state(uint k) { return s_label[k]; }
float tidy_free(uint k) { return s_free[k]; }
uint tidy_rank(uint k) { return s_rank[k]; }

#ifdef TIDY_SEARCH
// The search's copy: only the states, free costs and ranks, so its workgroups keep 10 KB of
// shared memory instead of 21.5 and more of them fit an SM.
uint64_t tidy_best(uint k) { return tidy[k].best; }
TidyLabel tidy_next(uint k) { return tidy[k].next; }
uint tidy_partner(uint k) { return tidy[k].partner; }

void load_states(uint n, uint phase) {
  for (uint k = gl_LocalInvocationID.x; k < n; k += gl_WorkGroupSize.x) {
    s_label[k] = tidy[k].label;
    s_free[k] = tidy[k].free;
    s_rank[k] = tidy[k].rank;
  }
  barrier();
}
#else
// The steps' copy, the bests, next states and partners included.
shared TidyLabel s_next[TIDY_SHARED_MAX];
TidyLabel tidy_next(uint k) { return s_next[k]; }
shared uint64_t s_best[TIDY_SHARED_MAX];
uint64_t tidy_best(uint k) { return s_best[k]; }
shared uint s_partner[TIDY_SHARED_MAX];
uint tidy_partner(uint k) { return s_partner[k]; }

// (the bests only after the search has them)
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
#endif
