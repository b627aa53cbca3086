// Rendering of transparent meshes and volumes through the HA-Buffer (a hashed A-buffer of mesh
// fragments) and its resolve, which adds each volume's box by a ray-box test, ray-casts every
// volume active between consecutive fragments and writes one image per depth layer. Constants,
// bindings and GPU structs are written once here for C++ and GLSL.
#ifndef STRATA_SHARED_VOLUME_RENDER_H
#define STRATA_SHARED_VOLUME_RENDER_H

#include "common.h"

#define VR_MAX_VOLUMES 8
#define VR_MAX_CUT_PLANES 12  // per volume: a crop box's six and six clipping planes
#define VR_MAX_LAYERS 8
#define VR_MAX_MESH_FRAGMENTS 16  // per pixel in the resolve; more are counted, not drawn
#define VR_MAX_FRAGMENTS (VR_MAX_MESH_FRAGMENTS + 2 * VR_MAX_VOLUMES)  // with the boxes' faces
#define VR_MAX_AGE 255      // probes per insertion before a fragment counts as overflow
#define VR_TF_SIZE 256      // entries per transfer-function row
#define VR_BRICK 8          // voxels per brick edge for empty-space skipping
#define VR_RESOLVE_GROUP 8  // resolve workgroup is 8 x 8 pixels

// Payload kinds (bits 8..9 of payload.y); bit 10: the fragment enters its volume.
#define VR_KIND_MESH 0u
#define VR_KIND_VOLUME_FACE 1u

// Counters written on the GPU, read back a frame later.
#define VR_COUNTER_OVERFLOW 0          // fragments that found no free slot
#define VR_COUNTER_FRAGMENTS 1         // mesh fragments the resolve found in the table
#define VR_COUNTER_RESOLVE_OVERFLOW 2  // mesh fragments beyond VR_MAX_MESH_FRAGMENTS in a pixel
#define VR_COUNTER_SAMPLES 3           // ray positions sampled
#define VR_COUNTER_SHADED 4            // volume samples shaded (alpha > 0)
#define VR_COUNTER_FETCHES 5           // atlas fetches (one per live volume per sample)
#define VR_COUNTER_TABLE_SIZE 6        // the table's slots in the frame these counters count
#define VR_COUNTER_COUNT 7

#define VR_BINDING_FRAME 0
#define VR_BINDING_VOLUMES 1
#define VR_BINDING_KEYS 2
#define VR_BINDING_PAYLOAD 3
#define VR_BINDING_COUNTERS 5
#define VR_BINDING_VERTICES 6
#define VR_BINDING_INDICES 7
#define VR_BINDING_ATLAS 8       // sampler3D: every volume, normalised, with borders
#define VR_ATLAS_BORDER 2        // voxels of replicated edge around each volume in the atlas
#define VR_BINDING_TRANSFER 9    // vec4[VR_TF_SIZE] per volume, straight RGBA, alpha per step
#define VR_BINDING_OCCUPANCY 10  // one uint per brick, all volumes one after the other
#define VR_BINDING_LAYERS 11     // image2DArray rgba16f, premultiplied
#define VR_BINDING_FINAL 12      // image2D rgba8, layers over the background, straight alpha
#define VR_BINDING_DEPTH 13      // image2D r32f, eye depth where alpha first passes depth_alpha

STRATA_BEGIN

struct VolumeGpu {
  mat4 world_to_texture;   // world -> [0,1]^3 (voxel centres at (i + 0.5) / dims)
  mat4 gradient_to_world;  // 3x3 part: a gradient per voxel to world units (transpose of the
                           // world-to-texture map times dims; a normal's direction)
  vec4
      atlas_offset;  // xyz: atlas coordinate of texture coordinate 0; w: transfer row centre (0..1)
  vec4 atlas_scale;  // xyz: atlas units per texture unit; w: reference step in world units
                     // (transfer-function alpha is per this distance: opacity correction)
  vec4 texel;        // xyz: 1 / dims (central differences, texture units); w: unused
  uvec4 bricks;      // xyz: brick grid size; w: first brick's index in the occupancy buffer
  // Cut-aways (Volume::cut) in texture space: a sample at tc is shown where
  // dot(xyz, tc) + w >= 0 for the first cut_count.x planes.
  vec4 cut[VR_MAX_CUT_PLANES];
  uvec4 cut_count;
};

