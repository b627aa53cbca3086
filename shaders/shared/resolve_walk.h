// The resolve of one pixel, written once for the GPU (habuffer_resolve.comp) and the CPU
// reference (passes/volume_render_reference.cpp). What the includer provides (the frame, the
// volumes' samples, transfer tables, bricks and cut-aways, and emit_layer, which takes the pixel's
// layers) is resolve_walk_access.h; resolve_pixel's arguments are the pixel's mesh fragments,
// sorted front to back: their eye depths and payloads. The volumes' boxes are added here, by a
// ray-box test.
//
// With VR_RESOLVE_LAYER_KEEP defined the includer also provides each layer's keep (ghosting),
// the layer the walk starts at and whether it stops at the depth (resolve_walk_access.h), and
// the depth follows the drawn picture instead of the walk's own sum: with A_l(z) layer l's
// alpha up to z, the picture's alpha at z in layer l is 1 - T * (1 - keep_l * A_l(z)), T the
// product of (1 - keep_j * A_j) over the layers j in front (their whole alphas). While every
// layer so far is kept whole that is the walk's own sum, so the depth is exactly the resolve's.
//
// The ray is parametrised by eye depth z: point(z) = origin + direction * z. Samples lie on one
// grid for the whole ray (near + (k + 0.5) * dz), so segments between fragments join seamlessly.

#ifndef __cplusplus
#include "resolve_walk_access.h"  // (C++: the reference's struct is checked against it)
#endif

// The frame's volume count; a constant where the includer resolves one volume only
// (VR_RESOLVE_ONE_VOLUME), so that the compiler drops the general paths.
#ifdef VR_RESOLVE_ONE_VOLUME
#define VR_RESOLVE_VOLUMES 1u
#else
#define VR_RESOLVE_VOLUMES frame.volume_count
#endif

struct PixelResult {
  float depth;                 // eye depth where the total alpha first reaches depth_alpha, or 0
  uint samples;                // ray positions sampled
  uint shaded;                 // volume samples shaded
  uint fetches;                // atlas fetches
};

uint shaded_samples = 0u;
uint atlas_fetches = 0u;

#ifdef VR_RESOLVE_LAYER_KEEP
float drawn_front_clear = 1.0f;  // T: what the drawn layers the ray has left let through
bool drawn_front_whole = true;   // every layer the ray has left is drawn as walked

// The drawn picture's alpha in layer l, whose own alpha so far is layer_alpha (total: the walk's
// sum of every layer).
float drawn_alpha(float total, float layer_alpha, uint l) {
  float keep = layer_keep(l);
  if (drawn_front_whole && keep >= 1.0f) return total;
  return 1.0f - drawn_front_clear * (1.0f - keep * layer_alpha);
}
#endif

// The ray leaves layer `from` (its colour `acc`) for layer `to`: those in between stay empty.
void close_layers(uint from, uint to, vec4 acc) {
  emit_layer(from, acc);
#ifdef VR_RESOLVE_LAYER_KEEP
  float keep = layer_keep(from);
  drawn_front_clear *= 1.0f - keep * acc.a;
  drawn_front_whole = drawn_front_whole && (keep >= 1.0f || acc.a <= 0.0f);
#endif
  for (uint l = from + 1u; l < to; ++l) emit_layer(l, vec4(0.0f));
}

uint layer_of(float z) {
  uint layer = 0u;
  for (uint i = 0u; i + 1u < frame.layer_count; ++i) {
    if (z >= split_depth(frame.splits, i)) layer = i + 1u;
  }
  return layer;
}

// Straight RGBA of volume v's transfer function at normalised intensity t: linear between the
// table's entries (centred at (i + 0.5) / VR_TF_SIZE), clamped at both ends.
vec4 transfer(uint v, float t) {
  float x = t * float(VR_TF_SIZE) - 0.5f;
  float base = floor(x);
  int i = int(base);
  return mix(table_entry(v, clamp(i, 0, VR_TF_SIZE - 1)),
             table_entry(v, clamp(i + 1, 0, VR_TF_SIZE - 1)), x - base);
}

bool inside_unit_box(vec3 tc) {
  return tc.x >= 0.0f && tc.y >= 0.0f && tc.z >= 0.0f && tc.x <= 1.0f && tc.y <= 1.0f &&
         tc.z <= 1.0f;
}

