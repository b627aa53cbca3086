// What placement_free_cost.h (and through it placement_cost.h and tidy.h) reads from its
// includer, stated once: as a concept the CPU references' structs are checked against in C++,
// and as declarations in GLSL, so that a shader without one of the functions fails to link with
// its name ("No function definition (body) found: table_at(").
#ifndef STRATA_SHARED_PLACEMENT_FREE_COST_ACCESS_H
#define STRATA_SHARED_PLACEMENT_FREE_COST_ACCESS_H

#include "placement.h"

#ifdef __cplusplus
#include <concepts>

STRATA_BEGIN
template <typename T>
concept PlacementFreeCostAccess = requires(const T& t, uint layer, int x, int y) {
  // the viewport, the weights and the rules (GLSL: a push-constant member; not declared here)
  { t.params } -> std::same_as<const PlacementParams&>;
  // summed-area table of the layer's integral costs (layer < layer_count) or hidden pixels
  // (layer_count + layer); 0 left of and above the image
  { t.table_at(layer, x, y) } -> std::same_as<float>;
  // keep-out rectangle i < params.keep_out_count (PLACEMENT_BINDING_KEEP_OUT)
  { t.keep_out_at(layer) } -> std::same_as<uvec4>;
};
STRATA_END
#else
float table_at(uint layer, int x, int y);
uvec4 keep_out_at(uint i);
#endif

#endif
