#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/label_drawing.h"
#include "shared/volume_render.h"  // VR_MAX_LAYERS

// One invocation per pixel, for every depth layer: each layer's labels drawn over its content in
// place.
layout(local_size_x = LABEL_DRAW_GROUP, local_size_y = LABEL_DRAW_GROUP) in;
layout(binding = LABEL_DRAW_BINDING_LAYERS, rgba16f) uniform image2DArray layers;
layout(binding = LABEL_DRAW_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = LABEL_DRAW_BINDING_PLACEMENTS, std430) readonly buffer Placements {
  PlacementGpu placements[];
};
layout(binding = LABEL_DRAW_BINDING_GLYPHS, std430) readonly buffer Glyphs { GlyphGpu glyphs[]; };
layout(binding = LABEL_DRAW_BINDING_COVERS, std430) readonly buffer Covers {
  AnchorCoverGpu covers[];
};
layout(binding = LABEL_DRAW_BINDING_ATLAS) uniform sampler2D atlas;
layout(binding = LABEL_DRAW_BINDING_IMAGES) uniform sampler2D images;
layout(push_constant) uniform Push { LabelDrawParams params; };

// Never past the end of either buffer, whatever the host says.
uint label_count() {
  return min(params.label_count, uint(min(labels.length(), placements.length())));
}
LabelGpu label_at(uint i) { return labels[i]; }
PlacementGpu placement_at(uint i) { return placements[i]; }
GlyphGpu glyph_at(uint i) { return glyphs[i]; }
float atlas_coverage(vec2 uv) { return textureLod(atlas, uv, 0.0).r; }
vec4 image_texel(vec2 uv) { return textureLod(images, uv, 0.0); }
bool layer_frames() { return params.layer_frames != 0u; }
bool connector_halos() { return params.connector_halos != 0u; }
float anchor_hidden_at(uint i) { return i < uint(covers.length()) ? covers[i].hidden : 0.0; }

#include "shared/label_draw_pixel.h"

// The labels that can touch this workgroup's tile, per layer (bit i of a row: label i), so that
// each pixel visits only those, still in label order. A workgroup takes its tile in every layer:
// the labels are culled once, and the layers without any are not read.
shared uint tile_labels[VR_MAX_LAYERS][LABEL_MAX / 32u];

void main() {
  const uint lane = gl_LocalInvocationIndex;
  const uint lanes = LABEL_DRAW_GROUP * LABEL_DRAW_GROUP;
  const uint layer_count = min(params.layer_count, uint(VR_MAX_LAYERS));
  const uint count = min(label_count(), LABEL_MAX);
  const uint words = (count + 31u) / 32u;  // (the bit sets' words in use: only those are cleared)
  for (uint w = lane; w < layer_count * words; w += lanes) tile_labels[w / words][w % words] = 0u;
  barrier();
  const vec2 tile_lo = vec2(gl_WorkGroupID.xy * LABEL_DRAW_GROUP) + 0.5f;
  const vec2 tile_hi = tile_lo + float(LABEL_DRAW_GROUP - 1u);
  for (uint i = lane; i < count; i += lanes) {
    const LabelGpu label = labels[i];
    if ((label.flags & LABEL_ENABLED) == 0u || label.layer >= layer_count) continue;
    const PlacementGpu placement = placements[i];
    if (placement.shown != PLACEMENT_SHOWN) continue;
    const vec2 centre = (label.flags & LABEL_INTERNAL) != 0u ? label.anchor : placement.position;
    if (!label_far_from_tile(tile_lo, tile_hi, label.anchor, centre, label.size)) {
      atomicOr(tile_labels[label.layer][i / 32u], 1u << (i % 32u));
    }
  }
  barrier();

  const uvec2 id = gl_GlobalInvocationID.xy;
  if (id.x >= params.width || id.y >= params.height) return;
  const vec2 p = vec2(id) + 0.5;
  for (uint layer = 0u; layer < layer_count; ++layer) {
    uint any_label = 0u;
    for (uint w = 0u; w < words; ++w) any_label |= tile_labels[layer][w];
    if (any_label == 0u) continue;  // (most tiles of a layer hold no label: left unread)
    // (the layer is read only where a label comes near the pixel)
    const ivec3 texel = ivec3(id, layer);
    bool loaded = false;
    vec4 content = vec4(0.0), drawn = vec4(0.0);
    for (uint w = 0u; w < words; ++w) {
      uint bits = tile_labels[layer][w];
      while (bits != 0u) {
        const uint i = w * 32u + uint(findLSB(bits));
        bits &= bits - 1u;
        if (!loaded) {
          const LabelGpu label = labels[i];
          const bool internal = (label.flags & LABEL_INTERNAL) != 0u;
          const vec2 centre = internal ? label.anchor : placements[i].position;
          if (label_far_from(p, label.anchor, centre, label.size)) continue;
          content = imageLoad(layers, texel);
          drawn = content;
          loaded = true;
        }
        drawn = draw_label_at(i, p, layer, drawn);
      }
    }
    if (loaded && drawn != content) imageStore(layers, texel, drawn);
  }
}
