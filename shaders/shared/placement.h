// Label placement on the GPU (thesis 3.2, 4.1): saliency, integral costs, and one fused
// constraints + cost (eq. 3.1) + argmin dispatch per label (place_label.comp). Written once for
// C++ and GLSL.
#ifndef STRATA_SHARED_PLACEMENT_H
#define STRATA_SHARED_PLACEMENT_H

#include "labels.h"

#define PLACEMENT_GROUP 16  // per-pixel passes: 16 x 16 threads per workgroup
#define PLACEMENT_TILE 32   // place_label: 32 x 32 candidates per workgroup ...
#define PLACE_GROUP_X 16    // ... of 16 x 16 threads, 2 x 2 candidates each (16 x 8
#define PLACE_GROUP_Y 16    // and 8 x 8 ran slower, 32 x 16 no faster: docs/performance.md)
#define PLACE_SPAN_X (PLACEMENT_TILE / PLACE_GROUP_X)  // candidates per invocation across ...
#define PLACE_SPAN_Y (PLACEMENT_TILE / PLACE_GROUP_Y)  // ... and down
#define PLACEMENT_CELL 4               // placement_bounds: 4 x 4 candidates per cell, ...
#define PLACEMENT_BOUNDS_GROUP 256     // ... a workgroup of 256 invocations, ...
#define PLACEMENT_BOUNDS_TILES 4       // ... one cell each: 4 tiles
#define VR_MAX_LAYERS_FOR_PLACEMENT 8  // as VR_MAX_LAYERS
#define SALIENCY_SCALE 100.0f          // |CIELAB gradient| of this size counts as saliency 1
// Legibility: a box pixel is hidden where the layers in front of the label's composite to at
// least HIDING_ALPHA; a box is legible when at least LEGIBLE_SHARE of its pixels are not hidden.
// The placement's tables hold each layer's hidden pixels after its integral costs (layer_count +
// layer); strata's counts (frame/labelled_render.h) use the same two figures.
#define HIDING_ALPHA 0.5f
#define LEGIBLE_SHARE 0.75f

// Constraint bits (one constraint image, thesis 4.1.1).
#define CONSTRAINT_LABEL 1u      // the new box or connector would touch a placed label's shadow
#define CONSTRAINT_CONNECTOR 2u  // ... a placed connector's shadow
#define CONSTRAINT_ANCHOR 4u     // the new box would cover an anchor

// PairRegionsGpu.info.x
#define REGION_BOX 1u        // the box region is there (the other label is shown)
#define REGION_CONNECTOR 2u  // the connector region is there (... and not internal)

// A packed (cost, pixel) pair no candidate reaches: "not placed".
#define PLACEMENT_NONE 0xFFFFFFFFFFFFFFFFul

#define PLACEMENT_BINDING_FINAL 0     // rgba8 label-free final image
#define PLACEMENT_BINDING_SALIENCY 1  // float per pixel
#define PLACEMENT_BINDING_LAYERS 2    // rgba16f array image, premultiplied
#define PLACEMENT_BINDING_COSTS \
  3                                      // float per pixel per layer (integral costs, eq. 3.3/3.4),
                                         // then per layer 1 where its pixel is hidden, else 0
