#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/debug_view.h"

// One of the frame's internal buffers as an rgba8 image (shared/debug_view.h says what each
// mode shows). Every input is bound whatever the mode, so that changing it needs no new graph.
layout(local_size_x = DEBUG_VIEW_GROUP, local_size_y = DEBUG_VIEW_GROUP) in;
layout(binding = DEBUG_VIEW_BINDING_OUTPUT, rgba8) writeonly uniform image2D output_image;
layout(binding = DEBUG_VIEW_BINDING_SALIENCY, std430) readonly buffer Saliency { float saliency[]; };
layout(binding = DEBUG_VIEW_BINDING_COSTS, std430) readonly buffer Costs { float costs[]; };
layout(binding = DEBUG_VIEW_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = DEBUG_VIEW_BINDING_PLACEMENTS, std430) readonly buffer Placements { PlacementGpu placements[]; };
layout(binding = DEBUG_VIEW_BINDING_ORDER, std430) readonly buffer Order { uint order[]; };
layout(binding = DEBUG_VIEW_BINDING_LAYERS, rgba16f) readonly uniform image2DArray layers;
layout(binding = DEBUG_VIEW_BINDING_FRAME) uniform Frame { FrameGpu frame; };
layout(binding = DEBUG_VIEW_BINDING_KEYS, std430) readonly buffer Keys { uvec2 keys[]; };
layout(push_constant) uniform Push { DebugViewParams view; };

float saliency_at(uint pixel) { return saliency[pixel]; }
float cost_at(uint layer, uint pixel) { return costs[layer * view.width * view.height + pixel]; }
vec4 layer_at(uvec2 p, uint layer) { return imageLoad(layers, ivec3(p, layer)); }
LabelGpu label_at(uint i) { return labels[i]; }
PlacementGpu placement_at(uint i) { return placements[i]; }
uint order_at(uint k) { return order[k]; }
uvec2 key_at(uint slot) { return keys[slot]; }
uint table_size() { return frame.table_size; }

#define DEBUG_VIEW_PIXEL
#include "shared/debug_view.h"

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= view.width || p.y >= view.height) return;
  view_setup();
  imageStore(output_image, ivec2(p), debug_view_pixel(p));
}