// Volume v's shaded sample at texture coordinate tc (premultiplied; zero outside its box or where
// its transfer function is transparent). The table's alpha is already corrected for the step:
// the per-sample power this would take otherwise cost the resolve a fifth of its time.
vec4 sample_volume(uint v, VolumeGpu vol, vec3 tc, vec3 to_eye) {
  if (!inside_unit_box(tc) || volume_cut(v, tc)) return vec4(0.0f);
  vec4 s = volume_sample(v, tc);
  atlas_fetches += 1u;
  vec4 c = transfer(v, s.w);
  if (c.a <= 0.0f) return vec4(0.0f);
  vec3 normal = mat3(vol.gradient_to_world) * vec3(s);
  float alpha = c.a;
  shaded_samples += 1u;
  // One reciprocal square root for both the zero test and the normalisation.
  float length2 = dot(normal, normal);
  vec4 shaded = length2 > 1e-12f ? shade_unit_normal(vec4(vec3(c), 1.0f),
                                                     normal * inversesqrt(length2), to_eye)
                                 : vec4(vec3(c), 1.0f);
  return vec4(vec3(shaded) * alpha, alpha);
}

// The sum of every live (entered, not yet left) volume's sample at p (premultiplied).
vec4 sample_volumes(uint live, vec3 p, vec3 to_eye) {
  vec4 sum = vec4(0.0f);
  for (uint v = 0u; v < VR_RESOLVE_VOLUMES; ++v) {
    if ((live & (1u << v)) == 0u) continue;
    VolumeGpu vol = volume_info(v);
    sum += sample_volume(v, vol, vec3(vol.world_to_texture * vec4(p, 1.0f)), to_eye);
  }
  if (sum.a > 1.0f) sum /= sum.a;
  return sum;
}

// Volume v's part of brick_state: the ray at texture coordinate tc, moving d texture units per
// unit of eye depth, at eye depth z. Whether tc's brick is empty (y = 1, or 0; 2 outside the
// box: no brick) and the eye depth where the ray leaves it (x).
vec2 brick_exit(uint v, VolumeGpu vol, vec3 tc, vec3 d, float z) {
  if (!inside_unit_box(tc)) return vec2(3.4e38f, 2.0f);
  bool empty = brick_empty(v, tc);
  // Bricks are VR_BRICK voxels wide: brick coordinates = voxel coordinates / VR_BRICK.
  vec3 per_unit = 1.0f / (vec3(vol.texel) * float(VR_BRICK));
  vec3 cell = floor(tc * per_unit);
  float t = 3.4e38f;
  if (abs(d.x) > 1e-12f)
    t = min(t, ((cell.x + (d.x > 0.0f ? 1.0f : 0.0f)) / per_unit.x - tc.x) / d.x);
  if (abs(d.y) > 1e-12f)
    t = min(t, ((cell.y + (d.y > 0.0f ? 1.0f : 0.0f)) / per_unit.y - tc.y) / d.y);
  if (abs(d.z) > 1e-12f)
    t = min(t, ((cell.z + (d.z > 0.0f ? 1.0f : 0.0f)) / per_unit.z - tc.z) / d.z);
  return vec2(z + max(t, 0.0f), empty ? 1.0f : 0.0f);
}

// Where the ray leaves the current brick of every live volume (x, eye depth) and whether all of
// those bricks are empty (y = 1): the next sample that could be visible lies beyond x.
vec2 brick_state(uint live, vec3 origin, vec3 direction, float z, float dz) {
  float exit_z = 3.4e38f;
  bool empty = true;
  for (uint v = 0u; v < VR_RESOLVE_VOLUMES; ++v) {
    if ((live & (1u << v)) == 0u) continue;
    VolumeGpu vol = volume_info(v);
    vec3 tc = vec3(vol.world_to_texture * vec4(origin + direction * z, 1.0f));
    vec2 brick = brick_exit(v, vol, tc, mat3(vol.world_to_texture) * direction, z);
    if (brick.y > 1.5f) continue;
    empty = empty && brick.y > 0.5f;
    exit_z = min(exit_z, brick.x);
  }
  if (exit_z > 3.0e38f) exit_z = z + dz;  // no live volume here: nothing to see at z
  return vec2(exit_z, empty ? 1.0f : 0.0f);
}

Ray pixel_ray(vec2 pixel) { return frame_pixel_ray(frame, pixel); }

