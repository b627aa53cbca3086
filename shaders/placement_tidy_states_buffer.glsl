// The tidy-up's label states read from the buffer (placement_tidy_large.comp and
// placement_tidy_search_large.comp, past TIDY_SHARED_MAX labels).
// A round's dispatches read every label's state many times over (each change is weighed against
// all labels): with up to TIDY_SHARED_MAX labels (placement_tidy.comp) each workgroup copies
// what its phase reads into shared memory first. (Read from the buffer, a round took 40 us or
// more on an H100, latency-bound.) With more (placement_tidy_large.comp, TIDY_STATES_IN_BUFFER)
// the phases read the buffer: no phase writes what it reads (the search writes the bests, the
// owners the partners and next states, the apply states it does not read), so the copy is only a
// cache. (Two shaders, so that the small case's reads are plain shared-memory loads with no
// choice made per read.)
// (if, not ?: a selection between two buffer structs stored elsewhere makes glslang write
// invalid SPIR-V)
TidyLabel tidy_state(uint k) {
  if (tidy_takes(params.phase) && tidy[k].take != 0u) return tidy[k].next;
  return tidy[k].label;
}
float tidy_free(uint k) {
  return tidy_takes(params.phase) && tidy[k].take != 0u ? tidy_free_cost(tidy[k].next, labels[k])
                                                        : tidy[k].free;
}
uint tidy_rank(uint k) { return tidy[k].rank; }
uint64_t tidy_best(uint k) { return tidy[k].best; }
TidyLabel tidy_next(uint k) { return tidy[k].next; }
uint tidy_partner(uint k) { return tidy[k].partner; }
void load_states(uint n, uint phase) {}
