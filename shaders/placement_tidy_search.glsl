// The tidy-up's search step (TIDY_SEARCH: placement_tidy_search.comp and its _large variant).
// The pair at position p of (0, 1), (0, 2) ... (0, n - 1), (1, 2) ...: row i starts at
// i (2n - i - 1) / 2. (The root gives the row to within one or two; integers settle it. A loop
// over the rows cost an invocation up to n steps.)
uvec2 pair_at(uint p, uint n) {
  const float b = float(2u * n - 1u);
  int i = int(floor((b - sqrt(max(b * b - 8.0 * float(p), 0.0))) * 0.5));
  i = clamp(i, 0, int(n) - 2);
  while (i > 0 && uint(i) * (2u * n - uint(i) - 1u) / 2u > p) --i;
  while (uint(i) + 2u < n && (uint(i) + 1u) * (2u * n - uint(i) - 2u) / 2u <= p) ++i;
  const uint row = uint(i);
  return uvec2(row, row + 1u + p - row * (2u * n - row - 1u) / 2u);
}

// TIDY_PHASE_SEARCH: item q is (label, move or hiding) below n x TIDY_SWAP, a pair of labels
// (i < j) above; TIDY_SEARCH_LANES invocations take an item, splitting the other labels.
shared ivec4 s_counts[64 / TIDY_SEARCH_LANES];
shared uint s_hide[64 / TIDY_SEARCH_LANES];

void search(uint t, uint n) {
  const uint q = t / TIDY_SEARCH_LANES, lane = t % TIDY_SEARCH_LANES;
  const uint slot = gl_LocalInvocationID.x / TIDY_SEARCH_LANES;
  const uint singles = n * TIDY_SWAP;
  uint i = 0u, change = 0u;
  bool live = false;
  // (A workgroup whose items could change nothing leaving before it copied the states, deciding
  // that from the buffer, made the tidy-up slower on a GPU.)
  load_states(n, TIDY_PHASE_SEARCH);
  if (q < singles) {
    i = q / TIDY_SWAP;
    change = q % TIDY_SWAP;
    live = tidy[i].conflicted != 0u;
  } else if (q < singles + n * (n - 1u) / 2u) {
    const uvec2 pair = pair_at(q - singles, n);
    i = pair.x;
    change = TIDY_SWAP + pair.y;
    if (movable(pair.x) && movable(pair.y)) {
      const ivec4 c = tidy_conflicts(tidy_state(pair.x), tidy_state(pair.y));
      live = c.x + c.y != 0;
    }
  }
  live = live && tidy_change_possible(i, change);
  if (lane == 0u) {
    s_counts[slot] = ivec4(0);
    s_hide[slot] = 0u;
  }
  barrier();
  if (live) {
    const ivec4 c = tidy_change_conflicts(i, change, lane, TIDY_SEARCH_LANES);
    if (c != ivec4(0)) {
      atomicAdd(s_counts[slot].x, c.x);
      atomicAdd(s_counts[slot].y, c.y);
      atomicAdd(s_counts[slot].z, c.z);
      atomicAdd(s_counts[slot].w, c.w);
    }
    if (change == TIDY_HIDE && tidy_may_hide(i, lane, TIDY_SEARCH_LANES)) atomicOr(s_hide[slot], 1u);
  }
  barrier();
  if (!live || lane != 0u || (change == TIDY_HIDE && s_hide[slot] == 0u)) return;
  const float delta = tidy_change_delta(i, change, s_counts[slot]);
  if (delta >= 0.0f) return;
  atomicMin(tidy[i].best, tidy_key(delta, change));
  if (change >= TIDY_SWAP) atomicMin(tidy[change - TIDY_SWAP].best, tidy_key(delta, TIDY_SWAP + i));
}

void main() {
  // (the search's items can pass 65535 workgroups across: its dispatch is two-dimensional)
  const uint t = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                 gl_LocalInvocationID.x;
  // A round: nothing to do once the round before applied nothing.
  if (rounds[params.step] != 0u) search(t, params.label_count);  // (the same for the whole dispatch)
}
