#include "passes/placement_reference.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "passes/summed_area_table.h"
#include "shared/ghost.h"
#include "shared/placement_cost_access.h"
#include "shared/saliency.h"
#include "shared/tidy_search_access.h"

namespace strata {
namespace gpu {
namespace {

// The summed-area tables as the shaders read them (0 left of and above the image).
float table_value(const std::vector<float>& tables, const PlacementParams& params, uint layer,
                  int x, int y) {
  if (x < 0 || y < 0) return 0.0f;
  return tables[size_t(layer) * params.width * params.height + size_t(y) * params.width +
                size_t(x)];
}

// The shared cost code sees these members as the shader sees its buffers.
struct Placer {
  PlacementParams params;
  std::span<const LabelGpu> labels;
  std::span<const uint32_t> order;
  const std::vector<float>& tables;
  std::vector<uint64_t> results;
  std::vector<PairRegionsGpu> regions;  // the label being placed against each placed label

  std::vector<vec2> anchors;     // every shown label's anchor
  std::vector<uvec4> keep_outs;  // PLACEMENT_BINDING_KEEP_OUT
  uvec4 keep_out_at(uint i) const { return keep_outs[i]; }

  // Every label placed so far, every anchor: the GPU's tile culling only skips what cannot matter.
  uint placed_count() const { return params.step; }
  PairRegionsGpu placed_regions(uint k) const { return regions[order[k]]; }
  uint anchor_count() const { return uint(anchors.size()); }
  vec2 anchor_at(uint k) const { return anchors[k]; }
  vec3 placed(uint j) const {
    if (results[j] == PLACEMENT_NONE) return vec3(0.0f);
    const uint pixel = uint(results[j] & 0xFFFFFFFFu);
    const uvec2 p(pixel % params.width, pixel / params.width);
    return vec3(box_origin(p, labels[j].size) + labels[j].size * 0.5f, 1.0f);
  }
  float table_at(uint layer, int x, int y) const {
    return table_value(tables, params, layer, x, y);
  }

#include "shared/placement_cost.h"
};
static_assert(PlacementCostAccess<Placer>);

// The tidy-up's rounds (shared/tidy_search.h) one step at a time: each step over
// every label before the next, as the GPU's barriers separate them.
struct Tidier {
  PlacementParams params;
  std::span<const LabelGpu> labels;
  const std::vector<float>& tables;
  std::vector<uint> ranks;
  std::vector<TidyLabel> states, nexts;
  std::vector<float> frees;
  std::vector<uint64_t> bests;
  std::vector<uint> partners;
  std::vector<ivec4> currents;   // each label's conflicts this round
  std::vector<uvec4> keep_outs;  // PLACEMENT_BINDING_KEEP_OUT
  uvec4 keep_out_at(uint i) const { return keep_outs[i]; }

  float table_at(uint layer, int x, int y) const {
    return table_value(tables, params, layer, x, y);
  }
  uint tidy_count() const { return uint(labels.size()); }
  LabelGpu tidy_input(uint k) const { return labels[k]; }
  TidyLabel tidy_state(uint k) const { return states[k]; }
  float tidy_free(uint k) const { return frees[k]; }
  uint tidy_rank(uint k) const { return ranks[k]; }
  uint64_t tidy_best(uint k) const { return bests[k]; }
  TidyLabel tidy_next(uint k) const { return nexts[k]; }
  uint tidy_partner(uint k) const { return partners[k]; }
  ivec4 tidy_conflicts_now(uint k) const { return currents[k]; }

#include "shared/tidy.h"
#include "shared/tidy_search.h"

  bool movable(uint k) const {
    return (states[k].flags & (TIDY_PLACED | TIDY_MOVABLE)) == (TIDY_PLACED | TIDY_MOVABLE);
  }

  void offer(uint k, float delta, uint change) {
    if (delta < 0.0f) bests[k] = std::min(bests[k], tidy_key(delta, change));
  }