#define PLACEMENT_BINDING_TABLES 4       // their summed-area tables, same layout
#define PLACEMENT_BINDING_LABELS 5       // LabelGpu[]
#define PLACEMENT_BINDING_ORDER 6        // uint[]: label indices in insertion order
#define PLACEMENT_BINDING_RESULTS 7      // uint64_t[] per label: cost bits << 32 | pixel
#define PLACEMENT_BINDING_CONSTRAINTS 8  // uint per pixel: constraint bits of the last label placed
#define PLACEMENT_BINDING_PLACEMENTS 9   // PlacementGpu[]
#define PLACEMENT_BINDING_BOUNDS 10      // float per order position per tile: lower cost bound
#define PLACEMENT_BINDING_BUCKETS 11     // PlacementBucketsGpu per order position
#define PLACEMENT_BINDING_TILES 12       // uvec2 (tile, bound bits) per order position per tile
#define PLACEMENT_BINDING_LOWER 13       // uint per order position: the smallest tile bound's bits
#define PLACEMENT_BINDING_ARGS 14        // uint[3] per place_label dispatch: its size (indirect)
#define PLACEMENT_BINDING_SPECULATIVE 15  // uint64_t per bucket-0 tile, two labels' worth
#define PLACEMENT_BINDING_REGIONS 16      // PairRegionsGpu per (order position, placed one's)
#define PLACEMENT_BINDING_SAMPLES 17      // uint64_t per tile-list position: a sampled candidate
#define PLACEMENT_BINDING_TIDY 18         // TidyGpu per label: the tidy-up's state
#define PLACEMENT_BINDING_TIDY_ROUNDS 19  // uint per tidy-up round + 1: changes applied before it
#define PLACEMENT_BINDING_TIDY_ARGS 20    // uint[3] per tidy-up round and step: its workgroups
#define PLACEMENT_BINDING_RANKS 21        // uint per label: its order position (LABEL_MAX: none)
#define PLACEMENT_BINDING_ROUND_OF 22     // uint per label: the round it was decided in
#define PLACEMENT_BINDING_ROUND_LIST 23   // uint[]: the labels a round searches again
#define PLACEMENT_BINDING_ROUND_ARGS 24   // uint[3] per round: its search's workgroups
#define PLACEMENT_BINDING_ROUND_COUNTS 25  // uint per round + 1: labels undecided before it
#define PLACEMENT_BINDING_ROUND_BITS 26    // uint[label_count / 32] per label: its conflicts
#define PLACEMENT_BINDING_ROUND_DONE 27    // uint per round: its COMMIT workgroups finished
#define PLACEMENT_BINDING_ROUND_WIDE 28    // uint per label: EVALUATE's workgroups finished, then
                                           // whether WIDE searches on (ROUNDS_GROUPS + 1)
#define PLACEMENT_BINDING_KEEP_OUT 29  // uvec4 per rectangle no box may touch (x0, y0, x1, y1 in
                                      // pixels, [lo, hi)): PlacementParams::keep_out_count of them
#define PLACEMENT_KEEP_OUT_MAX 4u     // the viewer's panel, a picture's title and legend, one spare

// PlacementParams.phase of placement_tidy.comp: the tidy-up's start, the four steps of each
// round (params.step), and the placements' output. The changes a round applies are taken up by
// the next round's conflicts step, or by the output (TidyGpu::take).
#define TIDY_PHASE_START 0u
#define TIDY_PHASE_CONFLICTS 1u  // per label: in some conflict? best change reset
#define TIDY_PHASE_SEARCH 2u     // per (label, move or hiding) and pair: the best changes
#define TIDY_PHASE_OWNERS 3u     // per label: owned change, state after it
#define TIDY_PHASE_SELECT 4u     // per owner: applied unless a better owner's change interacts
#define TIDY_ROUND_STEPS 4u      // dispatches per round
#define TIDY_PHASE_OUTPUT 6u     // per label: the placement

// The tile lists are in bucket order; an entry's x has this bit when its tile is in bucket 0 (the
// speculative pass's). The speculative minima are kept for two labels at a time (by order
// position parity).
#define PLACEMENT_BUCKET0_TILE 0x80000000u
// Bits 28-30 of the x of an entry beyond bucket 0: the constraint bits every candidate of the tile
// has from the labels placed two or more before it (place_label.comp classifies them); the tile's
// index is in the low bits.
#define PLACEMENT_TILE_CLASS_SHIFT 28u
#define PLACEMENT_TILE_INDEX_MASK 0x0FFFFFFFu
// A direct place_label dispatch has at most this many workgroups for the passes' tiles by
// default (about what a large GPU holds at once; past that they take several each), ...
#define PLACEMENT_DIRECT_GROUPS 512u
// ... and classifying workgroups take 4, 8 or 16 list entries each (PlacementParams::
// classify_tiles: as many as keep a label's classification within 256 workgroups).
#define PLACEMENT_CLASSIFY_TILES_MAX 16u

// Tiles are sorted per label into buckets by how far their lower cost bound lies above the
// label's smallest one: bucket 0 below bucket_width, bucket b (1..) below bucket_width * 4^b,
// the last one everything else. A speculative pass evaluates bucket 0's tiles while the label
// before is still being placed, and the rest of the list (in bucket order, so roughly by bound)
// is classified against the constraints known by then; the main pass then takes bucket 0 and
// the classified tiles that may still hold the best.
#define PLACEMENT_BUCKETS 8
#define PLACEMENT_BUCKET_GROWTH 4.0f

