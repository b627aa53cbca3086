// Label placement on the GPU (thesis 3.2, 4.1), all of it inside one frame's command buffer:
// saliency of the label-free final image, integral costs per layer (eq. 3.3/3.4) and their
// summed-area tables, lower cost bounds per label and 32x32 tile (tiles sorted into buckets by
// them), then per label in insertion order one fused constraints + cost (eq. 3.1) + argmin
// dispatch that finishes the label (its main pass) while it evaluates the next label's likeliest
// tiles speculatively, each reading the positions the earlier labels wrote on the GPU. The
// placements are copied to the host after the frame; nothing waits for them inside it.
#pragma once

#include <functional>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "engine/gpu/resources.h"
#include "engine/gpu/shader_library.h"
#include "engine/graph/graph_runner.h"
#include "engine/graph/readback.h"
#include "engine/scene/scene.h"
#include "passes/summed_area_table.h"
#include "shared/placement.h"

namespace strata {

// How the greedy placement decides its labels: one after the other in insertion order (the
// thesis's loop), or in parallel rounds (shared/placement_rounds.h: several times faster on a
// GPU, but crowded pictures show fewer labels; docs/performance.md).
enum class PlacementMethod {
  sequential,
  rounds,
};

struct PlacementSettings {
  CostWeights weights;  // eq. 3.1 (scene settings; defaults: the thesis's final paper)
  PlacementMethod method = PlacementMethod::sequential;
  // The rounds: how many at most (the last decides every label still undecided, conflicts and
  // all, for the tidy-up to settle), and how many of its 32x32 tiles of candidates a label
  // searches at most: the buckets of its tile list, cheapest bound first, while they fit (bucket
  // 0 always). With `wide_search`, a label that finds no position there it wants
  // (rounds_wide_cost) searches all of its tiles, as the sequential loop does: crowded scenes
  // show more labels, but those labels all make for the same free places, and the rounds
  // multiply (docs/performance.md).
  uint32_t rounds = ROUNDS_DEFAULT;
  uint32_t round_tiles = 64;
  bool wide_search = false;
  // Around label boxes in the constraints, in ems: label text sizes, which keep two labels apart
  // legibly at any image size (6 px at the default 14 px font).
  float margin_em = 6.0f / 14.0f;
  float text_pixels = 14.0f;  // an em: the label text's size (LabelledRenderer sets it per frame)
  // How far from the image's edges a box stays, in ems. A still uses the whole image; in motion
  // LabelledRenderer keeps the margin here too, so that a label whose anchor moves outward has
  // room to slide before the edge would cut it.
  float edge_em = 0.0f;
  // Rectangles of the image no box may touch, x0, y0, x1, y1 in pixels (the viewer's panel, a
  // picture's title and legend); empty ones (x0 >= x1 or y0 >= y1) count for nothing, and at most
  // PLACEMENT_KEEP_OUT_MAX others. Labels whose boxes fit nowhere else are hidden.
  std::vector<glm::uvec4> keep_out;
  bool hard = false;                    // forbid constraint violations (labels may end up hidden)
  float saliency_weight = 0.5f;         // eq. 3.3: how much saliency modulates the occlusion behind
  float occlusion_weight = 0.5f;        // eq. 3.4 (one layer)
  float single_saliency_weight = 0.5f;  // eq. 3.4 (one layer)
  // The ghosting the frame draws (shared/ghost.h): strength 0 to 1, lens radius in pixels. Boxes
  // in the lenses of the rear labels count as legible where the opened layers let them through.
  float ghost_strength = 0.0f;
  float ghost_radius = 0.0f;
  // Keep each label's constraint image (tests, debugging; the sequential loop only).
  bool write_constraints = false;
  // Cost above a label's lowest tile bound that its speculative pass covers (speed only:
  // the positions do not depend on it).
  float bucket_width = 0.0625f;
  // Rounds of the tidy-up after the greedy placement at most (shaders/shared/
  // tidy.h: swaps, moves and hiding that lower the finished layout's cost with crossings
  // and overlaps counted); 0: none. Hard mode has none: its layouts have no conflicts.
  uint32_t tidy_rounds = 64;
};

// Per label of `label_count`: its position in `order` | the first position of its priority
// (`group_first`, per position; empty: 0) << 16; all bits for a label not in the order.
std::vector<uint32_t> rounds_ranks(uint32_t label_count, std::span<const uint32_t> order,
                                   std::span<const uint32_t> group_first = {});

// The settings' keep-out rectangles that are not empty, as the placement's buffer holds them;
// more than PLACEMENT_KEEP_OUT_MAX is an Error.
std::vector<glm::uvec4> keep_out_rectangles(const PlacementSettings& s);

// The margin in pixels.
inline float margin_pixels(const PlacementSettings& s) {
  return s.margin_em * s.text_pixels;
}

gpu::PlacementParams placement_params(const PlacementSettings& s, graph::Extent viewport,
                                      uint32_t layer_count, uint32_t label_count, uint32_t step);
gpu::IntegralCostsParams integral_costs_params(const PlacementSettings& s, graph::Extent viewport,
                                               uint32_t layer_count, uint32_t label_count);

// How the placement's dispatches are sized. The label loop's and the tidy-up rounds' sizes are only
// known on the GPU: an indirect dispatch reads them there; a direct one has enough workgroups for
// any sizes (with at most PlacementLayout::direct_groups for the passes' tiles, each taking several
// past that), those past the sizes leaving at once. On a GPU direct is faster (a chain of dependent
// dispatches costs less per step direct than indirect, and idle workgroups little:
// docs/performance.md); on lavapipe, where every workgroup runs on the CPU, idle ones cost more
// than the whole placement.
enum class LabelDispatch {
  automatic,  // direct, except on CPU devices
  direct,
  indirect,
};

// How the placement is laid out on the device (speed and tests only: the positions do not depend
// on it).
struct PlacementLayout {
  LabelDispatch dispatch = LabelDispatch::automatic;
  // A direct dispatch's workgroups for the passes' tiles (at most), and the invocations of a
  // label's last workgroup that take its tile list (0: all; fewer make more chunks).
  uint32_t direct_groups = PLACEMENT_DIRECT_GROUPS;
  uint32_t finish_lanes = 0;
  // List entries per classifying workgroup: 4, 8 or 16 (0: placement_classify_tiles()).
  uint32_t classify_tiles = 0;
  // Direct tidy-up rounds: each block of kTidyBlockRounds past the first is skipped by
  // conditional rendering where the device has it and the round before the block applied
  // nothing (then no later round can).
  bool skip_idle_blocks = true;
  // The label loop as a graph pass per step instead of one pass (benchmark baselines that return
  // to the host between labels: GraphRunner::run_passes).
  bool pass_per_label = false;
};

// Tidy-up rounds per conditional block (PlacementLayout::skip_idle_blocks).
inline constexpr uint32_t kTidyBlockRounds = 8;

// More labels than a tidy-up workgroup keeps in shared memory: the tidy-up shaders that read the
// states from the buffer.
inline bool tidy_states_in_buffer(uint32_t label_count) {
  return label_count > TIDY_SHARED_MAX;
}

// The dispatch plan, decided once from the device, the layout and the label count.
struct PlacementPlan {
  bool indirect = false;          // LabelDispatch, resolved for the device
  bool skip_idle_blocks = false;  // conditional blocks of tidy-up rounds (direct only)
  bool large = false;             // tidy_states_in_buffer
  static PlacementPlan choose(const Context& ctx, uint32_t label_count,
                              const PlacementLayout& layout);
};

class Placement {
 public:
  // Adds passes that adjust the uploaded labels (LabelGpu[]) before they are placed.
  using AdjustLabels = std::function<void(graph::Graph&, graph::ResourceId labels)>;
  struct Inputs {
    graph::ResourceId final_image;  // the label-free final image (rgba8)
    graph::ResourceId layers;       // the depth layers (rgba16f array), premultiplied
    uint32_t layer_count = 1;
    // What the labels take from last frame (LabelForces::add_previous: previous positions for
    // eq. 3.1's eta term, held positions with their hold, hard-mode padding); none: the anchors
    // set_frame() gave, nothing held.
    AdjustLabels adjust_labels;
  };
  struct Outputs {
    graph::ResourceId labels, placements, saliency, costs, tables, constraints, results;
    graph::ResourceId buckets;  // PlacementBucketsGpu per order position (benchmark statistics)
    // uint per tidy-up round r: 1 for round 0, then the changes round r - 1 applied (round r runs
    // only when that is not 0; benchmark statistics)
    graph::ResourceId tidy_rounds;
    // The rounds (PlacementMethod::rounds): uint per round r, the labels undecided before it;
    // uint per label, the round that decided it.
    graph::ResourceId round_counts, round_of;
    graph::ResourceId order;  // uint[]: the frame's insertion order (label indices)
    // The passes that place the labels one by one, [label_loop, label_loop_end): one, or with
    // PlacementLayout::pass_per_label pass label_loop + s records step s (place_label dispatch s:
    // the main pass of order position s - 1 and the speculative one of s); and the rounds' pass.
    // A frame records the ones its PlacementSettings::method names; the others record nothing.
    graph::PassId label_loop, label_loop_end, rounds;
  };