float grid_depth(float k, float dz) {
  return frame.near_depth + (k + 0.5f) * dz;
}
// Where the ray enters and leaves volume v's box (eye depths; enter > leave: it misses). The
// slab test in texture space, where the box is [0,1]^3.
vec2 box_interval(uint v, vec3 origin, vec3 direction) {
  mat4 w2t = volume_info(v).world_to_texture;
  vec3 o = vec3(w2t * vec4(origin, 1.0f));
  vec3 d = mat3(w2t) * direction;
  float enter = -3.4e38f, leave = 3.4e38f;
  for (int axis = 0; axis < 3; ++axis) {
    if (abs(d[axis]) < 1e-20f) {
      if (o[axis] < 0.0f || o[axis] > 1.0f) enter = 3.4e38f;
      continue;
    }
    float t0 = (0.0f - o[axis]) / d[axis], t1 = (1.0f - o[axis]) / d[axis];
    enter = max(enter, min(t0, t1));
    leave = min(leave, max(t0, t1));
  }
  return vec2(enter, leave);
}

float grid_index_at_or_after(float z, float dz) {
  return max(ceil((z - frame.near_depth) / dz - 0.5f), 0.0f);
}

// The walk along one ray, shared by its steps below: the ray (with one volume, the common case,
// that volume's data stay in registers and the ray is stepped in its texture space), the layer it
// is in, that layer's colour so far (acc) and the eye depth where the next layer starts, the alpha
// of every layer summed, what it found so far, the live (entered, not yet left) volumes and how
// far their bricks are known to be occupied. Depth only grows along the ray, so layers are visited
// in order: the current layer's colour is emitted when the ray moves on (no array of layers: a
// dynamically indexed one would live in slow local memory on GPUs).
struct RayWalk {
  vec3 origin;
  vec3 direction;
  vec3 to_eye;
  float dz;
  float start_z;  // (samples and mesh fragments in front of the start layer are not walked)
  bool stops;
  VolumeGpu first;
  vec3 first_origin;
  vec3 first_direction;
  uint layer;
  float next_split;
  vec4 acc;
  float total;
  float depth;
  uint samples;
  uint live;
  float checked_until;  // samples before this depth lie in bricks known to be occupied
};
RayWalk walk;

// The walk's start at the pixel, before the volumes' boxes are known.
void walk_start(vec2 pixel) {
  shaded_samples = 0u;
  atlas_fetches = 0u;
#ifdef VR_RESOLVE_LAYER_KEEP
  const uint start_layer = walk_start_layer();
  drawn_front_clear = start_layer > 0u ? walk_start_clear() : 1.0f;
  drawn_front_whole = start_layer == 0u;
  walk.stops = walk_stops_at_depth();
#else
  const uint start_layer = 0u;
  walk.stops = false;
#endif
  walk.start_z = start_layer > 0u ? split_depth(frame.splits, start_layer - 1u) : frame.near_depth;
  Ray ray = pixel_ray(pixel);
  walk.origin = ray.origin;
  walk.direction = ray.direction;
  walk.to_eye = -normalize(walk.direction);
  walk.dz = frame.step / length(walk.direction);
  walk.first = volume_info(0u);
  walk.first_origin = vec3(walk.first.world_to_texture * vec4(walk.origin, 1.0f));
  walk.first_direction = mat3(walk.first.world_to_texture) * walk.direction;
  walk.layer = start_layer;
  walk.next_split =
      start_layer + 1u < frame.layer_count ? split_depth(frame.splits, start_layer) : 3.4e38f;
  walk.acc = vec4(0.0f);
  walk.total = 0.0f;
  walk.depth = 0.0f;
  walk.samples = 0u;
  walk.live = 0u;
  walk.checked_until = -1.0f;
}

// The ray reaches eye depth z: the layers it leaves are emitted, and z's layer is the walk's.
void walk_to_layer_of(float z) {
  uint l = z >= walk.next_split ? layer_of(z) : walk.layer;
  if (l == walk.layer) return;
  walk.next_split = l + 1u < frame.layer_count ? split_depth(frame.splits, l) : 3.4e38f;
  close_layers(walk.layer, l, walk.acc);
  walk.layer = l;
  walk.acc = vec4(0.0f);
}

// Colour c (premultiplied) at eye depth z joins the walk's layer; true where the depth is found.
bool walk_add(vec4 c, float z) {
  walk.acc = over(walk.acc, c);
#ifdef VR_RESOLVE_LAYER_KEEP
  walk.total = walk.total + (1.0f - walk.total) * c.a;
  // (the first z: the drawn alpha may step back by a rounding where a layer stops being whole)
  const bool found =
      walk.depth <= 0.0f && drawn_alpha(walk.total, walk.acc.a, walk.layer) >= frame.depth_alpha;
#else
  float before = walk.total;
  walk.total = walk.total + (1.0f - walk.total) * c.a;
  const bool found = before < frame.depth_alpha && walk.total >= frame.depth_alpha;
#endif
  if (found) walk.depth = z;
  return found;
}