// PlacementParams.phase
#define PLACEMENT_PHASE_BOUNDS 0u  // placement_bounds.comp: tile bounds and each label's lowest
#define PLACEMENT_PHASE_COUNT 1u   // ... tiles per bucket
#define PLACEMENT_PHASE_SORT 2u    // ... tiles sorted by bucket, the first dispatch's size

// PlacementParams.phase of place_rounds.comp.
#define ROUNDS_PHASE_MARK 0u      // per undecided label: search again? (the round's list)
#define ROUNDS_PHASE_EVALUATE 1u  // per listed label and searched tile: its cheapest candidate
#define ROUNDS_PHASE_COMMIT 2u    // per undecided label: its conflicts; the last workgroup decides
#define ROUNDS_PHASE_WIDE 3u      // ... the rest of its tiles, where its best is one no label wants
#define ROUNDS_STEPS 4u           // dispatches per round
#define ROUNDS_MAX 256u           // rounds at most (PlacementSettings::rounds)
#define ROUND_UNDECIDED 0xFFFFFFFFu  // a label's round while it has none
#define ROUNDS_NO_RANK 0xFFFFFFFFu   // PLACEMENT_BINDING_RANKS of a label not in the order
#define ROUNDS_DEFAULT 24u           // PlacementSettings::rounds by default
#define ROUNDS_GROUPS 64u            // EVALUATE's workgroups per label (each takes every 64th tile)
#define ROUNDS_SELECT_PASSES 8u      // passes of a round's selection (placement_rounds.h)

// The tidy-up after the greedy placement (shared/tidy.h).
#define TIDY_SUBPIXEL 64.0f
#define TIDY_DIRECTIONS 24u  // move candidates: 24 directions from the anchor ...
#define TIDY_RADII 5u        // ... at 5 distances (tidy_radius)
#define TIDY_MOVES (TIDY_DIRECTIONS * TIDY_RADII)
#define TIDY_HIDE TIDY_MOVES         // change id: hide the label
#define TIDY_SWAP (TIDY_MOVES + 1u)  // change id TIDY_SWAP + j: swap boxes with label j
#define TIDY_NONE 0xFFFFFFFFFFFFFFFFul
#define TIDY_NO_PARTNER 0xFFFFFFFFu
#define TIDY_ROUNDS_MAX 256u  // PlacementParams::tidy_rounds at most
#define TIDY_SHARED_MAX 256u  // labels whose states a tidy-up workgroup keeps in shared memory
#define TIDY_SEARCH_LANES 8u  // invocations weighing one change (placement_tidy.comp)

// TidyLabel.flags
#define TIDY_PLACED 1u   // the label has a box (placed, and not hidden by the tidy-up)
#define TIDY_MOVABLE 2u  // the tidy-up may move it (enabled, external, placed by the greedy loop)
#define TIDY_ANCHOR 4u   // its anchor counts (the label is enabled)

STRATA_BEGIN

// Cost weights of eq. 3.1 (defaults: the thesis program's final paper settings).
struct CostWeightsGpu {
  float distance_to_anchor;   // alpha, per pixel
  float connector_direction;  // beta, times |cos| + |sin|
  float label_shadow;         // gamma
  float connector_shadow;     // delta
  float anchor_constraint;    // epsilon
  float integral_costs;       // zeta, times the integral over the label box
  float previous_position;    // eta, per pixel
  float leader_crossing;      // the tidy-up: per leader crossing or through a box
  float illegible;            // a box the front layers hide (less than LEGIBLE_SHARE visible)
};

struct PlacementParams {
  CostWeightsGpu weights;
  uint width;
  uint height;
  uint layer_count;
  uint label_count;
  uint step;                     // place_label: the dispatch (main pass of order position step - 1,
                                 // speculative pass of step)
  uint hard;                     // 1: constraint violations and illegible boxes are forbidden (the
                                 // label may end up hidden)
  uint write_constraints;        // 1: store the constraint bits of every pixel (tests, debugging)
  float margin;                  // pixels added around label boxes in the constraints
  float saliency_weight;         // eq. 3.3: beta, how much saliency modulates occlusion behind
  float occlusion_weight;        // eq. 3.4 (one layer): alpha
  float single_saliency_weight;  // eq. 3.4: beta
  uint phase;                    // placement_bounds.comp: PLACEMENT_PHASE_*
  float bucket_width;            // cost above the label's lowest tile bound that bucket 0 holds
  uint order_count;              // labels in the insertion order
  uint label;           // place_label: the label at order position step - 1 (main pass) ...
  uint spec_label;      // ... and at step (speculative pass)
  uint finish_lanes;    // place_label: invocations of the last workgroup taking list entries
                        // (0: all; fewer make more chunks, for tests)
  uint classify_tiles;  // place_label: list entries per classifying workgroup (4, 8 or 16)
  uint tidy_rounds;     // placement_tidy: rounds of the tidy-up at most (0: none)
  uint indirect;        // 1: the tidy-up rounds are indirect dispatches (PlacementPlan)
  float edge;           // pixels a box keeps clear of the image's edges
  uint keep_out_count;  // rectangles no box may touch (PLACEMENT_BINDING_KEEP_OUT): the viewer's
                        // panel, a picture's title and legend
  uint pad;
};