  // `label_count` sizes the per-label buffers; a frame may enable fewer labels.
  Placement(Context& ctx, uint32_t label_count, PlacementLayout layout = {});
  // The same with its compute pipelines made beforehand by create_pipelines: they take a while on
  // drivers that compile at creation (lavapipe), so a caller may create them meanwhile.
  Placement(Context& ctx, uint32_t label_count, PlacementLayout layout,
            std::vector<ComputePipeline> pipelines);
  static std::vector<ComputePipeline> create_pipelines(Context& ctx, uint32_t label_count);
  // Pipelines for a placement of `label_count` labels: this one's, moved out (it is left without
  // them), where the count needs the same ones, else new (the scene's labels changed).
  std::vector<ComputePipeline> take_pipelines(uint32_t label_count);
  const PlacementPlan& plan() const { return plan_; }

  // Adds the placement's passes: upload (then in.adjust_labels), costs, bounds, the label loop,
  // the tidy-up and the readback.
  Outputs add_to(graph::Graph& graph, const Inputs& in);

  // This frame's labels (label_count of them; disabled ones are skipped) and insertion order
  // (indices of the enabled labels). Read when the frame is recorded. Labels from `active` on
  // are all disabled (spare label slots): the placement's work leaves them out. `group_first`:
  // per order position, the first position of its priority (the rounds decide none of a
  // priority's labels while a label of a higher one is undecided); empty: one priority.
  void set_frame(std::vector<gpu::LabelGpu> labels, std::vector<uint32_t> order,
                 const PlacementSettings& settings, std::optional<uint32_t> active = {},
                 std::span<const uint32_t> group_first = {});

