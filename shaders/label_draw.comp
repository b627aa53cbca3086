#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/label_drawing.h"

// One invocation per pixel of one depth layer: the layer's labels drawn over its content in place.
layout(local_size_x = LABEL_DRAW_GROUP, local_size_y = LABEL_DRAW_GROUP) in;
layout(binding = LABEL_DRAW_BINDING_LAYERS, rgba16f) uniform image2DArray layers;
layout(binding = LABEL_DRAW_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = LABEL_DRAW_BINDING_PLACEMENTS, std430) readonly buffer Placements {
  PlacementGpu placements[];
};
layout(binding = LABEL_DRAW_BINDING_GLYPHS, std430) readonly buffer Glyphs { GlyphGpu glyphs[]; };
layout(binding = LABEL_DRAW_BINDING_ATLAS) uniform sampler2D atlas;
layout(push_constant) uniform Push { LabelDrawParams params; };

// Never past the end of either buffer, whatever the host says.
uint label_count() {
  return min(params.label_count, uint(min(labels.length(), placements.length())));
}
LabelGpu label_at(uint i) { return labels[i]; }
PlacementGpu placement_at(uint i) { return placements[i]; }
GlyphGpu glyph_at(uint i) { return glyphs[i]; }
float atlas_coverage(vec2 uv) { return textureLod(atlas, uv, 0.0).r; }

#include "shared/label_draw_pixel.h"

void main() {
  const uvec3 id = gl_GlobalInvocationID;
  if (id.x >= params.width || id.y >= params.height || id.z >= params.layer_count) return;
  const ivec3 texel = ivec3(id);
  const vec4 content = imageLoad(layers, texel);
  const vec4 drawn = draw_labels_at(vec2(id.xy) + 0.5, id.z, content);
  if (drawn != content) imageStore(layers, texel, drawn);
}