// Where the ray leaves the bricks of the live volumes at eye depth z and whether all of them are
// empty (brick_state).
vec2 walk_bricks(float z) {
  // (one volume: in its texture space, as its samples)
  vec2 bricks = VR_RESOLVE_VOLUMES == 1u
                    ? brick_exit(0u, walk.first, walk.first_origin + walk.first_direction * z,
                                 walk.first_direction, z)
                    : brick_state(walk.live, walk.origin, walk.direction, z, walk.dz);
  if (bricks.y > 1.5f) bricks = vec2(z + walk.dz, 1.0f);  // (outside the box: as brick_state)
  return bricks;
}

// The walk's samples on the grid from eye depth `from` up to `to`, between two fragments.
void walk_samples(float from, float to) {
  float k = grid_index_at_or_after(from, walk.dz);
  while (walk.live != 0u && grid_depth(k, walk.dz) < to) {
    float zs = grid_depth(k, walk.dz);
    walk_to_layer_of(zs);
    if (walk.acc.a >= frame.termination_alpha) {  // this slab is opaque: go to the next one
      if (walk.layer + 1u >= frame.layer_count) break;
      k = max(grid_index_at_or_after(split_depth(frame.splits, walk.layer), walk.dz), k + 1.0f);
      continue;
    }
    // Occupancy is looked up once per brick, not per sample.
    if (frame.skip_empty != 0u && zs >= walk.checked_until) {
      vec2 bricks = walk_bricks(zs);
      if (bricks.y > 0.5f) {
        k = max(grid_index_at_or_after(bricks.x, walk.dz), k + 1.0f);
        continue;
      }
      walk.checked_until = bricks.x;
    }
    vec4 c = VR_RESOLVE_VOLUMES == 1u
                 ? sample_volume(0u, walk.first, walk.first_origin + walk.first_direction * zs,
                                 walk.to_eye)
                 : sample_volumes(walk.live, walk.origin + walk.direction * zs, walk.to_eye);
    walk.samples += 1u;
    if (walk_add(c, zs) && walk.stops) break;
    k += 1.0f;
  }
}

PixelResult resolve_pixel(vec2 pixel, uint count, float depths[VR_MAX_FRAGMENTS],
                          uvec2 payloads[VR_MAX_FRAGMENTS]) {
  walk_start(pixel);
  // Each box's faces between the near and far planes join the mesh fragments, in depth order
  // (after fragments at the same depth); a box the near plane cuts is live from the start.
  for (uint v = 0u; v < VR_RESOLVE_VOLUMES; ++v) {
    vec3 tc = vec3(volume_info(v).world_to_texture *
                   vec4(walk.origin + walk.direction * frame.near_depth, 1.0f));
    if (inside_unit_box(tc)) walk.live |= 1u << v;
    vec2 box = box_interval(v, walk.origin, walk.direction);
    if (box.x > box.y) continue;
    for (uint face = 0u; face < 2u; ++face) {
      float d = face == 0u ? box.x : box.y;
      if (d < frame.near_depth || d > frame.far_depth) continue;
      uint j = count++;
      for (; j > 0u && depths[j - 1u] > d; --j) {
        depths[j] = depths[j - 1u];
        payloads[j] = payloads[j - 1u];
      }
      depths[j] = d;
      payloads[j] = uvec2(0u, v | (VR_KIND_VOLUME_FACE << 8u) | ((1u - face) << 10u));
    }
  }

  // The segments between fragments are sampled; a mesh fragment joins its layer, a box face
  // makes its volume live or not.
  float z = frame.near_depth;
  for (uint i = 0u; i <= count; ++i) {
    if (walk.stops && walk.depth > 0.0f) break;
    float z_end = i < count ? depths[i] : frame.far_depth;
    walk_samples(max(z, walk.start_z), z_end);
    if (i == count) break;
    uvec2 p = payloads[i];
    uint kind = (p.y >> 8u) & 3u;
    if (kind == VR_KIND_MESH && z_end >= walk.start_z) {
      walk_to_layer_of(z_end);
      walk_add(unpackUnorm4x8(p.x), z_end);
    } else if (kind != VR_KIND_MESH) {
      uint bit = 1u << (p.y & 255u);
      walk.live = ((p.y >> 10u) & 1u) != 0u ? (walk.live | bit) : (walk.live & ~bit);
      walk.checked_until = -1.0f;
    }
    z = z_end;
  }
  close_layers(walk.layer, frame.layer_count, walk.acc);
  PixelResult r;
  r.depth = walk.depth;
  r.samples = walk.samples;
  r.shaded = shaded_samples;
  r.fetches = atlas_fetches;
  return r;
}