  // One round; false when it applied nothing.
  bool round() {
    const uint n = tidy_count();
    std::vector<bool> conflicted(n);
    currents.resize(n);
    for (uint i = 0; i < n; ++i) {
      currents[i] = tidy_conflicts_of(i, 0, 1);
      conflicted[i] = movable(i) && currents[i] != ivec4(0);
    }
    bests.assign(n, TIDY_NONE);
    for (uint i = 0; i < n; ++i) {
      if (!conflicted[i]) continue;
      for (uint change = 0; change < TIDY_SWAP; ++change) offer(i, tidy_delta(i, change), change);
    }
    for (uint i = 0; i < n; ++i) {
      for (uint j = i + 1; j < n; ++j) {
        if (!movable(i) || !movable(j)) continue;
        const ivec4 c = tidy_conflicts(states[i], states[j]);
        if (c.x + c.y == 0) continue;
        const float delta = tidy_delta(i, TIDY_SWAP + j);
        offer(i, delta, TIDY_SWAP + j);
        offer(j, delta, TIDY_SWAP + i);
      }
    }
    nexts = states;
    for (uint i = 0; i < n; ++i) partners[i] = tidy_owned_partner(i);
    for (uint i = 0; i < n; ++i) {
      if (partners[i] == TIDY_NO_PARTNER) continue;
      nexts[i] = tidy_changed(i, uint(bests[i] & 0xFFFFFFFFu));
      if (partners[i] != i) nexts[partners[i]] = tidy_changed(partners[i], TIDY_SWAP + i);
    }
    std::vector<uint> applied;
    for (uint i = 0; i < n; ++i) {
      if (partners[i] != TIDY_NO_PARTNER && !tidy_blocked(i, 0, 1)) applied.push_back(i);
    }
    for (uint i : applied) {
      for (uint k : {i, partners[i]}) {
        states[k] = nexts[k];
        frees[k] = tidy_free_cost(nexts[k], labels[k]);
      }
    }
    return !applied.empty();
  }
};
static_assert(TidySearchAccess<Tidier>);

}  // namespace
}  // namespace gpu

std::vector<gpu::PlacementGpu> tidy_reference(std::span<const gpu::LabelGpu> labels,
                                              std::span<const uint32_t> order,
                                              std::span<const uint64_t> results,
                                              const std::vector<float>& tables,
                                              const PlacementSettings& settings, graph::Extent size,
                                              uint32_t layer_count) {
  const auto n = uint32_t(labels.size());
  gpu::Tidier tidier{placement_params(settings, size, layer_count, n, 0),
                     labels,
                     tables,
                     std::vector<uint32_t>(n, LABEL_MAX),
                     {},
                     {},
                     {},
                     {},
                     std::vector<uint32_t>(n, TIDY_NO_PARTNER)};
  tidier.keep_outs = keep_out_rectangles(settings);
  for (uint32_t k = 0; k < order.size(); ++k) tidier.ranks[order[k]] = k;
  for (uint32_t i = 0; i < n; ++i) {
    tidier.states.push_back(tidier.tidy_label(labels[i], results[i]));
    tidier.frees.push_back(tidier.tidy_free_cost(tidier.states[i], labels[i]));
  }
  for (uint32_t r = 0; r < tidier.params.tidy_rounds && tidier.round(); ++r) {
  }
  std::vector<gpu::PlacementGpu> placements(n);
  for (uint32_t i = 0; i < n; ++i) placements[i] = tidier.tidy_placement(i, results[i]);
  return placements;
}

namespace {

// Saliency: CIELAB of each pixel, Sobel with clamp-to-edge neighbours.
std::vector<float> saliency_reference(std::span<const uint8_t> final_rgba8, graph::Extent size) {
  const uint32_t w = size.width, h = size.height;
  const size_t pixels = size_t{w} * h;
  std::vector<glm::vec3> lab(pixels);
  for (size_t p = 0; p < pixels; ++p) {
    lab[p] = gpu::rgb_to_lab(
        glm::vec3(final_rgba8[4 * p], final_rgba8[4 * p + 1], final_rgba8[4 * p + 2]) / 255.0f);
  }
  const auto at = [&](int x, int y) {
    return lab[size_t(std::clamp(y, 0, int(h) - 1)) * w + size_t(std::clamp(x, 0, int(w) - 1))];
  };
  std::vector<float> saliency(pixels);
  for (int y = 0; y < int(h); ++y) {
    for (int x = 0; x < int(w); ++x) {
      saliency[size_t(y) * w + size_t(x)] =
          gpu::sobel_saliency(at(x - 1, y - 1), at(x, y - 1), at(x + 1, y - 1), at(x - 1, y),
                              at(x + 1, y), at(x - 1, y + 1), at(x, y + 1), at(x + 1, y + 1));
    }
  }
  return saliency;
}

// Integral costs per layer, then hidden pixels per layer (after them), into out.costs.
void costs_reference(ReferencePlacement& out, std::span<const glm::vec4> layers,
                     uint32_t layer_count, std::span<const gpu::LabelGpu> labels,
                     const PlacementSettings& settings, graph::Extent size) {
  const uint32_t w = size.width;
  const size_t pixels = size_t{w} * size.height;
  out.costs.resize(pixels * layer_count * 2);
  std::vector<float> open_on(layer_count), kept(layer_count);
  for (size_t p = 0; p < pixels; ++p) {
    float all = 0.0f;
    for (uint32_t l = 0; l < layer_count; ++l) all += layers[l * pixels + p].a;
    // (the ghosting lenses of the rear labels: ghost_placement_opening)
    std::fill(open_on.begin(), open_on.end(), 0.0f);
    if (settings.ghost_strength > 0.0f && settings.ghost_radius > 0.0f) {
      const glm::vec2 centre(float(p % w) + 0.5f, float(p / w) + 0.5f);
      for (const gpu::LabelGpu& l : labels) {
        if (l.layer == 0u || l.layer >= layer_count) continue;
        open_on[l.layer] = std::max(open_on[l.layer],
                                    gpu::ghost_placement_opening(l, centre, settings.ghost_radius));
      }
    }
    float behind = 0.0f;
    float behind_alpha = 0.0f;
    for (int k = int(layer_count) - 1; k >= 0; --k) {
      const float a = layers[size_t(k) * pixels + p].a;
      kept[size_t(k)] = a * gpu::ghost_keep(behind, settings.ghost_strength);
      behind_alpha = gpu::ghost_behind_alpha(a, behind_alpha);
      if (k > 0)
        behind = std::max(behind, open_on[size_t(k)] * gpu::ghost_behind_weight(behind_alpha));
    }
    float in_front = 0.0f;
    float composite = 0.0f;  // of the layers in front of layer l, as the lenses leave them
    for (uint32_t l = 0; l < layer_count; ++l) {
      out.costs[(layer_count + l) * pixels + p] = composite >= HIDING_ALPHA ? 1.0f : 0.0f;
      composite += (1.0f - composite) * kept[l];
      in_front += layers[l * pixels + p].a;
      out.costs[l * pixels + p] = gpu::integral_cost(
          in_front, all - in_front, all, out.saliency[p], layer_count, settings.saliency_weight,
          settings.occlusion_weight, settings.single_saliency_weight);
    }
  }
}

// The greedy loop: each label's argmin over every pixel (ties: the lowest pixel index), as
// (cost bits << 32 | pixel); out.constraints gets the constraint bits.
std::vector<uint64_t> greedy_reference(ReferencePlacement& out,
                                       std::span<const gpu::LabelGpu> labels,
                                       std::span<const uint32_t> order,
                                       const PlacementSettings& settings, graph::Extent size,
                                       uint32_t layer_count) {
  const uint32_t w = size.width, h = size.height;
  gpu::Placer placer{placement_params(settings, size, layer_count, uint32_t(labels.size()), 0),
                     labels,
                     order,
                     out.tables,
                     std::vector<uint64_t>(labels.size(), PLACEMENT_NONE),
                     std::vector<gpu::PairRegionsGpu>(labels.size()),
                     {}};
  placer.keep_outs = keep_out_rectangles(settings);
  for (const gpu::LabelGpu& l : labels) {
    if ((l.flags & LABEL_ENABLED) != 0u) placer.anchors.push_back(l.anchor);
  }
  out.constraints.assign(size_t{w} * h, 0u);
  for (uint32_t step = 0; step < order.size(); ++step) {
    placer.params.step = step;
    const uint32_t label = order[step];
    const gpu::LabelGpu& me = labels[label];
    for (uint32_t k = 0; k < step; ++k) {
      const uint32_t j = order[k];
      placer.regions[j] =
          placer.pair_regions(me, labels[j], placer.placed(j), margin_pixels(settings));
    }
    for (uint32_t y = 0; y < h; ++y) {
      for (uint32_t x = 0; x < w; ++x) {
        const glm::uvec2 p(x, y);
        if (!placer.candidate_allowed(me, p)) continue;
        const glm::vec2 origin = gpu::box_origin(p, me.size);
        const glm::vec2 centre = origin + me.size * 0.5f;
        const uint32_t bits =
            placer.constraint_bits(me, centre, 0u, std::numeric_limits<float>::infinity());
        const uint32_t pixel = y * w + x;
        if (settings.write_constraints) out.constraints[pixel] = bits;
        if (settings.hard && bits != 0u) continue;
        const float cost = placer.candidate_cost(me, origin, centre, bits);
        uint32_t cost_bits;
        std::memcpy(&cost_bits, &cost, 4);
        placer.results[label] =
            std::min(placer.results[label], (uint64_t(cost_bits) << 32) | pixel);
      }
    }
  }
  return std::move(placer.results);
}

}  // namespace

namespace gpu {
namespace {

// The rounds (shared/placement_rounds.h) as their definition reads: each round every undecided
// label searches all of its searched tiles again against the labels decided before it (the GPU
// searches again only where a newly decided label constrains a choice).
struct Rounder {
  PlacementParams params;
  std::span<const LabelGpu> labels;
  const std::vector<float>& tables;
  std::vector<PairRegionsGpu> decided;  // the regions of the shown labels decided before the round
  std::vector<vec2> anchors;            // every enabled label's anchor
  std::vector<uvec4> keep_outs;         // PLACEMENT_BINDING_KEEP_OUT
  uvec4 keep_out_at(uint i) const { return keep_outs[i]; }

