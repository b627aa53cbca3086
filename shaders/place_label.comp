#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "shared/placement.h"

// The greedy label loop, one dispatch per step: constraints, eq. 3.1 and the argmin over
// lists of 32x32 tiles (placement_bounds.comp sorted each label's tiles into buckets by a lower
// bound of their cost without constraints). Dispatch j has four kinds of workgroups:
//  - CLASSIFY, the label at order position j: its list entries past bucket 0 against the labels
//    placed up to j - 2 and the anchors: the constraint bits every candidate of a tile has, and
//    four sampled candidates' costs (place_label_classify.glsl).
//  - MAIN, the label at order position j - 1: the tiles its best may still lie in. Bucket 0's
//    tiles were evaluated by the speculative pass of the dispatch before; of those, only the ones
//    label j - 2's regions reach are evaluated again, the others hand on their minimum.
//  - SPEC, the label at order position j: its bucket-0 tiles, with the constraints of the labels
//    up to j - 2 (j - 1 is not final yet), a minimum per tile and no pruning. Both passes'
//    workgroups evaluate tiles of candidates (place_label_evaluate.glsl).
//  - one region writer: label j - 2's constraint regions for the labels from j + 1 on
//    (place_label_regions.glsl).
// The main pass's workgroups meet in results[label] with one 64-bit atomicMin each; the
// dispatch's last workgroup finds label j - 1 final, writes its regions for labels j and j + 1,
// bounds label j's best by the true cost of its speculative winners and samples (their cost plus
// what j - 1's regions add there), and keeps, for j's main pass, the classified entries whose
// bound with their bits does not exceed that (place_label_finish.glsl). A dispatch is either
// indirect, of that size, or direct, of enough workgroups for any counts, those past them leaving
// at once (Placement chooses: see LabelDispatch). The loop never returns to the CPU, and a
// label's speculative pass and classification are off the chain of dependent dispatches.
layout(local_size_x = PLACE_GROUP_X, local_size_y = PLACE_GROUP_Y) in;
layout(binding = PLACEMENT_BINDING_TABLES, std430) readonly buffer Tables { float tables[]; };
layout(binding = PLACEMENT_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = PLACEMENT_BINDING_ORDER, std430) readonly buffer Order { uint order[]; };
// coherent: a tile's read of its label's best so far (evaluate_tile) sees other workgroups'
// atomicMin results (a stale value is only a weaker bound, never a wrong one: results only
// decrease).
layout(binding = PLACEMENT_BINDING_RESULTS, std430) coherent buffer Results { uint64_t results[]; };
layout(binding = PLACEMENT_BINDING_CONSTRAINTS, std430) writeonly buffer Constraints { uint constraints[]; };
layout(binding = PLACEMENT_BINDING_BUCKETS, std430) coherent buffer Buckets { PlacementBucketsGpu buckets[]; };
// Written past bucket 0: the classification's bits in label j's list (read in the next dispatch)
// and, by the dispatch's last workgroup, label j's main pass moved up.
layout(binding = PLACEMENT_BINDING_TILES, std430) coherent buffer Tiles { uvec2 tile_list[]; };
layout(binding = PLACEMENT_BINDING_ARGS, std430) writeonly buffer Args { uint args[]; };
layout(binding = PLACEMENT_BINDING_SPECULATIVE, std430) coherent buffer Speculative { uint64_t speculative[]; };
// Read for the labels being placed and classified (written by earlier dispatches); written, once
// a label is final, for the labels after it (rows no workgroup of the same dispatch reads).
layout(binding = PLACEMENT_BINDING_REGIONS, std430) buffer Regions { PairRegionsGpu regions[]; };
// The classification's cheapest sample per list entry of label j, read by the last workgroup.
layout(binding = PLACEMENT_BINDING_SAMPLES, std430) coherent buffer Samples { uint64_t samples[]; };
layout(binding = PLACEMENT_BINDING_KEEP_OUT, std430) readonly buffer KeepOut { uvec4 keep_out[]; };
layout(push_constant) uniform Push { PlacementParams params; };

// The order position this workgroup places, and the placed ones it tests against (0 .. placed - 1).
uint position;
uint placed;

// Shared by a tile's workgroup (place_label_evaluate.glsl): the placed labels and anchors this
// tile's candidates can reach, culled by chunks of PLACE_CULL_CHUNK labels (one chunk up to that
// many labels; more take turns through the lists).
#define PLACE_CULL_CHUNK (PLACE_GROUP_X * PLACE_GROUP_Y)
shared uint tile_placed[PLACE_CULL_CHUNK];
shared uint tile_placed_count;
shared vec2 tile_anchors[PLACE_CULL_CHUNK];
shared uint tile_anchor_count;
shared uint tile_bits;  // constraints every candidate of the tile has
shared uint tile_hope;  // 1: some candidate's cost without constraints is not above the best
shared uint64_t tile_best;  // the label's best when this workgroup started
shared uint64_t group_best[PLACE_GROUP_X * PLACE_GROUP_Y];  // per subgroup
// A CLASSIFY workgroup's (place_label_classify.glsl), per entry:
shared uint class_bits[PLACEMENT_CLASSIFY_TILES_MAX];  // bits 0-2: every candidate's; 3q + 3..5: sample q's
// The dispatch's passes: the main pass's size and bound, the speculative pass's size, the entries
// of the speculative pass's label's list.
shared uint dispatch_main, dispatch_spec, dispatch_listed;
shared float dispatch_bound;
// The last workgroup's (place_label_finish.glsl):
shared uint finishing;  // 1: this workgroup is the dispatch's last
shared uint bound_bits;  // the bound candidates' smallest true cost (bits)
shared uint kept;  // entries past bucket 0 the main pass takes
shared float finish_lowest;  // the label's lowest tile bound
shared uint finish_ends[PLACEMENT_BUCKETS];  // where each bucket's entries end in its list

