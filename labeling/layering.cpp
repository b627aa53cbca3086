#include "labeling/layering.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace strata {

uint64_t SplitMix64::next() {
  uint64_t z = (state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

double SplitMix64::next_unit() {
  // The top 53 bits fill a double's mantissa exactly.
  return static_cast<double>(next() >> 11) * 0x1.0p-53;
}

uint64_t SplitMix64::next_below(uint64_t n) {
  // Reject the lowest 2^64 mod n outputs so that every residue is equally likely.
  const uint64_t threshold = (0 - n) % n;
  for (;;) {
    const uint64_t x = next();
    if (x >= threshold) return x % n;
  }
}

namespace {

constexpr uint32_t unassigned = std::numeric_limits<uint32_t>::max();
constexpr int max_lloyd_iterations = 100;

uint32_t count_distinct(std::span<const float> values) {
  std::vector<float> sorted(values.begin(), values.end());
  std::sort(sorted.begin(), sorted.end());
  return static_cast<uint32_t>(std::unique(sorted.begin(), sorted.end()) - sorted.begin());
}

// Index of a value drawn with probability weight[i] / total. Values with weight 0 (already a
// centre) are never drawn; the fallback covers rounding in the running sum.
size_t draw_weighted(const std::vector<double>& weight, double total, SplitMix64& rng) {
  const double target = rng.next_unit() * total;
  double running = 0.0;
  size_t last_positive = 0;
  for (size_t i = 0; i < weight.size(); ++i) {
    if (weight[i] <= 0.0) continue;
    running += weight[i];
    last_positive = i;
    if (running > target) return i;
  }
  return last_positive;
}

// k-means++ seeding. k <= distinct values, so until k centres are chosen some value is away from
// every centre and the total weight is positive.
std::vector<double> seed_centres(std::span<const float> values, uint32_t k, SplitMix64& rng) {
  std::vector<double> centres{values[rng.next_below(values.size())]};
  std::vector<double> squared_distance(values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    const double d = values[i] - centres[0];
    squared_distance[i] = d * d;
  }
  while (centres.size() < k) {
    double total = 0.0;
    for (const double d2 : squared_distance) total += d2;
    const double centre = values[draw_weighted(squared_distance, total, rng)];
    centres.push_back(centre);
    for (size_t i = 0; i < values.size(); ++i) {
      const double d = values[i] - centre;
      squared_distance[i] = std::min(squared_distance[i], d * d);
    }
  }
  return centres;
}

// Nearest centre; ties go to the lower index, so equal centres never share a value.
uint32_t nearest_centre(double value, const std::vector<double>& centres) {
  uint32_t best = 0;
  for (uint32_t c = 1; c < centres.size(); ++c) {
    if (std::abs(value - centres[c]) < std::abs(value - centres[best])) best = c;
  }
  return best;
}

bool assign(std::span<const float> values, const std::vector<double>& centres,
            std::vector<uint32_t>& cluster) {
  bool changed = false;
  for (size_t i = 0; i < values.size(); ++i) {
    const uint32_t c = nearest_centre(values[i], centres);
    changed |= c != cluster[i];
    cluster[i] = c;
  }
  return changed;
}

// Centres move to their members' mean; an empty cluster keeps its centre.
void update_centres(std::span<const float> values, const std::vector<uint32_t>& cluster,
                    std::vector<double>& centres) {
  std::vector<double> sum(centres.size(), 0.0);
  std::vector<size_t> count(centres.size(), 0);
  for (size_t i = 0; i < values.size(); ++i) {
    sum[cluster[i]] += values[i];
    ++count[cluster[i]];
  }
  for (size_t c = 0; c < centres.size(); ++c) {
    if (count[c] > 0) centres[c] = sum[c] / static_cast<double>(count[c]);
  }
}

// Renumbers the clusters by increasing centre and drops the empty ones unless `keep_empty`.
std::vector<float> renumber_front_to_back(const std::vector<double>& centres,
                                          std::vector<uint32_t>& cluster, bool keep_empty) {
  std::vector<bool> used(centres.size(), keep_empty);
  for (const uint32_t c : cluster) used[c] = true;
  std::vector<uint32_t> order;
  for (uint32_t c = 0; c < centres.size(); ++c) {
    if (used[c]) order.push_back(c);
  }
  std::sort(order.begin(), order.end(),
            [&](uint32_t a, uint32_t b) { return centres[a] < centres[b]; });
  std::vector<uint32_t> new_index(centres.size(), unassigned);
  std::vector<float> sorted_centres;
  for (const uint32_t c : order) {
    new_index[c] = static_cast<uint32_t>(sorted_centres.size());
    sorted_centres.push_back(static_cast<float>(centres[c]));
  }
  for (uint32_t& c : cluster) c = new_index[c];
  return sorted_centres;
}

// Lloyd's iterations from `centre`; returns each value's cluster, numbered front to back.
std::vector<uint32_t> lloyd(std::span<const float> values, std::vector<double> centre,
                            std::vector<float>* centres, bool keep_empty = false) {
  std::vector<uint32_t> cluster(values.size(), unassigned);
  for (int iteration = 0; iteration < max_lloyd_iterations; ++iteration) {
    if (!assign(values, centre, cluster)) break;
    update_centres(values, cluster, centre);
  }
  std::vector<float> sorted_centres = renumber_front_to_back(centre, cluster, keep_empty);
  if (centres) *centres = std::move(sorted_centres);
  return cluster;
}

}  // namespace

std::vector<uint32_t> kmeans_plus_plus(std::span<const float> values, uint32_t k, uint64_t seed,
                                       std::vector<float>* centres) {
  if (centres) centres->clear();
  if (values.empty()) return {};
  k = std::clamp(k, 1u, count_distinct(values));
  SplitMix64 rng{seed};
  return lloyd(values, seed_centres(values, k, rng), centres);
}

float eye_depth_to_ndc_z(float eye_depth, float near_plane, float far_plane) {
  const double d = eye_depth, n = near_plane, f = far_plane;
  return static_cast<float>(f * (d - n) / (d * (f - n)));
}

float ndc_z_to_eye_depth(float ndc_z, float near_plane, float far_plane) {
  const double z = ndc_z, n = near_plane, f = far_plane;
  return static_cast<float>(f * n / (f - z * (f - n)));
}

namespace {

bool usable_depth(float depth, float near_plane, float far_plane) {
  return !std::isnan(depth) && depth > near_plane && depth < far_plane;
}

struct Member {
  float ndc_z;
  float eye_depth;
  auto operator<=>(const Member&) const = default;
};

// Each cluster's lower-median member in NDC z, as the member's own eye depth; an empty cluster's
// centre (NDC z) as an eye depth.
std::vector<float> cluster_medians(const std::vector<Member>& members,
                                   const std::vector<uint32_t>& cluster,
                                   const std::vector<float>& centres, float near_plane,
                                   float far_plane) {
  std::vector<std::vector<Member>> by_cluster(centres.size());
  for (size_t i = 0; i < members.size(); ++i) by_cluster[cluster[i]].push_back(members[i]);
  std::vector<float> planes;
  for (size_t c = 0; c < centres.size(); ++c) {
    std::vector<Member>& group = by_cluster[c];
    if (group.empty()) {
      planes.push_back(ndc_z_to_eye_depth(centres[c], near_plane, far_plane));
      continue;
    }
    const auto median = group.begin() + static_cast<std::ptrdiff_t>((group.size() - 1) / 2);
    std::nth_element(group.begin(), median, group.end());
    planes.push_back(median->eye_depth);
  }
  return planes;
}

}  // namespace

namespace {

std::vector<Member> usable_members(std::span<const float> depths, float near_plane,
                                   float far_plane) {
  std::vector<Member> members;
  for (const float depth : depths) {
    if (usable_depth(depth, near_plane, far_plane)) {
      members.push_back({eye_depth_to_ndc_z(depth, near_plane, far_plane), depth});
    }
  }
  return members;
}

// The layering of clusters `cluster` (numbered front to back, with increasing `centres`): planes
// at the medians (an empty cluster's at its centre), and each label on the layer whose plane is at
// or behind its anchor.
Layering layering_of(const std::vector<Member>& members, const std::vector<uint32_t>& cluster,
                     const std::vector<float>& centres, std::span<const float> anchor_eye_depths,
                     float near_plane, float far_plane) {
  Layering layering;
  layering.plane_depths = cluster_medians(members, cluster, centres, near_plane, far_plane);
  layering.layer_count = std::max<uint32_t>(1, static_cast<uint32_t>(centres.size()));
  if (!layering.plane_depths.empty()) {
    layering.split_depths.assign(layering.plane_depths.begin(), layering.plane_depths.end() - 1);
  }
  const std::vector<float>& splits = layering.split_depths;
  layering.label_layer.reserve(anchor_eye_depths.size());
  for (const float depth : anchor_eye_depths) {
    const bool usable = usable_depth(depth, near_plane, far_plane);
    const auto first_not_less = std::lower_bound(splits.begin(), splits.end(), depth);
    layering.label_layer.push_back(usable ? static_cast<uint32_t>(first_not_less - splits.begin())
                                          : 0u);
  }
  return layering;
}

std::vector<float> ndc_z_of(std::span<const Member> members) {
  std::vector<float> z;
  for (const Member& m : members) z.push_back(m.ndc_z);
  return z;
}

}  // namespace

Layering layer_labels(std::span<const float> anchor_eye_depths, uint32_t layer_count,
                      float near_plane, float far_plane, uint64_t seed) {
  const std::vector<Member> members = usable_members(anchor_eye_depths, near_plane, far_plane);
  std::vector<float> centres;
  const std::vector<uint32_t> cluster = kmeans_plus_plus(
      ndc_z_of(members), std::clamp(layer_count, 1u, max_layer_count), seed, &centres);
  return layering_of(members, cluster, centres, anchor_eye_depths, near_plane, far_plane);
}

Layering follow_layering(const Layering& previous, std::span<const float> anchor_eye_depths,
                         uint32_t layer_count, float near_plane, float far_plane,
                         const LayerHysteresis& hysteresis, uint64_t seed) {
  const std::vector<Member> members = usable_members(anchor_eye_depths, near_plane, far_plane);
  const std::vector<float> z = ndc_z_of(members);
  const uint32_t k = std::clamp(layer_count, 1u, max_layer_count);
  if (members.empty() || previous.plane_depths.size() != std::min(k, count_distinct(z)) ||
      previous.label_layer.size() != anchor_eye_depths.size()) {
    return layer_labels(anchor_eye_depths, layer_count, near_plane, far_plane, seed);
  }
  // Warm start: the previous planes, where the camera now puts their eye depths.
  std::vector<double> start;
  for (const float plane : previous.plane_depths) {
    start.push_back(eye_depth_to_ndc_z(plane, near_plane, far_plane));
  }
  std::vector<float> centres;
  // A cluster the iterations empty keeps its place (at its centre): dropping it, and seeding
  // again next frame, would move many labels at once.
  const std::vector<uint32_t> cluster = lloyd(z, start, &centres, true);
  Layering layering =
      layering_of(members, cluster, centres, anchor_eye_depths, near_plane, far_plane);
  const std::vector<float>& planes = layering.plane_depths;
  if (std::adjacent_find(planes.begin(), planes.end(), std::greater_equal<float>()) !=
      planes.end()) {
    return layer_labels(anchor_eye_depths, layer_count, near_plane, far_plane, seed);
  }

  // A label stays on its previous layer while its anchor is within the margin of that slab.
  std::vector<float> plane_z;
  for (const float plane : layering.plane_depths) {
    plane_z.push_back(eye_depth_to_ndc_z(plane, near_plane, far_plane));
  }
  const auto last = static_cast<uint32_t>(plane_z.size() - 1);
  for (size_t i = 0; i < anchor_eye_depths.size(); ++i) {
    const float depth = anchor_eye_depths[i];
    const uint32_t was = previous.label_layer[i];
    if (!usable_depth(depth, near_plane, far_plane) || was == layering.label_layer[i]) continue;
    const float d = eye_depth_to_ndc_z(depth, near_plane, far_plane);
    // The slab of layer l is (plane l-1, plane l]; the last one has no back side.
    const bool front_ok =
        was == 0 || d > plane_z[was - 1] - hysteresis.margin * (plane_z[was] - plane_z[was - 1]);
    const bool back_ok =
        was >= last || d <= plane_z[was] + hysteresis.margin * (plane_z[was + 1] - plane_z[was]);
    if (front_ok && back_ok) layering.label_layer[i] = was;
  }
  return layering;
}

}  // namespace strata