  // Labels in this frame's insertion order.
  uint32_t order_count() const { return uint32_t(order_.size()); }

  // The placements of the last completed frame (of the readback's current slot).
  std::span<const gpu::PlacementGpu> results() const;
  graph::Readback& readback() { return readback_; }

  // The placement's compute pipelines (shader name and what the driver reports of each).
  std::vector<PipelineReport> pipeline_statistics() const;

 private:
  struct Buffers {
    graph::ResourceId labels, order, results, placements, saliency, costs, tables, constraints;
    graph::ResourceId bounds, tiles, buckets, lower, args, speculative, samples, regions, tidy,
        tidy_rounds, tidy_args;
    graph::ResourceId ranks, round_of, round_list, round_args, round_counts, round_bits, round_done,
        round_wide;
    graph::ResourceId keep_out;
    graph::ResourceId readback;
  };
  Buffers add_buffers(graph::Graph& graph);
  void add_upload(graph::Graph& graph, const Buffers& b);
  void add_costs(graph::Graph& graph, const Buffers& b, const Inputs& in);
  void add_bounds(graph::Graph& graph, const Buffers& b);
  // The loop's first pass; its last is the graph's last.
  graph::PassId add_label_loop(graph::Graph& graph, const Buffers& b);
  graph::PassId add_rounds(graph::Graph& graph, const Buffers& b);
  // Rounds recorded for this frame, and the workgroups a round's search has per label
  // (ROUNDS_GROUPS, at most the tiles).
  uint32_t round_count() const;
  uint32_t round_groups(graph::Extent viewport) const;
  void add_tidy(graph::Graph& graph, const Buffers& b);
  void record_tidy_rounds(graph::PassContext& pc, gpu::PlacementParams p, const Buffers& b) const;
  // The one place that tells direct and indirect dispatches apart: the use a pass declares for
  // sizes it reads from `args` (none when direct), and a dispatch, sized by `args` at `offset` on
  // the GPU or by `groups`.
  void declare_sizes(std::vector<graph::ResourceUse>& uses, graph::ResourceId args) const;
  void dispatch(graph::PassContext& pc, const ComputePipeline& pipeline,
                const gpu::PlacementParams& p, graph::ResourceId args, VkDeviceSize offset,
                glm::uvec3 groups) const;
  glm::uvec3 direct_groups(graph::Extent viewport) const;
  // List entries per classifying workgroup at this viewport (the layout's, or by tile count).
  uint32_t classify_tiles(graph::Extent viewport) const;
  gpu::PlacementParams params(graph::Extent viewport, uint32_t step) const;

  Context& ctx_;
  uint32_t label_count_;
  uint32_t active_ = 0;
  uint32_t frame_count() const { return active_; }
  PlacementLayout layout_;
  PlacementPlan plan_;
  uint32_t layer_count_ = 1;
  std::vector<gpu::LabelGpu> labels_;
  std::vector<uint32_t> order_;
  // per label: its position in order_ | the first position of its priority << 16; all bits for
  // none (rounds_rank, rounds_group_first)
  std::vector<uint32_t> ranks_;
  PlacementSettings settings_;
  ComputePipeline integral_costs_, bounds_, place_, tidy_, search_;
  std::optional<ComputePipeline> rounds_;  // made when a frame first places in rounds
  SummedAreaTable tables_;
  graph::Readback readback_;
};

}  // namespace strata