// placement.integral_costs's own push constants (PlacementParams fills the 128 bytes every device
// takes): saliency, integral costs and the hidden pixels legibility counts.
struct IntegralCostsParams {
  uint width;
  uint height;
  uint layer_count;
  uint label_count;
  float saliency_weight;
  float occlusion_weight;
  float single_saliency_weight;
  float ghost_strength;  // the frame's ghosting (shared/ghost.h): a pixel its lenses let through
  float ghost_radius;    // is not hidden (ghost_placement_opening); the lens radius in pixels
};

// Where a label k's box centre would break a constraint with a placed label j (thesis 4.1.1,
// after Stein & Decoret): its box or connector would touch j's box (`box`) or connector
// (`connector`). Each region is convex, an intersection of half-planes dot(p.xy, c) <= p.z;
// unused planes are zero. Written once per pair when j is placed; read by every tile.
struct PairRegionsGpu {
  vec4 box[4];
  vec4 connector[6];
  uvec4 info;  // x: REGION_* bits
};

// Where the regions of the label at order position s against the one placed before it at order
// position t (t < s) are kept: row s holds its s pairs, so n labels need n (n - 1) / 2 of them.
// (Every pair is written before it is read, by the label loop, once t is final.)
STRATA_INLINE uint placement_pair_slot(uint s, uint t) {
  return s * (s - 1u) / 2u + t;
}
STRATA_INLINE uint placement_pair_count(uint labels) {
  return labels > 1u ? labels * (labels - 1u) / 2u : 1u;
}

// A label as the tidy-up sees it: fixed point, the box's corners and the anchor.
struct TidyLabel {
  ivec2 anchor;
  ivec2 lo;  // box, top-left ...
  ivec2 hi;  // ... and bottom-right corner
  uint flags;
  uint pixel;  // the candidate pixel (placement's convention) of the box
};

// Per label (order position s): its tiles per bucket, and its main pass.
struct PlacementBucketsGpu {
  uint done;    // workgroups of place_label dispatch s finished (the last one sizes the next)
  uint rest;    // tiles of the main pass beyond bucket 0 (moved up behind it in the list)
  uint main;    // tiles of the main pass: bucket 0 and rest
  float bound;  // the main pass's bound on the label's best cost (speculative winners', samples')
  uint counts[PLACEMENT_BUCKETS];
  uint cursors[PLACEMENT_BUCKETS];
  float lowest;  // the smallest of the label's tile bounds (the buckets' reference)
};

// A label's entry of PLACEMENT_BINDING_RANKS: its order position, and the first order position
// of its priority (labels of a priority wait while a higher priority's are undecided).
STRATA_INLINE uint rounds_rank(uint packed) {
  return packed & 0xFFFFu;
}
STRATA_INLINE uint rounds_group_first(uint packed) {
  return packed >> 16u;
}

// Words of a label's conflict row (PLACEMENT_BINDING_ROUND_BITS) for n labels.
STRATA_INLINE uint rounds_row_words(uint n) {
  return (n + 31u) / 32u;
}

// The top-left pixel of a label box of `size` whose candidate pixel is p.
STRATA_INLINE vec2 box_origin(uvec2 p, vec2 size) {
  return vec2(p) - floor(size * 0.5f);
}

// Half the box that the constraints test around label `me`: its size, the margin and its own
// padding.
STRATA_INLINE vec2 constraint_half_size(LabelGpu me, float margin) {
  return me.size * 0.5f + vec2(margin + me.padding);
}

// Is box centre c the label's held position? (The candidates nearest to it: within half a pixel.)
STRATA_INLINE bool holds(LabelGpu me, vec2 c) {
  return all(lessThanEqual(abs(c - me.held), vec2(0.5f)));
}

