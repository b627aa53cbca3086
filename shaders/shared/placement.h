// Label placement on the GPU (thesis 3.2, 4.1): saliency, integral costs, and one fused
// constraints + cost (eq. 3.1) + argmin dispatch per label. Written once for C++ and GLSL.
#ifndef STRATA_SHARED_PLACEMENT_H
#define STRATA_SHARED_PLACEMENT_H

#include "labels.h"

#define PLACEMENT_GROUP 16               // 16 x 16 pixels per workgroup
#define VR_MAX_LAYERS_FOR_PLACEMENT 8    // as VR_MAX_LAYERS
#define SALIENCY_SCALE 100.0f            // |CIELAB gradient| of this size counts as saliency 1

// Constraint bits (one constraint image, thesis 4.1.1).
#define CONSTRAINT_LABEL 1u      // the new box or connector would touch a placed label's shadow
#define CONSTRAINT_CONNECTOR 2u  // ... a placed connector's shadow
#define CONSTRAINT_ANCHOR 4u     // the new box would cover an anchor

// A packed (cost, pixel) pair no candidate reaches: "not placed".
#define PLACEMENT_NONE 0xFFFFFFFFFFFFFFFFul

#define PLACEMENT_BINDING_FINAL 0        // rgba8 label-free final image
#define PLACEMENT_BINDING_SALIENCY 1     // float per pixel
#define PLACEMENT_BINDING_LAYERS 2       // rgba16f array image, premultiplied
#define PLACEMENT_BINDING_COSTS 3        // float per pixel per layer (integral costs, eq. 3.3/3.4)
#define PLACEMENT_BINDING_TABLES 4       // their summed-area tables, same layout
#define PLACEMENT_BINDING_LABELS 5       // LabelGpu[]
#define PLACEMENT_BINDING_ORDER 6        // uint[]: label indices in insertion order
#define PLACEMENT_BINDING_RESULTS 7      // uint64_t[] per label: cost bits << 32 | pixel
#define PLACEMENT_BINDING_CONSTRAINTS 8  // uint per pixel: constraint bits of the last label placed
#define PLACEMENT_BINDING_PLACEMENTS 9   // PlacementGpu[]

STRATA_BEGIN
#ifdef __cplusplus
using namespace glm;
#endif

// Cost weights of eq. 3.1 (defaults: the thesis program's final paper settings).
struct CostWeightsGpu {
  float distance_to_anchor;   // alpha, per pixel
  float connector_direction;  // beta, times |cos| + |sin|
  float label_shadow;         // gamma
  float connector_shadow;     // delta
  float anchor_constraint;    // epsilon
  float integral_costs;       // zeta, times the integral over the label box
  float previous_position;    // eta, per pixel
  float pad;
};

struct PlacementParams {
  CostWeightsGpu weights;
  uint width;
  uint height;
  uint layer_count;
  uint label_count;
  uint step;          // place_label: the position in the insertion order being placed
  uint hard;          // 1: constraint violations are forbidden (the label may end up hidden)
  uint write_constraints;  // 1: store the constraint bits of every pixel (tests, debugging)
  float margin;       // pixels added around label boxes in the constraints
  float saliency_weight;   // eq. 3.3: beta, how much saliency modulates occlusion behind
  float occlusion_weight;  // eq. 3.4 (one layer): alpha
  float single_saliency_weight;  // eq. 3.4: beta
  float pad;
};

#ifdef __cplusplus
inline
#endif
// The top-left pixel of a label box of `size` whose candidate pixel is p.
vec2 box_origin(uvec2 p, vec2 size) { return vec2(p) - floor(size * 0.5f); }
STRATA_END

#endif
