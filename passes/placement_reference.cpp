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

  std::vector<vec2> anchors;  // every shown label's anchor

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
  std::vector<ivec4> currents;  // each label's conflicts this round

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
  const std::vector<uint64_t> results =
      greedy_reference(out, labels, order, settings, size, layer_count);
  out.placements = tidy_reference(labels, order, results, out.tables, settings, size, layer_count);
  return out;
}

}  // namespace strata
