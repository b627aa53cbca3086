// Included by place_label.comp: a final label's constraint regions against the labels after it.
// Dispatch j's region writer writes label j - 2's for the labels from j + 1 on; its last
// workgroup, label j - 1's for labels j and j + 1 (the next dispatch's passes need those).

// The regions of the labels at order positions first .. last - 1 against the one at position s,
// placed at `placed` (two invocations per label: its box half and its connector half).
void write_regions(uint s, uint first, uint last, LabelGpu placed_label, vec3 placed) {
  const uint threads = PLACE_GROUP_X * PLACE_GROUP_Y;
  for (uint u = gl_LocalInvocationIndex; first + u / 2u < last; u += threads) {
    const uint k_pos = first + u / 2u;
    const uint slot = placement_pair_slot(k_pos, s);
    const LabelGpu k = labels[order[k_pos]];
    if ((u & 1u) == 0u) {
      const PairBoxRegion r = pair_box_region(k, placed_label, placed, params.margin);
      regions[slot].box = r.box;
      regions[slot].info = r.info;
    } else {
      regions[slot].connector = pair_connector_region(k, placed_label, placed, params.margin).p;
    }
  }
}

// The region writer of dispatch j: label j - 2, final since the last dispatch, against the labels
// from j + 1 on (the ones up to j have them from that dispatch's last workgroup).
void write_later_regions(uint j) {
  const uint s = order[j - 2u];
  write_regions(j - 2u, j + 1u, params.order_count, labels[s], placed_from(results[s], s));
}
