#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/pick.h"
#include "shared/volume_shading.h"
#include "resolve_scene.glsl"

// Picking (shared/pick.h): each asked pixel's ray walked as the picture is drawn, one invocation
// a pixel, from the first layer that can reach depth_alpha to the depth.
layout(local_size_x = PICK_GROUP) in;
layout(binding = PICK_BINDING_PIXELS, std430) readonly buffer Pixels { vec2 pixels[]; };
layout(binding = PICK_BINDING_POINTS, std430) writeonly buffer Points { vec4 points[]; };
layout(binding = PICK_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = PICK_BINDING_PLACEMENTS, std430) readonly buffer Placements {
  PlacementGpu placements[];
};
layout(binding = PICK_BINDING_DEPTH, r32f) readonly uniform image2D depth_image;
layout(binding = PICK_BINDING_LAYERS, rgba16f) readonly uniform image2DArray layers;
layout(push_constant) uniform Push { PickParams params; };

// The walk's hooks: it keeps layer_keeps[l] of layer l (its colours are not needed).
float layer_alpha[VR_MAX_LAYERS];
float layer_keeps[VR_MAX_LAYERS];
void emit_layer(uint l, vec4 colour) {}
float layer_keep(uint l) { return layer_keeps[l]; }
PickStart start;  // (pick_start: the layers in front cannot reach depth_alpha)
uint walk_start_layer() { return start.layer; }
float walk_start_clear() { return start.clear; }
bool walk_stops_at_depth() { return true; }
#define VR_RESOLVE_LAYER_KEEP
#include "shared/resolve_walk.h"

// The largest opening of the labels' lenses on each layer at p (labels.ghost's, without the boxes':
// under a box the box is what is drawn); false where none opens.
bool open_layers(vec2 p, uint layer_count, out GhostOpenings open) {
  open = ghost_no_openings();
  if (params.ghost.strength <= 0.0f) return false;
  const uint count = min(min(params.ghost.label_count, LABEL_MAX),
                         uint(min(labels.length(), placements.length())));
  bool any = false;
  for (uint i = 0u; i < count; ++i) {
    const LabelGpu label = labels[i];
    if (label.layer >= layer_count) continue;
    const vec2 opening = vec2(ghost_opening(label, placements[i], p, params.ghost).x, 0.0f);
    open = ghost_with(open, label.layer, opening);
    any = any || opening.x > 0.0f;
  }
  return any;
}

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= min(params.count, uint(min(pixels.length(), points.length())))) return;
  const ivec2 t = pick_texel(pixels[i], params.ghost.width, params.ghost.height);
  const ivec2 cast_pixel = pick_cast_pixel(frame, t, params.ghost.width, params.ghost.height);
  const uint layer_count = min(frame.layer_count, uint(VR_MAX_LAYERS));
  GhostOpenings open;
  if (!open_layers(vec2(t) + 0.5f, layer_count, open)) {
    points[i] = pick_point(frame, cast_pixel, imageLoad(depth_image, t).r);
    return;
  }
  for (uint l = 0u; l < VR_MAX_LAYERS; ++l) {
    layer_alpha[l] = l < layer_count ? imageLoad(layers, ivec3(t, l)).a : 0.0f;
  }
  const GhostKeeps keeps = ghost_keeps(open, layer_alpha, layer_count, params.ghost.strength);
  for (uint l = 0u; l < VR_MAX_LAYERS; ++l) layer_keeps[l] = keeps.layer[l];
  start = pick_start(keeps, layer_alpha, layer_count, frame.depth_alpha);
  if (start.layer >= layer_count) {
    points[i] = vec4(0.0f);
    return;
  }
  uint count = 0u, dropped = 0u;
  float depths[VR_MAX_FRAGMENTS];
  uvec2 payloads[VR_MAX_FRAGMENTS];
  if (frame.mesh_count > 0u) {
    count = gather_fragments(uvec2(cast_pixel), depths, payloads, dropped);
  }
  const PixelResult r = resolve_pixel(vec2(cast_pixel) + 0.5f, count, depths, payloads);
  points[i] = pick_point(frame, cast_pixel, r.depth);
}
