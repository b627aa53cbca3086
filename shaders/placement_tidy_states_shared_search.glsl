// The tidy-up search's copy of the labels' states.
// (the search reads only the states, free costs and ranks, so its workgroups keep 10 KB of shared
// memory instead of 21.5 and more of them fit an SM)
uint64_t tidy_best(uint k) { return tidy[k].best; }
TidyLabel tidy_next(uint k) { return tidy[k].next; }
uint tidy_partner(uint k) { return tidy[k].partner; }

// The workgroup's copy of the labels' states.
void load_states(uint n, uint phase) {
  for (uint k = gl_LocalInvocationID.x; k < n; k += gl_WorkGroupSize.x) {
    s_label[k] = tidy[k].label;
    s_free[k] = tidy[k].free;
    s_rank[k] = tidy[k].rank;
  }
  barrier();
}