// The regions of the label at order position s against the one placed at order position t.
PairRegionsGpu regions_of(uint s, uint t) { return regions[placement_pair_slot(s, t)]; }
// What shared/placement_cost.h asks of its includer (placement_cost_access.h): the placed labels
// and anchors the tile's workgroup culled, and the integral-cost tables.
uint placed_count() { return tile_placed_count; }
PairRegionsGpu placed_regions(uint k) { return regions_of(position, tile_placed[k]); }
uint anchor_count() { return tile_anchor_count; }
vec2 anchor_at(uint k) { return tile_anchors[k]; }
uvec4 keep_out_at(uint i) {
  return keep_out[i];
}
// (The load does not depend on the test, so a candidate's four are issued together; clamped, so
// a candidate off screen reads inside the table.)
float table_at(uint layer, int x, int y) {
  const uint column = uint(clamp(x, 0, int(params.width) - 1));
  const uint row = uint(clamp(y, 0, int(params.height) - 1));
  const float value = tables[(layer * params.height + row) * params.width + column];
  return x < 0 || y < 0 ? 0.0 : value;
}

#include "shared/placement_cost.h"

// A result's key: (cost bits, pixel index), PLACEMENT_NONE when nothing was found; its cost, and
// the box centre of label j there (z = 1; all 0 for none).
vec3 placed_from(uint64_t r, uint j) {
  if (r == PLACEMENT_NONE) return vec3(0.0);
  const uint pixel = uint(r & 0xFFFFFFFFul);
  const uvec2 p = uvec2(pixel % params.width, pixel / params.width);
  return vec3(box_origin(p, labels[j].size) + labels[j].size * 0.5, 1.0);
}
float cost_of(uint64_t key) {
  return key == PLACEMENT_NONE ? uintBitsToFloat(0x7F800000u) : uintBitsToFloat(uint(key >> 32));
}

#include "place_label_tile.glsl"
#include "place_label_classify.glsl"
#include "place_label_evaluate.glsl"
#include "place_label_pass.glsl"
#include "place_label_regions.glsl"
#include "place_label_finish.glsl"

// The sizes of dispatch j's passes and the main pass's bound, into dispatch_* (one invocation
// reads them: thousands of workgroups read the same few words).
void read_dispatch_sizes(uint j) {
  if (gl_LocalInvocationIndex == 0u) {
    dispatch_main = j > 0u ? buckets[j - 1u].main : 0u;
    dispatch_bound = j > 0u ? buckets[j - 1u].bound : 0.0;
    uint count0 = 0u, listed = 0u;
    if (j < params.order_count) {
      count0 = buckets[j].counts[0];
      [[unroll]] for (uint b = 0u; b < PLACEMENT_BUCKETS; ++b) listed += buckets[j].counts[b];
    }
    dispatch_spec = count0;
    dispatch_listed = listed;
  }
}

// The main pass's minimum into results, then this workgroup counts itself finished: the last of
// the `working` workgroups finishes the dispatch (`finishing`, and finish()'s shared state set).
void count_finished(uint j, uint working, uint64_t main_group) {
  if (gl_LocalInvocationIndex == 0u) {
    // Thousands of workgroups share one address: only those that improve on it touch it.
    if (main_group != PLACEMENT_NONE && main_group < results[params.label]) {
      atomicMin(results[params.label], main_group);
    }
    memoryBarrierBuffer();
    finishing = atomicAdd(buckets[j].done, 1u) + 1u == working ? 1u : 0u;
    if (finishing != 0u) {
      bound_bits = 0x7F800000u;
      kept = 0u;
      memoryBarrierBuffer();
    }
  }
}

void main() {
  const uint j = params.step;  // this dispatch: MAIN for position j - 1, SPEC for position j
  const uint w = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  read_dispatch_sizes(j);
  barrier();
  const uint main_count = dispatch_main, spec_count = dispatch_spec, listed = dispatch_listed;
  const float best_bound = dispatch_bound;
  const uint classify_count = placement_classify_groups(listed - spec_count, params.classify_tiles);
  // The workgroups: the classification's (first, so that they start at once), the passes', and
  // the region writer. The passes' items are the main pass's tiles, then the speculative pass's;
  // a dispatch with fewer workgroups for them (a direct one: see LabelDispatch) has each take
  // every so many. Those past all this leave at once. The last to finish sizes the next dispatch.
  const uint items = main_count + spec_count;
  const uint groups = gl_NumWorkGroups.x * gl_NumWorkGroups.y;
  const uint stride = min(items, groups - classify_count - 1u);
  const uint working = classify_count + stride + 1u;
  if (w >= working) return;
  if (w + 1u == working && j >= 2u && j + 1u < params.order_count) write_later_regions(j);
  const bool is_classify = w < classify_count;
  if (is_classify) classify(j, w, spec_count, listed);
  uint64_t main_group = PLACEMENT_NONE;
  const bool has_items = !is_classify && w + 1u < working;
  for (uint item = w - classify_count; has_items && item < items; item += stride) {
    const uint64_t group = pass_item(j, item, main_count, best_bound);
    if (item < main_count) main_group = min(main_group, group);
  }
  count_finished(j, working, main_group);
  barrier();
  if (finishing != 0u) finish(j);
}
