// The labels' states read from the buffer, past TIDY_SHARED_MAX labels (placement_tidy_large.comp,
// placement_tidy_search_large.comp; placement_tidy_states_shared.glsl says why a copy below that).
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
