#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/volume_render.h"

// Mesh vertices are pulled from storage buffers by index (volume boxes are not drawn: the
// resolve intersects them with each pixel's ray).
layout(binding = VR_BINDING_FRAME) uniform Frame { FrameGpu frame; };
layout(binding = VR_BINDING_VERTICES, std430) readonly buffer Vertices { vec4 vertices[]; };  // position, normal
layout(binding = VR_BINDING_INDICES, std430) readonly buffer Indices { uint indices[]; };
layout(push_constant) uniform Push { DrawGpu draw; };

layout(location = 0) out vec3 view_position;
layout(location = 1) out vec3 view_normal;

void main() {
  const uint index = indices[draw.first_index + gl_VertexIndex];
  const mat4 model_view = frame.world_to_view * draw.model;
  const vec4 view = model_view * vec4(vertices[2 * index].xyz, 1.0);
  view_position = view.xyz;
  view_normal = transpose(inverse(mat3(model_view))) * vertices[2 * index + 1].xyz;
  gl_Position = frame.view_to_clip * view;
}
