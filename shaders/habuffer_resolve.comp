#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require

// The resolve (shared/resolve_walk.h): per pixel, the HA-Buffer's fragments gathered and sorted
// (resolve_scene.glsl, with the scene's bindings), the volumes' boxes added, the walk, the layers
// and the final image. Compiled as itself for any scene and, with VR_RESOLVE_ONE_VOLUME, as
// habuffer_resolve_one_volume.comp (the shader table in CMakeLists.txt): a scene of one volume and
// no meshes, whose walk the compiler then specialises (fewer registers, a faster resolve:
// docs/performance.md). The volumes' records are a uniform block, read as constants.
#ifdef VR_RESOLVE_ONE_VOLUME
#define VR_RESOLVE_MESHES false
#else
#define VR_RESOLVE_MESHES (frame.mesh_count > 0u)
#endif
#include "shared/background.h"
#include "shared/volume_shading.h"
#include "resolve_scene.glsl"

layout(local_size_x = VR_RESOLVE_GROUP, local_size_y = VR_RESOLVE_GROUP) in;
layout(binding = VR_BINDING_COUNTERS, std430) buffer Counters { uint counters[VR_COUNTER_COUNT]; };
layout(binding = VR_BINDING_LAYERS, rgba16f) writeonly uniform image2DArray layers;
layout(binding = VR_BINDING_FINAL, rgba8) writeonly uniform image2D final_image;
layout(binding = VR_BINDING_DEPTH, r32f) writeonly uniform image2D depth_image;

// The pixel's layers go to the images as the walk leaves them; the final image composites them.
ivec2 pixel_coord;
vec4 all_layers = vec4(0.0);
void emit_layer(uint l, vec4 colour) {
  imageStore(layers, ivec3(pixel_coord, l), colour);
  all_layers = over(all_layers, colour);
}

#include "shared/resolve_walk.h"

void main() {
  const uvec2 group = resolve_group(gl_WorkGroupID.xy, gl_NumWorkGroups.xy, frame.group_order);
  const uvec2 px = group * gl_WorkGroupSize.xy + gl_LocalInvocationID.xy;
  const bool inside = px.x < frame.width && px.y < frame.height;
  uint count = 0u, dropped = 0u;
  float depths[VR_MAX_FRAGMENTS];
  uvec2 payloads[VR_MAX_FRAGMENTS];
  if (inside && VR_RESOLVE_MESHES) count = gather_fragments(px, depths, payloads, dropped);
  PixelResult r;
  pixel_coord = ivec2(px);
  if (inside) r = resolve_pixel(vec2(px) + 0.5, count, depths, payloads);
  const uint found = subgroupAdd(count + dropped);
  const uint lost = subgroupAdd(dropped);
  const uint samples = subgroupAdd(inside ? r.samples : 0u);
  const uint shaded = subgroupAdd(inside ? r.shaded : 0u);
  const uint fetches = subgroupAdd(inside ? r.fetches : 0u);
  // With frames in flight the counters read back are a frame or two old: they say which table
  // they were counted in, so a table already grown is not grown again for the same overflow.
  if (px == uvec2(0)) counters[VR_COUNTER_TABLE_SIZE] = frame.table_size;
  if (subgroupElect()) {
    atomicAdd(counters[VR_COUNTER_FRAGMENTS], found);
    if (lost > 0u) atomicAdd(counters[VR_COUNTER_RESOLVE_OVERFLOW], lost);
    atomicAdd(counters[VR_COUNTER_SAMPLES], samples);
    atomicAdd(counters[VR_COUNTER_SHADED], shaded);
    atomicAdd(counters[VR_COUNTER_FETCHES], fetches);
  }
  if (!inside) return;
  imageStore(final_image, ivec2(px), straight_alpha(over_background(all_layers, frame.background)));
  imageStore(depth_image, ivec2(px), vec4(r.depth));
}