// A label's placement at candidate pixel (`pixel`, in an image `width` wide) of eq. 3.1 cost
// `cost`: its box centre, and the cost without the hold (what the position itself costs).
STRATA_INLINE PlacementGpu shown_placement(LabelGpu me, uint pixel, float cost, uint width) {
  PlacementGpu p;
  p.position = box_origin(uvec2(pixel % width, pixel / width), me.size) + me.size * 0.5f;
  p.cost = holds(me, p.position) ? cost : cost - me.hold;
  p.shown = PLACEMENT_SHOWN;
  p.opacity = 1.0f;
  p.pad = 0u;
  return p;
}

STRATA_INLINE PlacementGpu hidden_placement(LabelGpu me) {
  PlacementGpu p;
  p.position = me.anchor;
  p.cost = 0.0f;
  p.shown = PLACEMENT_HIDDEN;
  p.opacity = 0.0f;
  p.pad = 0u;
  return p;
}

// The classifying workgroups of a label whose tile list has `beyond` entries past bucket 0.
STRATA_INLINE uint placement_classify_groups(uint beyond, uint per_group) {
  return (beyond + per_group - 1u) / per_group;
}

// List entries per classifying workgroup for `tiles` tiles: 4, or 8 or 16 where that keeps the
// classification within 256 workgroups (fewer resident at once make a label's dispatch longer;
// smaller groups finish sooner; docs/performance.md has the sizes measured).
STRATA_INLINE uint placement_classify_tiles(uint tiles) {
  return tiles <= 1024u ? 4u : tiles <= 2048u ? 8u : 16u;
}

// The workgroups of a place_label dispatch sized to its passes: a main pass of `main_tiles`, the
// next label's speculative pass and classification (its list: `listed` entries, `spec_tiles` of
// them in bucket 0), and the region writer.
STRATA_INLINE uint placement_label_groups(uint main_tiles, uint spec_tiles, uint listed,
                                          uint per_group) {
  return main_tiles + spec_tiles + placement_classify_groups(listed - spec_tiles, per_group) + 1u;
}

// The workgroup counts of an indirect dispatch over `count` tiles (x is limited to 65535).
STRATA_INLINE uvec3 placement_dispatch_size(uint count) {
  return uvec3(min(count, 65535u), (count + 65534u) / 65535u, 1u);
}

// The workgroups (of 64 invocations) of tidy-up step `phase` for n labels: one per label for the
// conflicts and the selection, TIDY_SEARCH_LANES invocations per change for the search (moves and
// hidings, n TIDY_SWAP, and swaps, n (n - 1) / 2) in rows of at most 65535, an invocation per
// label for the others. The host sizes the rounds' indirect dispatches with it, and the tidy-up
// writes it for each round that runs (the rest stay at zero workgroups).
STRATA_INLINE uvec3 tidy_phase_groups(uint phase, uint n) {
  if (phase == TIDY_PHASE_CONFLICTS || phase == TIDY_PHASE_SELECT) return uvec3(n, 1u, 1u);
  uint threads = n;
  if (phase == TIDY_PHASE_SEARCH) threads = (n * TIDY_SWAP + n * (n - 1u) / 2u) * TIDY_SEARCH_LANES;
  return placement_dispatch_size((threads + 63u) / 64u);
}

// How many 32 x 32 tiles cover the viewport across and down.
STRATA_INLINE uvec2 placement_tiles(uint width, uint height) {
  return uvec2((width + PLACEMENT_TILE - 1u) / PLACEMENT_TILE,
               (height + PLACEMENT_TILE - 1u) / PLACEMENT_TILE);
}

// How far above the label's lowest bound bucket b starts: 0, then bucket_width * 4^(b - 1). The
// sort and the main pass's sizing both use this, so they agree to the last bit.
STRATA_INLINE float placement_bucket_edge(uint b, float bucket_width) {
  float edge = b == 0u ? 0.0f : bucket_width;
  for (uint k = 1u; k < b; ++k) edge *= PLACEMENT_BUCKET_GROWTH;
  return edge;
}

// The bucket of a tile whose lower cost bound lies `above` the label's lowest.
STRATA_INLINE uint placement_bucket(float above, float bucket_width) {
  uint b = 0u;
  while (b + 1u < PLACEMENT_BUCKETS && above >= placement_bucket_edge(b + 1u, bucket_width)) ++b;
  return b;
}
STRATA_END

#endif