  uint placed_count() const { return uint(decided.size()); }
  PairRegionsGpu placed_regions(uint k) const { return decided[k]; }
  uint anchor_count() const { return uint(anchors.size()); }
  vec2 anchor_at(uint k) const { return anchors[k]; }
  float table_at(uint layer, int x, int y) const {
    return table_value(tables, params, layer, x, y);
  }

#include "shared/placement_cost.h"
#include "shared/placement_bound.h"
#include "shared/placement_rounds.h"

  // The tiles a label searches (placement_bounds.comp's buckets, rounds_searched_tiles).
  std::vector<uint> searched_tiles(const LabelGpu& me, uint budget) {
    const uvec2 across = placement_tiles(params.width, params.height);
    const uint tiles = across.x * across.y;
    const uint cells = (PLACEMENT_TILE / PLACEMENT_CELL) * (PLACEMENT_TILE / PLACEMENT_CELL);
    std::vector<float> bounds(tiles, std::numeric_limits<float>::infinity());
    float lowest = std::numeric_limits<float>::infinity();
    for (uint t = 0; t < tiles; ++t) {
      for (uint c = 0; c < cells; ++c) bounds[t] = std::min(bounds[t], tile_cell_bound(me, t, c));
      lowest = std::min(lowest, bounds[t]);
    }
    PlacementBucketsGpu b{};
    std::vector<uint> bucket(tiles, PLACEMENT_BUCKETS);
    for (uint t = 0; t < tiles; ++t) {
      if (std::isinf(bounds[t])) continue;
      bucket[t] = params.write_constraints != 0u
                      ? 0u
                      : placement_bucket(bounds[t] - lowest, params.bucket_width);
      ++b.counts[bucket[t]];
    }
    const uint count = rounds_searched_tiles(b, budget);
    uint last = 0, total = 0;
    while (total < count) total += b.counts[last++];
    std::vector<uint> out;
    for (uint t = 0; t < tiles; ++t) {
      if (bucket[t] < last) out.push_back(t);
    }
    return out;
  }

