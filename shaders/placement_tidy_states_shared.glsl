// The labels' states in shared memory, up to TIDY_SHARED_MAX labels (placement_tidy.comp,
// placement_tidy_search.comp). A round's dispatches read every label's state many times over
// (each change is weighed against all labels), so each workgroup copies what its phase reads into
// shared memory first (read from the buffer, a round was latency-bound: docs/performance.md).
// Past that count (placement_tidy_states_buffer.glsl) the phases read the buffer: no phase writes
// what it reads (the search writes the bests, the owners the partners and next states, the apply
// states it does not read), so the copy is only a cache. (Two shaders, so that the small case's
// reads are plain shared-memory loads with no choice made per read.) The steps' and the search's
// load_states are in placement_tidy_states_shared_steps.glsl and
// placement_tidy_states_shared_search.glsl.
shared TidyLabel s_label[TIDY_SHARED_MAX];
shared float s_free[TIDY_SHARED_MAX];
shared uint s_rank[TIDY_SHARED_MAX];
TidyLabel tidy_state(uint k) { return s_label[k]; }
float tidy_free(uint k) { return s_free[k]; }
uint tidy_rank(uint k) { return s_rank[k]; }