struct FrameGpu {
  mat4 world_to_view;
  mat4 view_to_world;
  mat4 view_to_clip;
  mat4 clip_to_view;
  vec4 splits[2];   // layer boundaries (eye depth): split i is splits[i / 4][i % 4]
  vec4 background;  // the final image's (shared/background.h): RGB with a = 1, or all 0: none
  uint width;
  uint height;
  uint layer_count;
  uint volume_count;
  uint table_size;  // HA-Buffer slots
  uint skip_empty;  // 1: empty-space skipping
  uint mesh_count;  // 0: the table is empty and the resolve does not read it
  uint group_order;  // VR_ORDER_*: which pixels the resolve's workgroups take, in dispatch order
  float near_depth;  // eye depth of the near and far planes
  float far_depth;
  float step;               // sampling distance along rays, world units
  float termination_alpha;  // early ray termination, per layer
  float depth_alpha;        // the depth image records where alpha first reaches this
  float pad2;
  float pad3;
  float pad4;
};

// The order in which the resolve's workgroups (8x8 pixels each) take the image, by the device's
// kind. GPUs: rows from the top (VR_ORDER_ROWS; vertical strips 4, 8 or 16 workgroups wide, for
// the texture caches, were slower: docs/performance.md). CPU devices (VR_ORDER_ROWS_INTERLEAVED): rows in VR_ROW_INTERLEAVE
// interleaved sets (0, 8, 16, ..., then 1, 9, ...), so that every long run of consecutive
// workgroups spans the whole image: lavapipe hands each of its threads one contiguous run of a
// dispatch's workgroups, and with rows in order the thread whose half of the image held more of
// the volume ran on alone. On a GPU that order is slower (docs/performance.md).
#define VR_ORDER_ROWS 0u
#define VR_ORDER_ROWS_INTERLEAVED 1u
#define VR_ROW_INTERLEAVE 8u

// The row for position r of `rows` in VR_ORDER_ROWS_INTERLEAVED.
STRATA_INLINE uint resolve_group_row(uint r, uint rows) {
  uint q = rows / VR_ROW_INTERLEAVE, m = rows % VR_ROW_INTERLEAVE;
  // (sets k < m hold q + 1 rows, the others q)
  uint set, index;
  if (r < m * (q + 1u)) {
    set = r / (q + 1u);
    index = r % (q + 1u);
  } else {
    set = m + (r - m * (q + 1u)) / max(q, 1u);
    index = (r - m * (q + 1u)) % max(q, 1u);
  }
  return index * VR_ROW_INTERLEAVE + set;
}

// The workgroup (column, row) that the one at `id` of the dispatch takes.
STRATA_INLINE uvec2 resolve_group(uvec2 id, uvec2 groups, uint order) {
  return order == VR_ORDER_ROWS_INTERLEAVED ? uvec2(id.x, resolve_group_row(id.y, groups.y)) : id;
}

// A pixel's ray: point(z) = origin + direction * z at eye depth z.
struct Ray {
  vec3 origin;     // the eye, world space
  vec3 direction;  // world displacement per unit of eye depth
};

// The ray through `pixel` (pixel units, centres at +0.5) of frame f.
STRATA_INLINE Ray frame_pixel_ray(FrameGpu f, vec2 pixel) {
  vec2 ndc = pixel / vec2(float(f.width), float(f.height)) * 2.0f - 1.0f;
  vec4 far_point = f.clip_to_view * vec4(ndc, 1.0f, 1.0f);
  vec3 view_direction = vec3(far_point) / far_point.w;
  view_direction = view_direction / -view_direction.z;
  Ray ray;
  ray.origin = vec3(f.view_to_world * vec4(0.0f, 0.0f, 0.0f, 1.0f));
  ray.direction = mat3(f.view_to_world) * view_direction;
  return ray;
}

// Push constants of one mesh's draw in the HA-Buffer build.
struct DrawGpu {
  mat4 model;        // model to world
  vec4 color;        // straight RGBA
  uint first_index;  // first index in the index buffer
  uint object;       // mesh index
  uint pad0;
  uint pad1;
};
STRATA_END

#endif
