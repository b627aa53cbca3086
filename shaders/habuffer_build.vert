#version 460
#extension GL_GOOGLE_include_directive : require
#include "shared/volume_render.h"

// Vertices are pulled from storage buffers: meshes by index, volume boxes from a unit cube.
layout(binding = VR_BINDING_FRAME) uniform Frame { FrameGpu frame; };
layout(binding = VR_BINDING_VERTICES, std430) readonly buffer Vertices { vec4 vertices[]; };  // position, normal
layout(binding = VR_BINDING_INDICES, std430) readonly buffer Indices { uint indices[]; };
layout(push_constant) uniform Push { DrawGpu draw; };

layout(location = 0) out vec3 view_position;
layout(location = 1) out vec3 view_normal;
layout(location = 2) flat out vec3 face_normal_view;  // volume boxes: the face's outward normal

// The 12 triangles of the unit cube, outward normal per face.
const vec3 kCorners[8] = vec3[](vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0), vec3(1, 1, 0),
                                vec3(0, 0, 1), vec3(1, 0, 1), vec3(0, 1, 1), vec3(1, 1, 1));
const uint kCube[36] = uint[](0, 2, 1, 1, 2, 3,   4, 5, 6, 5, 7, 6,   0, 1, 4, 1, 5, 4,
                              2, 6, 3, 3, 6, 7,   0, 4, 2, 2, 4, 6,   1, 3, 5, 3, 7, 5);
const vec3 kFaceNormals[6] = vec3[](vec3(0, 0, -1), vec3(0, 0, 1), vec3(0, -1, 0),
                                    vec3(0, 1, 0), vec3(-1, 0, 0), vec3(1, 0, 0));

void main() {
  vec3 position, normal;
  if (draw.kind == VR_KIND_MESH) {
    const uint index = indices[draw.first_index + gl_VertexIndex];
    position = vertices[2 * index].xyz;
    normal = vertices[2 * index + 1].xyz;
  } else {
    position = kCorners[kCube[gl_VertexIndex]];
    normal = kFaceNormals[gl_VertexIndex / 6];
  }
  const mat4 model_view = frame.world_to_view * draw.model;
  const vec4 view = model_view * vec4(position, 1.0);
  view_position = view.xyz;
  const mat3 normal_matrix = transpose(inverse(mat3(model_view)));
  view_normal = normal_matrix * normal;
  face_normal_view = view_normal;
  gl_Position = frame.view_to_clip * view;
}