  // The label's cheapest candidate over the tiles against the decided labels, as in the loop.
  uint64_t cheapest(const LabelGpu& me, const std::vector<uint>& tiles) {
    const uint tiles_x = placement_tiles(params.width, params.height).x;
    uint64_t best = PLACEMENT_NONE;
    for (const uint t : tiles) {
      const uvec2 first = uvec2(t % tiles_x, t / tiles_x) * uint(PLACEMENT_TILE);
      for (uint y = first.y; y < first.y + PLACEMENT_TILE && y < params.height; ++y) {
        for (uint x = first.x; x < first.x + PLACEMENT_TILE && x < params.width; ++x) {
          const uvec2 p(x, y);
          if (!candidate_allowed(me, p)) continue;
          const vec2 origin = box_origin(p, me.size);
          const vec2 centre = origin + me.size * 0.5f;
          const uint bits = constraint_bits(me, centre, 0u, std::numeric_limits<float>::infinity());
          if (params.hard != 0u && bits != 0u) continue;
          const float cost = candidate_cost(me, origin, centre, bits);
          uint cost_bits;
          std::memcpy(&cost_bits, &cost, 4);
          best = std::min(best, (uint64_t(cost_bits) << 32) | (y * params.width + x));
        }
      }
    }
    return best;
  }
};
static_assert(PlacementCostAccess<Rounder>);

}  // namespace
}  // namespace gpu

bool rounds_conflict_reference(const gpu::LabelGpu& a, uint64_t ka, const gpu::LabelGpu& b,
                               uint64_t kb, const PlacementSettings& settings, graph::Extent size) {
  const std::vector<float> no_tables;
  gpu::Rounder rounder{placement_params(settings, size, 1, 2, 0), {}, no_tables, {}, {}};
  rounder.keep_outs = keep_out_rectangles(settings);
  return rounder.rounds_conflict(a, ka, b, kb);
}

ReferenceRounds rounds_reference(std::span<const gpu::LabelGpu> labels,
                                 std::span<const uint32_t> order, const std::vector<float>& tables,
                                 const PlacementSettings& settings, graph::Extent size,
                                 uint32_t layer_count, std::span<const uint32_t> group_first) {
  const auto n = uint32_t(labels.size());
  gpu::Rounder rounder{placement_params(settings, size, layer_count, n, 0), labels, tables, {}, {}};
  rounder.keep_outs = keep_out_rectangles(settings);
  for (const gpu::LabelGpu& l : labels) {
    if ((l.flags & LABEL_ENABLED) != 0u) rounder.anchors.push_back(l.anchor);
  }
  const glm::uvec2 across = gpu::placement_tiles(size.width, size.height);
  const uint32_t budget = std::clamp(settings.round_tiles, 1u, across.x * across.y);
  // (more than the tiles searches them all, as does the GPU)
  std::vector<std::vector<uint32_t>> tiles(n), all_tiles(n);
  const std::vector<uint32_t> packed = rounds_ranks(n, order, group_first);
  std::vector<uint32_t> ranks(n, LABEL_MAX), firsts(n, 0);
  for (uint32_t s = 0; s < order.size(); ++s) {
    ranks[order[s]] = gpu::rounds_rank(packed[order[s]]);
    firsts[order[s]] = gpu::rounds_group_first(packed[order[s]]);
    tiles[order[s]] = rounder.searched_tiles(labels[order[s]], budget);
    all_tiles[order[s]] = rounder.searched_tiles(labels[order[s]], ~0u);
  }
  ReferenceRounds out;
  out.results.assign(n, PLACEMENT_NONE);
  out.round_of.assign(n, ROUND_UNDECIDED);
  const uint32_t rounds =
      std::min({settings.rounds, ROUNDS_MAX, std::max(uint32_t(order.size()), 1u)});
  std::vector<uint32_t> open(order.begin(), order.end());
  for (uint32_t r = 0; r < rounds && !open.empty(); ++r) {
    out.undecided.push_back(uint32_t(open.size()));
    for (const uint32_t i : open) {
      rounder.decided.clear();
      for (uint32_t j = 0; j < n; ++j) {
        if (out.round_of[j] == ROUND_UNDECIDED || out.results[j] == PLACEMENT_NONE) continue;
        rounder.decided.push_back(rounder.pair_regions(
            labels[i], labels[j], rounder.key_placed(labels[j], out.results[j]),
            margin_pixels(settings)));
      }
      out.results[i] = rounder.cheapest(labels[i], tiles[i]);
      const float cost = out.results[i] == PLACEMENT_NONE
                             ? std::numeric_limits<float>::infinity()
                             : glm::uintBitsToFloat(uint32_t(out.results[i] >> 32));
      if (settings.wide_search && cost >= rounder.rounds_wide_cost()) {
        out.results[i] = rounder.cheapest(labels[i], all_tiles[i]);
      }
    }
    // The passes of the selection (the last round decides all): which earlier undecided labels
    // each one depends on, then each pass from the one before.
    enum State { open_state, in_state, out_state };
    std::vector<State> state(n, open_state);
    std::vector<std::vector<uint32_t>> depends(n);
    for (const uint32_t i : open) {
      for (const uint32_t j : open) {
        if (ranks[j] >= ranks[i]) continue;
        if (ranks[j] < firsts[i]) state[i] = out_state;
        else if (rounder.rounds_conflict(labels[i], out.results[i], labels[j], out.results[j]))
          depends[i].push_back(j);
      }
    }
    for (uint32_t pass = 0; pass < ROUNDS_SELECT_PASSES && r + 1 < rounds; ++pass) {
      std::vector<State> next = state;
      for (const uint32_t i : open) {
        if (state[i] != open_state) continue;
        bool any_in = false, all_out = true;
        for (const uint32_t j : depends[i]) {
          any_in = any_in || state[j] == in_state;
          all_out = all_out && state[j] == out_state;
        }
        next[i] = any_in ? out_state : all_out ? in_state : open_state;
      }
      state = std::move(next);
    }
    std::vector<uint32_t> waiting;
    for (const uint32_t i : open) {
      if (r + 1 == rounds || state[i] == in_state) out.round_of[i] = r;
      else waiting.push_back(i);
    }
    open = std::move(waiting);
  }
  return out;
}

ReferencePlacement place_reference(std::span<const uint8_t> final_rgba8,
                                   std::span<const glm::vec4> layers, uint32_t layer_count,
                                   std::span<const gpu::LabelGpu> labels,
                                   std::span<const uint32_t> order,
                                   const PlacementSettings& settings, graph::Extent size) {
  const uint32_t w = size.width, h = size.height;
  const size_t pixels = size_t{w} * h;
  ReferencePlacement out;
  out.saliency = saliency_reference(final_rgba8, size);
  costs_reference(out, layers, layer_count, labels, settings, size);
  out.tables.resize(out.costs.size());
  for (uint32_t l = 0; l < 2 * layer_count; ++l) {
    const std::vector<double> table =
        summed_area_table_reference(std::span(out.costs).subspan(l * pixels, pixels), w, h);
    for (size_t p = 0; p < pixels; ++p) out.tables[l * pixels + p] = float(table[p]);
  }
  std::vector<uint64_t> results;
  if (settings.method == PlacementMethod::rounds) {
    ReferenceRounds rounds = rounds_reference(labels, order, out.tables, settings, size, layer_count);
    results = std::move(rounds.results);
    out.round_of = std::move(rounds.round_of);
    out.undecided = std::move(rounds.undecided);
  } else {
    results = greedy_reference(out, labels, order, settings, size, layer_count);
  }
  out.placements = tidy_reference(labels, order, results, out.tables, settings, size, layer_count);
  return out;
}

}  // namespace strata
