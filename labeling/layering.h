// Depth layering of labels (thesis section 3.3): the anchors' depths are clustered with 1D
// k-means++ in Vulkan's non-linear NDC z, one layer plane per cluster at its median, and each
// label goes to the layer whose plane is at or behind its anchor.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace strata {

// splitmix64 (Steele, Lea and Flood 2014): a tiny PRNG of our own, so that clusterings and
// random insertion orders are the same on every standard library for a given seed.
struct SplitMix64 {
  uint64_t state;

  uint64_t next();
  double next_unit();               // uniform in [0, 1)
  uint64_t next_below(uint64_t n);  // uniform in [0, n), n > 0, without modulo bias
};

// 1D k-means++ (Arthur and Vassilvitskii 2007): the first centre is a uniformly chosen value,
// each next one a value drawn with probability proportional to its squared distance to the
// nearest chosen centre; then Lloyd iterations until no assignment changes (at most 100).
// `values` must be finite. k is clamped to [1, number of distinct values]. Returns each value's
// cluster, numbered front to back (cluster 0 has the smallest centre) and without gaps: a cluster
// that Lloyd's iterations empty is dropped. `centres` receives the increasing centres, one per
// cluster. Empty input gives an empty result and no centres. Deterministic for a given seed.
std::vector<uint32_t> kmeans_plus_plus(std::span<const float> values, uint32_t k, uint64_t seed,
                                       std::vector<float>* centres = nullptr);

// Vulkan's [0, 1] depth of a perspective projection for eye depth d in [near, far], and back;
// 0 < near < far.
float eye_depth_to_ndc_z(float eye_depth, float near_plane, float far_plane);
float ndc_z_to_eye_depth(float ndc_z, float near_plane, float far_plane);

inline constexpr uint32_t max_layer_count = 8;

struct Layering {
  // Eye depths of the planes of clusters 0 .. L-2, increasing: the renderer's slab l is
  // [split l-1, split l).
  std::vector<float> split_depths;
  // Per label: the number of split depths strictly less than its anchor depth, so a label on its
  // layer's plane belongs to that layer and labels behind the last split go to the last layer.
  std::vector<uint32_t> label_layer;
  // L: the layer count asked for, or fewer when there are fewer distinct anchor depths.
  uint32_t layer_count = 1;
  // Eye depths of all L layer planes (the cluster medians), increasing; the first L-1 are the
  // split depths. A label is moved onto its layer's plane (thesis Figure 3.5).
  std::vector<float> plane_depths;
};

// Layers the labels by their anchors' eye depths (thesis 3.3). layer_count is clamped to
// [1, max_layer_count]. Clusters are formed in NDC z, which spends more layers near the camera.
// Each plane is its cluster's median anchor in NDC z (the lower median for an even count, so the
// plane always passes through an anchor and that label's depth terms are exact); its eye depth
// is that anchor's own depth, the exact inverse of the NDC mapping, so a label on a plane is on
// it bit for bit. Anchors that are not usable (NaN, depth <= near or >= far) are left out of
// the clustering and get layer 0; with no usable anchor there is one layer and no split.
Layering layer_labels(std::span<const float> anchor_eye_depths, uint32_t layer_count,
                      float near_plane, float far_plane, uint64_t seed = 1);

// How the layering holds still while the camera moves.
struct LayerHysteresis {
  // A label leaves its layer only once its anchor is past the layer's slab by more than this
  // share of the distance (in NDC z) between the two planes on that side.
  float margin = 1.5f;
};

// The next frame's layering, following `previous` (the same labels, the camera moved): Lloyd's
// iterations start from the previous planes instead of a k-means++ seeding, so small moves keep
// the clusters; and a label keeps its previous layer while its anchor stays within the margin of
// that layer's slab. Falls back to layer_labels when the layer count cannot stay the same.
Layering follow_layering(const Layering& previous, std::span<const float> anchor_eye_depths,
                         uint32_t layer_count, float near_plane, float far_plane,
                         const LayerHysteresis& hysteresis, uint64_t seed = 1);

}  // namespace strata
