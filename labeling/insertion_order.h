// Label insertion orders for the greedy placement (thesis 3.2.3): the order labels are placed in
// within a layer. Each returns a permutation of the label indices, first placed first.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace strata {

// The default mode: the labels in the scene's order, 0 .. count-1.
std::vector<uint32_t> scene_order(uint32_t count);

// Distance from each pixel centre to the nearest background pixel centre (occupancy < 0.5;
// row-major, width × height), by Jump Flooding (Rong and Tan 2006). This is the CPU reference,
// plain loops. JFA is approximate: a pixel can keep a seed that is not its nearest when the
// nearest one's flood was cut off by closer seeds. Such pixels are rare and the error small (on
// random sparse background: 0.04 % of pixels, at most 2 pixels too far). Background pixels are 0;
// without any background every pixel is +infinity.
std::vector<float> jump_flooding_distance_transform(std::span<const float> occupancy,
                                                    uint32_t width, uint32_t height);

// Stein and Décoret's order (2008): innermost labels first.
//  1. the distance transform of the background (above);
//  2. each anchor's weight w_k is the distance at its pixel (0 on background or outside the
//     image; 0 for every anchor when the image has no background, which makes the order the
//     scene order and the diagram the plain Voronoi diagram);
//  3. the Apollonius (additively weighted Voronoi) diagram of the anchors, by Jump Flooding:
//     pixel p belongs to the anchor k minimising |p - a_k| - w_k; written to `diagram`
//     (row-major anchor index, -1 where no anchor reaches), and only computed when asked for;
//  4. the order: weight descending, ties by anchor index ascending.
// How the diagram relates to the order: in Stein and Décoret's reading, the cells that do not
// reach the background are those of the innermost, most surrounded anchors, the hardest to place;
// a heavy weight (far from the background) makes a cell grow over its lighter neighbours'. In this
// implementation the weight ordering alone determines the order (no cell is inspected, no
// adjacency walked); the diagram is returned for inspection and tests. Anchors are in pixels,
// x right, y down, pixel centres at +0.5; an anchor outside the image owns no cell.
std::vector<uint32_t> apollonius_order(std::span<const glm::vec2> anchors_px,
                                       std::span<const float> occupancy, uint32_t width,
                                       uint32_t height, std::vector<int32_t>* diagram = nullptr);

// A Fisher-Yates shuffle of 0 .. count-1, the same for a given seed everywhere (SplitMix64). The
// optimise-on-idle mode tries random orders and keeps one when its total energy is lower.
std::vector<uint32_t> random_order(uint32_t count, uint64_t seed);

}  // namespace strata
