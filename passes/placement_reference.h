// The CPU reference of the placement passes (passes/placement.h): the same saliency, integral
// costs, summed-area tables, constraints, cost and argmin, in plain C++ running the shared
// shader code (shaders/shared/saliency.h, placement_cost.h). Small images only: tests.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "passes/placement.h"

namespace strata {

struct ReferencePlacement {
  std::vector<float> saliency;  // per pixel
  std::vector<float> costs;     // per layer, per pixel: eq. 3.3/3.4, then 1 where hidden, else 0
  std::vector<float> tables;    // their summed-area tables
  std::vector<uint32_t> constraints;          // bits of the last label placed, per pixel
  std::vector<gpu::PlacementGpu> placements;  // per label
  // PlacementMethod::rounds: the round that decided each label, and per round the labels
  // undecided before it.
  std::vector<uint32_t> round_of, undecided;
};

// The greedy placement in rounds (shaders/shared/placement_rounds.h) over the placement's
// `tables`: per label its result (cost bits << 32 | pixel) and round, per round the labels
// undecided before it.
struct ReferenceRounds {
  std::vector<uint64_t> results;
  std::vector<uint32_t> round_of, undecided;
};
// Whether labels a and b, at result keys ka and kb, constrain each other (rounds_conflict).
bool rounds_conflict_reference(const gpu::LabelGpu& a, uint64_t ka, const gpu::LabelGpu& b,
                               uint64_t kb, const PlacementSettings& settings, graph::Extent size);

ReferenceRounds rounds_reference(std::span<const gpu::LabelGpu> labels,
                                 std::span<const uint32_t> order, const std::vector<float>& tables,
                                 const PlacementSettings& settings, graph::Extent size,
                                 uint32_t layer_count, std::span<const uint32_t> group_first = {});

// The placement tidy-up pass: the greedy loop's results (cost bits << 32 | pixel per label)
// after the tidy-up (shaders/shared/tidy.h) over the placement's `tables`.
std::vector<gpu::PlacementGpu> tidy_reference(std::span<const gpu::LabelGpu> labels,
                                              std::span<const uint32_t> order,
                                              std::span<const uint64_t> results,
                                              const std::vector<float>& tables,
                                              const PlacementSettings& settings, graph::Extent size,
                                              uint32_t layer_count);

// final_rgba8: the label-free final image; layers: premultiplied RGBA, layer after layer.
ReferencePlacement place_reference(std::span<const uint8_t> final_rgba8,
                                   std::span<const glm::vec4> layers, uint32_t layer_count,
                                   std::span<const gpu::LabelGpu> labels,
                                   std::span<const uint32_t> order,
                                   const PlacementSettings& settings, graph::Extent size);

}  // namespace strata
