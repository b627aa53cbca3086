#include "passes/volume_render_reference.h"

#include <algorithm>
#include <cmath>

#include "shared/background.h"
#include "shared/resolve_walk_access.h"
#include "shared/volume_shading.h"

namespace strata {
namespace gpu {
namespace {

using glm::ivec3;  // the software sampler's voxel coordinates, by their GLSL name like the rest

// One pixel's work on the CPU. The shared resolve is included inside this struct, so its
// functions see `frame` and the sampling functions below as members. It is compiled with the
// layer keep hook (picking walks the picture as ghosting draws it): with every layer kept whole,
// the resolve's own walk.
struct Reference {
  FrameGpu frame;
  const RenderInputs& in;
  std::vector<vec4> table;  // corrected_transfer for the frame's step

  // (the walk loads the first volume's data whatever the count, as the GPU's one-entry buffer)
  VolumeGpu volume_info(uint v) const {
    return v < in.volumes.size() ? in.volumes[v] : VolumeGpu{};
  }

  // Linear filtering with clamp-to-edge addressing, as the GPU's sampler does.
  vec4 volume_sample(uint v, vec3 tc) const {
    const VolumeGpu& vol = in.volumes[v];
    const vec3 a = vec3(vol.atlas_offset) + tc * vec3(vol.atlas_scale);
    const vec3 x = a * vec3(in.atlas_dims) - 0.5f;
    const vec3 base = floor(x);
    const vec3 f = x - base;
    const ivec3 top = ivec3(in.atlas_dims) - 1;
    vec4 sum(0.0f);
    for (int corner = 0; corner < 8; ++corner) {
      const ivec3 o(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
      const ivec3 p = clamp(ivec3(base) + o, ivec3(0), top);
      const float w =
          (o.x ? f.x : 1.0f - f.x) * (o.y ? f.y : 1.0f - f.y) * (o.z ? f.z : 1.0f - f.z);
      const int16_t* texel =
          &in.atlas[4 * ((size_t(p.z) * in.atlas_dims.y + size_t(p.y)) * in.atlas_dims.x +
                         size_t(p.x))];
      sum += w * vec4(float(texel[0]), float(texel[1]), float(texel[2]), float(texel[3]));
    }
    return sum / 32767.0f;
  }

  vec4 table_entry(uint v, int i) const { return table[size_t(v) * VR_TF_SIZE + size_t(i)]; }

  bool volume_cut(uint v, vec3 tc) const {
    const VolumeGpu& vol = in.volumes[v];
    for (uint i = 0; i < vol.cut_count.x; ++i)
      if (dot(vec3(vol.cut[i]), tc) + vol.cut[i].w < 0.0f) return true;
    return false;
  }

  bool brick_empty(uint v, vec3 tc) const {
    const VolumeGpu& vol = in.volumes[v];
    const uvec3 bricks(vol.bricks);
    const uvec3 b = min(uvec3(tc / (vec3(vol.texel) * float(VR_BRICK))), bricks - 1u);
    return in.occupancy[vol.bricks.w + (b.z * bricks.y + b.y) * bricks.x + b.x] == 0u;
  }

  // The pixel's layers (layer l at layers[l * stride]) as the walk emits them.
  glm::vec4* layers = nullptr;
  size_t stride = 0;
  void emit_layer(uint l, vec4 colour) const { layers[l * stride] = colour; }

  // The share of each layer the walk keeps (VR_RESOLVE_LAYER_KEEP).
  float layer_keeps[VR_MAX_LAYERS] = {1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f};
  float layer_keep(uint l) const { return layer_keeps[l]; }
  PickStart start{0u, 1.0f};  // where the walk starts (a pick's: pick_start)
  bool stops_at_depth = false;
  uint walk_start_layer() const { return start.layer; }
  float walk_start_clear() const { return start.clear; }
  bool walk_stops_at_depth() const { return stops_at_depth; }

#define VR_RESOLVE_LAYER_KEEP
#include "shared/resolve_walk.h"
#undef VR_RESOLVE_LAYER_KEEP
};
static_assert(ResolveWalkLayerKeepAccess<Reference>);
static_assert(VR_MAX_LAYERS == 8, "layer_keeps' initialiser");

struct Fragment {
  float depth;
  uvec2 payload;
};

// Möller-Trumbore; t is the eye depth because the ray's direction is per unit of eye depth.
bool intersect(const vec3& o, const vec3& d, const vec3& a, const vec3& b, const vec3& c, float& t,
               float& u, float& v) {
  const vec3 e1 = b - a, e2 = c - a, p = cross(d, e2);
  const float det = dot(e1, p);
  if (std::abs(det) < 1e-12f) return false;
  const vec3 s = o - a, q = cross(s, e1);
  u = dot(s, p) / det;
  v = dot(d, q) / det;
  t = dot(e2, q) / det;
  return u >= 0.0f && v >= 0.0f && u + v <= 1.0f;
}

std::vector<Fragment> mesh_fragments(const RenderInputs& in, const FrameGpu& frame,
                                     const vec3& origin, const vec3& direction) {
  std::vector<Fragment> out;
  const auto visible = [&](float t) { return t >= frame.near_depth && t <= frame.far_depth; };
  for (uint m = 0; m < in.meshes.size(); ++m) {
    const RenderInputs::MeshDraw& draw = in.meshes[m];
    const mat4 model_view = frame.world_to_view * draw.transform;
    const mat3 normal_matrix = transpose(inverse(mat3(model_view)));
    for (uint i = 0; i + 2 < draw.index_count; i += 3) {
      vec3 p[3], n[3];
      for (uint k = 0; k < 3; ++k) {
        const uint index = in.indices[draw.first_index + i + k];
        p[k] = vec3(draw.transform * in.vertices[2 * size_t(index)]);
        n[k] = normal_matrix * vec3(in.vertices[2 * size_t(index) + 1]);
      }
      float t, u, v;
      if (!intersect(origin, direction, p[0], p[1], p[2], t, u, v) || !visible(t)) continue;
      const vec3 view_position = vec3(frame.world_to_view * vec4(origin + direction * t, 1.0f));
      const vec3 normal = (1.0f - u - v) * n[0] + u * n[1] + v * n[2];
      out.push_back({t, uvec2(mesh_payload_color(draw.color, normal, -normalize(view_position)),
                              m | (VR_KIND_MESH << 8u))});
    }
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const Fragment& a, const Fragment& b) { return a.depth < b.depth; });
  return out;
}

// The mesh fragments along the ray through `pixel`, in the walk's arrays (the first
// VR_MAX_MESH_FRAGMENTS, as the GPU's resolve keeps); returns how many.
uint32_t walk_fragments(const Reference& ref, vec2 pixel, float (&depths)[VR_MAX_FRAGMENTS],
                        uvec2 (&payloads)[VR_MAX_FRAGMENTS]) {
  const Ray ray = frame_pixel_ray(ref.frame, pixel);
  const std::vector<Fragment> found = mesh_fragments(ref.in, ref.frame, ray.origin, ray.direction);
  const uint32_t count = uint32_t(std::min<size_t>(found.size(), VR_MAX_MESH_FRAGMENTS));
  for (uint32_t i = 0; i < count; ++i) {
    depths[i] = found[i].depth;
    payloads[i] = found[i].payload;
  }
  return count;
}

}  // namespace
}  // namespace gpu

ReferencePixel walk_reference_pixel(const RenderInputs& inputs, const gpu::FrameGpu& frame,
                                    glm::vec2 pixel, std::span<const float> keep,
                                    const gpu::PickStart* pick) {
  gpu::Reference ref{frame, inputs, corrected_transfer(inputs, frame.step)};
  for (size_t l = 0; l < keep.size() && l < VR_MAX_LAYERS; ++l) ref.layer_keeps[l] = keep[l];
  if (pick) {
    ref.start = *pick;
    ref.stops_at_depth = true;
  }
  ReferencePixel out;
  out.layers.assign(frame.layer_count, glm::vec4(0.0f));
  ref.layers = out.layers.data();
  ref.stride = 1;
  float depths[VR_MAX_FRAGMENTS];
  glm::uvec2 payloads[VR_MAX_FRAGMENTS];
  const uint32_t count = gpu::walk_fragments(ref, pixel, depths, payloads);
  out.depth = ref.resolve_pixel(pixel, count, depths, payloads).depth;
  return out;
}

ReferenceImage render_reference(const RenderInputs& inputs, const Camera& camera,
                                const RenderSettings& settings, graph::Extent size) {
  const gpu::FrameGpu frame = frame_data(inputs, camera, settings, size, 1);
  gpu::Reference ref{frame, inputs, corrected_transfer(inputs, frame.step)};
  ReferenceImage image;
  image.size = size;
  image.layer_count = settings.layer_count;
  const size_t pixels = size_t{size.width} * size.height;
  image.layers.assign(pixels * settings.layer_count, glm::vec4(0.0f));
  image.final.assign(pixels, glm::vec4(0.0f));
  image.depth.assign(pixels, 0.0f);
  for (uint32_t y = 0; y < size.height; ++y) {
    for (uint32_t x = 0; x < size.width; ++x) {
      const glm::vec2 centre(float(x) + 0.5f, float(y) + 0.5f);
      float depths[VR_MAX_FRAGMENTS];
      glm::uvec2 payloads[VR_MAX_FRAGMENTS];
      const uint32_t count = gpu::walk_fragments(ref, centre, depths, payloads);
      const size_t p = size_t{y} * size.width + x;
      ref.layers = &image.layers[p];
      ref.stride = pixels;
      const auto r = ref.resolve_pixel(centre, count, depths, payloads);
      glm::vec4 all(0.0f);
      for (uint32_t l = 0; l < settings.layer_count; ++l)
        all = gpu::over(all, image.layers[l * pixels + p]);
      image.final[p] =
          gpu::straight_alpha(gpu::over_background(all, background_rgba(settings.background)));
      image.depth[p] = r.depth;
      image.samples += r.samples;
      image.shaded += r.shaded;
    }
  }
  return image;
}

}  // namespace strata
