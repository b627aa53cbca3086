#include "passes/volume_renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <future>
#include <thread>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/core/error.h"
#include "engine/gpu/context.h"
#include "engine/graph/graph_runner.h"
#include "shared/volume_render.h"
#include "shared/volume_shading.h"

namespace strata {

using graph::ResourceId;
using graph::Use;

static_assert(VR_MAX_LAYERS == kMaxLayers, "the scene side's layer limit is the renderer's");
static_assert(VR_MAX_CUT_PLANES == kMaxCutPlanes, "the scene side's cut-away limit");

namespace {

// Volumes live in one 3D atlas, stacked along z with replicated borders: one sampler, no
// descriptor indexing (lavapipe lacks it), any input voxel type. Each texel holds the gradient
// (central differences, per voxel) and the normalised intensity, so one filtered fetch gives a
// sample and its normal instead of seven.
constexpr VkFormat kAtlasFormat = VK_FORMAT_R16G16B16A16_SNORM;
constexpr float kSnorm = 32767.0f;

glm::mat4 texture_to_world(const Volume& v);

// Volume v's cut-away planes (world) in its texture space, where the walk tests them:
// n . (A tc + b) + d = (A^T n) . tc + n . b + d.
void set_cut_planes(const Volume& v, const std::vector<glm::vec4>& planes, gpu::VolumeGpu& info) {
  if (planes.size() > VR_MAX_CUT_PLANES)
    throw Error("volume '" + v.name + "': " + std::to_string(planes.size()) +
                " cut-away planes, at most " + std::to_string(VR_MAX_CUT_PLANES));
  const glm::mat4 to_world = texture_to_world(v);
  info.cut_count = glm::uvec4(uint32_t(planes.size()), 0u, 0u, 0u);
  for (size_t c = 0; c < planes.size(); ++c) {
    const glm::vec3 n(planes[c]);
    info.cut[c] = glm::vec4(glm::transpose(glm::mat3(to_world)) * n,
                            glm::dot(n, glm::vec3(to_world[3])) + planes[c].w);
  }
}

glm::mat4 texture_to_world(const Volume& v) {
  const glm::mat4 voxel_from_texture = glm::translate(glm::mat4(1.0f), glm::vec3(-0.5f)) *
                                       glm::scale(glm::mat4(1.0f), glm::vec3(v.dims));
  return v.index_to_world() * voxel_from_texture;
}

// Runs slices(first, last) over [0, count) split between the machine's cores. (On one core the
// demo's atlas waited while lavapipe's pipelines compiled on the other.)
template <typename F>
void over_slices(uint32_t count, const F& slices) {
  const uint32_t parts = std::clamp(std::thread::hardware_concurrency(), 1u, 16u);
  std::vector<std::future<void>> rest;
  for (uint32_t p = 1; p < parts; ++p) {
    rest.push_back(std::async(std::launch::async, [&slices, count, parts, p] {
      slices(uint32_t(uint64_t(count) * p / parts), uint32_t(uint64_t(count) * (p + 1) / parts));
    }));
  }
  slices(0u, count / parts);
  for (std::future<void>& part : rest) part.get();
}

// Each voxel as intensity normalised over the volume's value range, quantised to 15 bits (the
// positive half of a 16-bit SNORM channel).
std::vector<int16_t> normalised(const Volume& v) {
  std::vector<int16_t> out(v.voxel_count());
  const float lo = v.value_range.x;
  const float span = v.value_range.y > lo ? v.value_range.y - lo : 1.0f;
  over_slices(v.dims.z, [&](uint32_t first, uint32_t last) {
    for (uint32_t k = first; k < last; ++k) {
      size_t n = size_t(k) * v.dims.y * v.dims.x;
      for (uint32_t j = 0; j < v.dims.y; ++j) {
        for (uint32_t i = 0; i < v.dims.x; ++i) {
          const float t = std::clamp((v.value(i, j, k) - lo) / span, 0.0f, 1.0f);
          out[n++] = static_cast<int16_t>(std::lround(t * kSnorm));
        }
      }
    }
  });
  return out;
}

// Min and max of every brick's samples, dilated by one voxel: the trilinear footprint of any
// point inside a brick stays within it.
void brick_ranges(const std::vector<int16_t>& t, glm::uvec3 dims, glm::uvec3 bricks,
                  std::vector<glm::vec2>& out) {
  for (uint32_t bz = 0; bz < bricks.z; ++bz) {
    for (uint32_t by = 0; by < bricks.y; ++by) {
      for (uint32_t bx = 0; bx < bricks.x; ++bx) {
        const glm::ivec3 lo = glm::ivec3(bx, by, bz) * VR_BRICK - 1;
        const glm::ivec3 hi = glm::min(lo + (VR_BRICK + 1), glm::ivec3(dims) - 1);
        const glm::ivec3 first = glm::max(lo, glm::ivec3(0));
        int16_t mn = 32767, mx = 0;
        for (int z = first.z; z <= hi.z; ++z) {
          for (int y = first.y; y <= hi.y; ++y) {
            for (int x = first.x; x <= hi.x; ++x) {
              const int16_t s = t[(size_t(z) * dims.y + y) * dims.x + x];
              mn = std::min(mn, s);
              mx = std::max(mx, s);
            }
          }
        }
        out.emplace_back(float(mn) / kSnorm, float(mx) / kSnorm);
      }
    }
  }
}

float finest_world_spacing(const glm::mat4& texture_to_world, glm::uvec3 dims) {
  float finest = 3.4e38f;
  for (int axis = 0; axis < 3; ++axis) {
    finest = std::min(finest, glm::length(glm::vec3(texture_to_world[axis])) / float(dims[axis]));
  }
  return finest;
}

VkDeviceSize at_least(VkDeviceSize bytes) {
  return std::max<VkDeviceSize>(bytes, 64);
}

}  // namespace

VolumeLimits device_volume_limits(const Context& ctx) {
  VkPhysicalDeviceMaintenance3Properties maintenance{
      .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES};
  VkPhysicalDeviceProperties2 properties{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2,
                                         .pNext = &maintenance};
  vkGetPhysicalDeviceProperties2(ctx.physical_device(), &properties);
  VkPhysicalDeviceMemoryProperties memory{};
  vkGetPhysicalDeviceMemoryProperties(ctx.physical_device(), &memory);
  VkDeviceSize largest_heap = 0;
  for (uint32_t i = 0; i < memory.memoryHeapCount; ++i)
    if (memory.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      largest_heap = std::max(largest_heap, memory.memoryHeaps[i].size);
  const uint64_t bytes = std::min<uint64_t>(maintenance.maxMemoryAllocationSize, largest_heap);
  constexpr uint32_t voxel_bytes = 4 * sizeof(int16_t);  // kAtlasFormat
  const uint32_t side = properties.properties.limits.maxImageDimension3D;
  return {.max_side = side > 2 * VR_ATLAS_BORDER ? side - 2 * VR_ATLAS_BORDER : 0,
          .max_device_voxels = bytes / voxel_bytes,
          .device_voxel_bytes = voxel_bytes,
          .device = properties.properties.deviceName};
}

namespace {

void extend_bounds(RenderInputs& in, const glm::vec3& p) {
  in.scene_min = glm::min(in.scene_min, p);
  in.scene_max = glm::max(in.scene_max, p);
}

// The atlas: every volume stacked along z with a border of replicated edge voxels; its size
// checked against the device's.
glm::uvec3 checked_atlas_dims(const Scene& scene, uint32_t max_image_dimension_3d,
                              uint64_t max_bytes) {
  glm::uvec3 dims(1, 1, 0);
  for (const Volume& v : scene.volumes) {
    dims.x = std::max(dims.x, v.dims.x + 2 * VR_ATLAS_BORDER);
    dims.y = std::max(dims.y, v.dims.y + 2 * VR_ATLAS_BORDER);
    dims.z += v.dims.z + 2 * VR_ATLAS_BORDER;
  }
  dims.z = std::max(dims.z, 1u);
  if (dims.x > max_image_dimension_3d || dims.y > max_image_dimension_3d ||
      dims.z > max_image_dimension_3d) {
    throw Error(scene.source.string() + ": the volumes need a " + std::to_string(dims.x) + "x" +
                std::to_string(dims.y) + "x" + std::to_string(dims.z) +
                " atlas; this device allows " + std::to_string(max_image_dimension_3d) +
                " per side");
  }
  const uint64_t atlas_bytes = 4 * sizeof(int16_t) * uint64_t(dims.x) * dims.y * dims.z;
  if (atlas_bytes > max_bytes) {
    throw Error(scene.source.string() + ": the volumes need a " + std::to_string(dims.x) + "x" +
                std::to_string(dims.y) + "x" + std::to_string(dims.z) + " atlas of " +
                std::to_string(atlas_bytes >> 20) + " MiB; this device takes at most " +
                std::to_string(max_bytes >> 20) + " MiB in one allocation");
  }
  return dims;
}

// One volume's slab of the atlas from slice z0 on: per voxel the central-difference gradient and
// the normalised value `t`, the border replicating the edge.
void fill_atlas_slab(const Volume& v, const std::vector<int16_t>& t, glm::uvec3 dims, uint32_t z0,
                     std::vector<int16_t>& atlas) {
  const glm::ivec3 vd(v.dims);
  over_slices(v.dims.z + 2 * VR_ATLAS_BORDER, [&](uint32_t first, uint32_t last) {
    for (uint32_t az = first; az < last; ++az) {
      const int k = std::clamp(int(az) - int(VR_ATLAS_BORDER), 0, vd.z - 1);
      for (uint32_t ay = 0; ay < dims.y; ++ay) {
        const int j = std::clamp(int(ay) - int(VR_ATLAS_BORDER), 0, vd.y - 1);
        int16_t* row = &atlas[4 * (size_t(z0 + az) * dims.y + ay) * dims.x];
        for (uint32_t ax = 0; ax < dims.x; ++ax) {
          const int i = std::clamp(int(ax) - int(VR_ATLAS_BORDER), 0, vd.x - 1);
          const auto at = [&](int x, int y, int z) {  // clamped to the volume's edge
            const size_t cz = size_t(std::clamp(z, 0, vd.z - 1));
            const size_t cy = size_t(std::clamp(y, 0, vd.y - 1));
            const size_t cx = size_t(std::clamp(x, 0, vd.x - 1));
            return int(t[(cz * vd.y + cy) * vd.x + cx]);
          };
          row[4 * ax + 0] = int16_t((at(i + 1, j, k) - at(i - 1, j, k)) / 2);
          row[4 * ax + 1] = int16_t((at(i, j + 1, k) - at(i, j - 1, k)) / 2);
          row[4 * ax + 2] = int16_t((at(i, j, k + 1) - at(i, j, k - 1)) / 2);
          row[4 * ax + 3] = t[(size_t(k) * vd.y + j) * vd.x + i];
        }
      }
    }
  });
}

// What the shaders know of volume `index` (of `count`) whose slab starts at atlas slice z0: its
// maps to and from world space, its place in the atlas and its cut planes (its bricks are the
// caller's).
gpu::VolumeGpu volume_info(const Volume& v, const glm::mat4& to_world, uint32_t index, size_t count,
                           glm::uvec3 dims, uint32_t z0) {
  gpu::VolumeGpu info{};
  info.world_to_texture = glm::inverse(to_world);
  // Per voxel to per texture unit (× dims), then world: gradients transform with the transpose
  // of the world-to-texture map.
  const glm::mat3 gradient =
      glm::transpose(glm::mat3(info.world_to_texture)) *
      glm::mat3(glm::vec3(v.dims.x, 0, 0), glm::vec3(0, v.dims.y, 0), glm::vec3(0, 0, v.dims.z));
  info.gradient_to_world = glm::mat4(gradient);
  const glm::vec3 atlas_size(dims);
  info.atlas_offset =
      glm::vec4(glm::vec3(VR_ATLAS_BORDER, VR_ATLAS_BORDER, z0 + VR_ATLAS_BORDER) / atlas_size,
                (float(index) + 0.5f) / float(count));
  const float spacing = finest_world_spacing(to_world, v.dims);
  info.atlas_scale = glm::vec4(glm::vec3(v.dims) / atlas_size, spacing);
  info.texel = glm::vec4(1.0f / glm::vec3(v.dims), 0.0f);
  set_cut_planes(v, v.cut, info);
  return info;
}

// Every volume into the atlas, with its VolumeGpu, bricks, bounds and transfer function.
void add_volumes(const Scene& scene, RenderInputs& in) {
  const glm::uvec3 dims = in.atlas_dims;
  uint32_t z0 = 0, first_brick = 0;
  for (uint32_t index = 0; index < scene.volumes.size(); ++index) {
    const Volume& v = scene.volumes[index];
    const std::vector<int16_t> t = normalised(v);
    fill_atlas_slab(v, t, dims, z0, in.atlas);
    const glm::mat4 to_world = texture_to_world(v);
    gpu::VolumeGpu info = volume_info(v, to_world, index, scene.volumes.size(), dims, z0);
    const glm::uvec3 bricks = (v.dims + uint32_t(VR_BRICK - 1)) / uint32_t(VR_BRICK);
    info.bricks = glm::uvec4(bricks, first_brick);
    brick_ranges(t, v.dims, bricks, in.brick_ranges);
    first_brick += bricks.x * bricks.y * bricks.z;
    in.volumes.push_back(info);
    in.finest_spacing = std::min(in.finest_spacing, info.atlas_scale.w);  // (its finest spacing)
    for (int c = 0; c < 8; ++c) {
      extend_bounds(in, glm::vec3(to_world * glm::vec4(c & 1, (c >> 1) & 1, (c >> 2) & 1, 1.0f)));
    }
    in.transfer_functions.push_back(v.transfer_function >= 0
                                        ? scene.transfer_functions.at(size_t(v.transfer_function))
                                        : TransferFunction{});
    z0 += v.dims.z + 2 * VR_ATLAS_BORDER;
  }
}

// Meshes: one vertex buffer (position, normal as vec4 pairs) and one index buffer.
void add_meshes(const Scene& scene, RenderInputs& in) {
  for (const Mesh& mesh : scene.meshes) {
    const uint32_t base = static_cast<uint32_t>(in.vertices.size() / 2);
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      in.vertices.emplace_back(mesh.positions[i], 1.0f);
      in.vertices.emplace_back(
          i < mesh.normals.size() ? mesh.normals[i] : glm::vec3(0.0f, 0.0f, 1.0f), 0.0f);
      extend_bounds(in, glm::vec3(mesh.transform * glm::vec4(mesh.positions[i], 1.0f)));
    }
    in.meshes.push_back({static_cast<uint32_t>(in.indices.size()),
                         static_cast<uint32_t>(mesh.indices.size()), mesh.color, mesh.transform});
    for (uint32_t index : mesh.indices) in.indices.push_back(base + index);
  }
}

}  // namespace

static_assert(kMaxVolumes == VR_MAX_VOLUMES);

RenderInputs prepare_render_inputs(const Scene& scene, uint32_t max_image_dimension_3d,
                                   uint64_t max_bytes) {
  if (scene.volumes.size() > VR_MAX_VOLUMES) {
    throw Error(scene.source.string() + ": " + std::to_string(scene.volumes.size()) +
                " volumes; strata renders at most " + std::to_string(VR_MAX_VOLUMES));
  }
  RenderInputs in;
  in.scene_min = glm::vec3(3.4e38f);
  in.scene_max = glm::vec3(-3.4e38f);
  in.finest_spacing = 3.4e38f;
  in.atlas_dims = checked_atlas_dims(scene, max_image_dimension_3d, max_bytes);
  const glm::uvec3 dims = in.atlas_dims;
  in.atlas.assign(4 * size_t(dims.x) * dims.y * dims.z, 0);
  add_volumes(scene, in);
  add_meshes(scene, in);
  if (in.finest_spacing > 1e30f)
    in.finest_spacing = glm::length(in.scene_max - in.scene_min) / 256.0f;
  in.update_transfer();
  return in;
}

// The transfer table samples each function at its entries' centres. A brick is occupied when
// any entry its value range can reach (with the linear filter's neighbours) has alpha above 0.
void RenderInputs::update_transfer() {
  const size_t rows = std::max<size_t>(1, transfer_functions.size());
  transfer_table.assign(VR_TF_SIZE * rows, glm::vec4(0.0f));
  for (size_t row = 0; row < transfer_functions.size(); ++row) {
    for (uint32_t i = 0; i < VR_TF_SIZE; ++i) {
      transfer_table[row * VR_TF_SIZE + i] =
          transfer_functions[row].sample((float(i) + 0.5f) / VR_TF_SIZE);
    }
  }
  occupancy.assign(brick_ranges.size(), 0);
  for (size_t v = 0; v < volumes.size(); ++v) {
    const glm::uvec4 b = volumes[v].bricks;
    for (uint32_t n = 0; n < b.x * b.y * b.z; ++n) {
      const glm::vec2 range = brick_ranges[b.w + n];
      const int lo = std::clamp(int(std::floor(range.x * VR_TF_SIZE - 0.5f)), 0, VR_TF_SIZE - 1);
      const int hi = std::clamp(int(std::ceil(range.y * VR_TF_SIZE - 0.5f)), 0, VR_TF_SIZE - 1);
      for (int i = lo; i <= hi && !occupancy[b.w + n]; ++i) {
        occupancy[b.w + n] = transfer_table[v * VR_TF_SIZE + size_t(i)].a > 0.0f;
      }
    }
  }
}

std::vector<glm::vec4> corrected_transfer(const RenderInputs& inputs, float step) {
  std::vector<glm::vec4> table = inputs.transfer_table;
  for (size_t v = 0; v < inputs.volumes.size() && (v + 1) * VR_TF_SIZE <= table.size(); ++v) {
    const float reference = inputs.volumes[v].atlas_scale.w;
    for (size_t i = v * VR_TF_SIZE; i < (v + 1) * VR_TF_SIZE; ++i) {
      table[i].a = gpu::corrected_alpha(table[i].a, step, reference);
    }
  }
  return table;
}

std::vector<float> split_depths(const RenderInputs& in, const Camera& camera,
                                const RenderSettings& settings) {
  const uint32_t layers = settings.layer_count;
  if (!settings.splits.empty()) {
    if (settings.splits.size() != layers - 1) {
      throw Error("layers: " + std::to_string(layers) + " layers need " +
                  std::to_string(layers - 1) + " split depths, " +
                  std::to_string(settings.splits.size()) + " given");
    }
    return settings.splits;
  }
  // Evenly over the eye depths the scene's bounds cover, inside the near and far planes.
  float lo = 3.4e38f, hi = -3.4e38f;
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner((c & 1) ? in.scene_max.x : in.scene_min.x,
                           (c & 2) ? in.scene_max.y : in.scene_min.y,
                           (c & 4) ? in.scene_max.z : in.scene_min.z);
    const float depth = -(camera.view * glm::vec4(corner, 1.0f)).z;
    lo = std::min(lo, depth);
    hi = std::max(hi, depth);
  }
  lo = std::clamp(lo, camera.near_plane, camera.far_plane);
  hi = std::clamp(hi, lo, camera.far_plane);
  std::vector<float> splits;
  for (uint32_t i = 1; i < layers; ++i) splits.push_back(lo + (hi - lo) * float(i) / float(layers));
  return splits;
}

gpu::FrameGpu frame_data(const RenderInputs& in, const Camera& camera,
                         const RenderSettings& settings, graph::Extent e, uint32_t table_size) {
  if (uint64_t{e.width} * e.height > (1u << 24)) {
    throw Error("render: " + std::to_string(e.width) + "x" + std::to_string(e.height) +
                " is more than the HA-Buffer's 16M pixels");
  }
  if (settings.layer_count < 1 || settings.layer_count > VR_MAX_LAYERS) {
    throw Error("layers: " + std::to_string(settings.layer_count) + " is not in 1.." +
                std::to_string(VR_MAX_LAYERS));
  }
  gpu::FrameGpu f{};
  f.world_to_view = camera.view;
  f.view_to_world = glm::inverse(camera.view);
  const glm::mat4 projection = camera.projection(float(e.width) / float(e.height));
  f.view_to_clip = projection;
  f.clip_to_view = glm::inverse(projection);
  const std::vector<float> splits = split_depths(in, camera, settings);
  for (size_t i = 0; i < splits.size(); ++i) f.splits[i / 4][int(i % 4)] = splits[i];
  f.background = background_rgba(settings.background);
  f.width = e.width;
  f.height = e.height;
  f.layer_count = settings.layer_count;
  f.volume_count = static_cast<uint32_t>(in.volumes.size());
  f.table_size = table_size;
  f.skip_empty = settings.skip_empty ? 1u : 0u;
  f.mesh_count = static_cast<uint32_t>(in.meshes.size());
  f.near_depth = camera.near_plane;
  f.far_depth = camera.far_plane;
  f.step = settings.step > 0.0f ? settings.step : 0.5f * in.finest_spacing;
  f.termination_alpha = settings.termination_alpha;
  f.depth_alpha = settings.depth_alpha;
  return f;
}

VolumeRenderer::VolumeRenderer(Context& ctx, const Scene& scene, RenderSettings settings)
    : ctx_(ctx),
      settings_(std::move(settings)),
      camera_(camera_for(scene, "")),
      inputs_([&] {
        const VolumeLimits limits = device_volume_limits(ctx);
        return prepare_render_inputs(scene, ctx.properties().limits.maxImageDimension3D,
                                     limits.max_device_voxels * limits.device_voxel_bytes);
      }()),
      group_order_(ctx.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU
                       ? VR_ORDER_ROWS_INTERLEAVED
                       : VR_ORDER_ROWS),
      counters_readback_(ctx, VR_COUNTER_COUNT * sizeof(uint32_t)),
      build_(ctx, "habuffer_build.vert", "habuffer_build.frag", {}),
      // (one volume and no meshes, the common case: a resolve the compiler specialises)
      resolve_(ctx, inputs_.volumes.size() == 1 && inputs_.meshes.empty()
                        ? "habuffer_resolve_one_volume.comp"
                        : "habuffer_resolve.comp"),
      upscale_(ctx, "volume_upscale.comp") {
  frame_data(inputs_, camera_, settings_, {1, 1}, 1);  // checks the settings early
  const glm::uvec3 d = inputs_.atlas_dims;
  atlas_ =
      Image(ctx, {kAtlasFormat, {d.x, d.y, d.z}, VK_IMAGE_TYPE_3D, VK_IMAGE_USAGE_SAMPLED_BIT});
  upload(ctx, atlas_, as_bytes(inputs_.atlas), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  const auto filled = [&](const auto& data, VkBufferUsageFlags usage) {
    Buffer b(ctx, at_least(data.size() * sizeof(data[0])), usage, MemoryKind::device_local);
    upload(ctx, b, as_bytes(data));
    return b;
  };
  vertices_ = filled(inputs_.vertices, storage);
  indices_ = filled(inputs_.indices, storage);
  // (a uniform buffer of the block's VR_MAX_VOLUMES records: GPUs read them as constants instead
  // of holding them in registers)
  std::vector<gpu::VolumeGpu> volume_data = inputs_.volumes;
  volume_data.resize(VR_MAX_VOLUMES);
  volumes_ = filled(volume_data, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  occupancy_ = Buffer(ctx, at_least(inputs_.occupancy.size() * sizeof(uint32_t)), storage,
                      MemoryKind::device_local);
  upload_transfer();
}

void VolumeRenderer::upload_transfer(Uploads* in_frame) {
  ++transfer_version_;
  if (inputs_.occupancy.empty()) return;
  if (in_frame) {
    in_frame->add(ctx_, occupancy_, as_bytes(inputs_.occupancy));
  } else {
    upload(ctx_, occupancy_, as_bytes(inputs_.occupancy));
  }
}

void VolumeRenderer::set_cut(uint32_t volume, const Volume& v, Uploads* in_frame) {
  set_cut_planes(v, v.cut, inputs_.volumes.at(volume));
  std::vector<gpu::VolumeGpu> volume_data = inputs_.volumes;
  volume_data.resize(VR_MAX_VOLUMES);
  if (in_frame) {
    in_frame->add(ctx_, volumes_, as_bytes(volume_data));
  } else {
    upload(ctx_, volumes_, as_bytes(volume_data));
  }
  ++transfer_version_;  // (an interactive frame casts its rays again)
}

void VolumeRenderer::set_transfer_function(uint32_t volume, const TransferFunction& tf,
                                           Uploads* in_frame) {
  inputs_.transfer_functions.at(volume) = tf;
  inputs_.update_transfer();
  upload_transfer(in_frame);
}

void VolumeRenderer::set_table_size(uint32_t slots) {
  forced_slots_ = std::max(slots, 1u);
}

uint32_t VolumeRenderer::slots_for(graph::Extent e) const {
  if (forced_slots_) return forced_slots_;
  if (inputs_.meshes.empty()) return 1;  // volume boxes need no slots; the resolve skips the table
  const double wanted =
      double(e.width) * e.height * settings_.expected_depth_complexity / settings_.load_factor;
  return static_cast<uint32_t>(std::min(std::ceil(wanted), 4.0e9));
}

VolumeRenderer::Transients VolumeRenderer::add_transients(graph::Graph& graph) const {
  const auto slots = [this](graph::Extent e) { return VkDeviceSize{slots_for(e)} * 8; };
  Transients t;
  t.frame = graph.add_buffer("render.frame",
                             {[](graph::Extent) { return VkDeviceSize{sizeof(gpu::FrameGpu)}; }});
  t.keys = graph.add_buffer("render.keys", {slots});
  t.payload = graph.add_buffer("render.payload", {slots});
  // (written each frame: corrected for the frame's step, which the viewer may change any time)
  const VkDeviceSize table_bytes = inputs_.transfer_table.size() * sizeof(glm::vec4);
  t.transfer =
      graph.add_buffer("render.transfer", {[table_bytes](graph::Extent) { return table_bytes; }});
  t.counters = graph.add_buffer("render.counters", {[](graph::Extent) {
                                  return VkDeviceSize{VR_COUNTER_COUNT * sizeof(uint32_t)};
                                }});
  return t;
}

VolumeRenderer::Outputs VolumeRenderer::add_images(graph::Graph& graph, const std::string& suffix,
                                                   bool keep) const {
  Outputs o;
  o.layers =
      graph.add_image("render.layers" + suffix,
                      {VK_FORMAT_R16G16B16A16_SFLOAT, {}, settings_.layer_count, true, keep});
  o.final =
      graph.add_image("render.final" + suffix, {VK_FORMAT_R8G8B8A8_UNORM, {}, 1, false, keep});
  o.depth = graph.add_image("render.depth" + suffix, {VK_FORMAT_R32_SFLOAT, {}, 1, false, keep});
  return o;
}

void VolumeRenderer::import_scene(graph::Graph& graph) {
  const auto uploaded = [&graph](const char* name, const Buffer& buffer) {
    return graph.import_buffer(name, {.buffer = buffer.handle(), .has_content = true});
  };
  ids_.atlas = graph.import_image("render.atlas",
                                  {.image = atlas_.handle(),
                                   .view = atlas_.view(),
                                   .format = kAtlasFormat,
                                   .has_content = true,
                                   .initial_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
  ids_.volumes = uploaded("render.volumes", volumes_);
  ids_.occupancy = uploaded("render.occupancy", occupancy_);
  ids_.vertices = uploaded("render.vertices", vertices_);
  ids_.indices = uploaded("render.indices", indices_);
  ids_.readback = counters_readback_.import(graph, "render.counters_readback");
}

// The frame's data and transfer table written, the counters and the HA-Buffer's keys cleared;
// nothing but the counters when the frame casts the same rays as the last (interactive, at rest).
void VolumeRenderer::add_clear_pass(graph::Graph& graph, const Transients& t) {
  graph.add_pass({"render.clear",
                  graph::PassKind::transfer,
                  {{t.frame, Use::transfer_dst},
                   {t.transfer, Use::transfer_dst},
                   {t.keys, Use::transfer_dst},
                   {t.counters, Use::transfer_dst}},
                  [this, t](graph::PassContext& pc) {
                    gpu::FrameGpu data = frame_data(inputs_, camera_, settings_,
                                                    cast_size(pc.viewport), slots_for(pc.viewport));
                    data.group_order = group_order_;
                    vkCmdFillBuffer(pc.cmd, pc.buffer(t.counters), 0, VK_WHOLE_SIZE, 0);
                    const Cast now{data, transfer_version_, pc.allocation()};
                    reuse_cast_ = settings_.interactive && same_cast(now);
                    if (reuse_cast_) return;
                    if (settings_.interactive) last_cast_ = now;
                    vkCmdUpdateBuffer(pc.cmd, pc.buffer(t.frame), 0, sizeof data, &data);
                    const std::vector<glm::vec4> table = corrected_transfer(inputs_, data.step);
                    vkCmdUpdateBuffer(pc.cmd, pc.buffer(t.transfer), 0,
                                      table.size() * sizeof(glm::vec4), table.data());
                    vkCmdFillBuffer(pc.cmd, pc.buffer(t.keys), 0, VK_WHOLE_SIZE, 0);
                  },
                  "render"});
}

// The HA-Buffer built from the meshes, then resolved with the volumes into the `cast` images.
void VolumeRenderer::add_cast_passes(graph::Graph& graph, const Transients& t,
                                     const Outputs& cast) {
  graph.add_pass({"render.habuffer_build",
                  graph::PassKind::graphics,
                  {{t.frame, Use::uniform, VR_BINDING_FRAME},
                   {ids_.vertices, Use::storage_read, VR_BINDING_VERTICES},
                   {ids_.indices, Use::storage_read, VR_BINDING_INDICES},
                   {t.keys, Use::storage_read_write, VR_BINDING_KEYS},
                   {t.payload, Use::storage_write, VR_BINDING_PAYLOAD},
                   {t.counters, Use::storage_read_write, VR_BINDING_COUNTERS}},
                  [this](graph::PassContext& pc) {
                    if (!reuse_cast_) record_build(pc);
                  },
                  "render"});
  graph.add_pass({"render.resolve",
                  graph::PassKind::compute,
                  {{t.frame, Use::uniform, VR_BINDING_FRAME},
                   {ids_.volumes, Use::uniform, VR_BINDING_VOLUMES},
                   {t.keys, Use::storage_read, VR_BINDING_KEYS},
                   {t.payload, Use::storage_read, VR_BINDING_PAYLOAD},
                   {t.counters, Use::storage_read_write, VR_BINDING_COUNTERS},
                   {ids_.atlas, Use::sampled, VR_BINDING_ATLAS},
                   {t.transfer, Use::storage_read, VR_BINDING_TRANSFER},
                   {ids_.occupancy, Use::storage_read, VR_BINDING_OCCUPANCY},
                   {cast.layers, Use::storage_write, VR_BINDING_LAYERS},
                   {cast.final, Use::storage_write, VR_BINDING_FINAL},
                   {cast.depth, Use::storage_write, VR_BINDING_DEPTH}},
                  [this](graph::PassContext& pc) {
                    if (reuse_cast_) return;
                    const graph::Extent e = cast_size(pc.viewport);
                    pc.dispatch(resolve_, {e.width, e.height, 1});
                  },
                  "render"});
}

VolumeRenderer::Outputs VolumeRenderer::add_to(graph::Graph& graph) {
  const Transients t = add_transients(graph);
  Outputs out = add_images(graph, "", false);
  out.frame = t.frame;
  out.keys = t.keys;
  // (interactive: the resolve writes the cast pixels, the upscale the images everyone reads)
  last_cast_.reset();  // (a new graph: new images)
  const Outputs cast = settings_.interactive ? add_images(graph, ".cast", true) : out;
  import_scene(graph);
  out.payload = t.payload;
  out.volumes = ids_.volumes;
  out.atlas = ids_.atlas;
  out.transfer = t.transfer;
  out.occupancy = ids_.occupancy;

  add_clear_pass(graph, t);
  add_cast_passes(graph, t, cast);
  if (settings_.interactive) add_upscale(graph, cast, out);
  const ResourceId counters = t.counters, readback = ids_.readback;
  graph.add_pass({"render.counters",
                  graph::PassKind::transfer,
                  {{counters, Use::transfer_src}, {readback, Use::transfer_dst}},
                  [counters, readback](graph::PassContext& pc) {
                    const VkBufferCopy region{0, 0, VR_COUNTER_COUNT * sizeof(uint32_t)};
                    vkCmdCopyBuffer(pc.cmd, pc.buffer(counters), pc.buffer(readback), 1, &region);
                  }});
  return out;
}

void VolumeRenderer::add_upscale(graph::Graph& graph, const Outputs& cast, const Outputs& out) {
  graph.add_pass({"render.upscale",
                  graph::PassKind::compute,
                  {{cast.layers, Use::storage_read, UPSCALE_BINDING_LOW_LAYERS},
                   {cast.final, Use::storage_read, UPSCALE_BINDING_LOW_FINAL},
                   {cast.depth, Use::storage_read, UPSCALE_BINDING_LOW_DEPTH},
                   {out.layers, Use::storage_write, UPSCALE_BINDING_LAYERS},
                   {out.final, Use::storage_write, UPSCALE_BINDING_FINAL},
                   {out.depth, Use::storage_write, UPSCALE_BINDING_DEPTH}},
                  [this](graph::PassContext& pc) {
                    const graph::Extent low = cast_size(pc.viewport);
                    const gpu::UpscaleParams p{{pc.viewport.width, pc.viewport.height},
                                               {low.width, low.height},
                                               std::max(settings_.divisor, 1u),
                                               settings_.layer_count};
                    pc.dispatch(upscale_, p, {pc.viewport.width, pc.viewport.height, 1});
                  },
                  "render"});
}

graph::Extent cast_extent(graph::Extent viewport, uint32_t divisor) {
  divisor = std::max(divisor, 1u);
  return {(viewport.width + divisor - 1) / divisor, (viewport.height + divisor - 1) / divisor};
}

std::vector<glm::vec4> upscale_reference(std::span<const glm::vec4> low, graph::Extent size,
                                         uint32_t divisor, uint32_t layer_count) {
  const graph::Extent cast = cast_extent(size, divisor);
  const gpu::UpscaleParams p{
      {size.width, size.height}, {cast.width, cast.height}, divisor, layer_count};
  const size_t low_pixels = size_t(cast.width) * cast.height;
  const auto at = [&](uint32_t l, glm::ivec2 q) {
    return low[l * low_pixels + size_t(q.y) * cast.width + size_t(q.x)];
  };
  std::vector<glm::vec4> out;
  for (uint32_t l = 0; l < layer_count; ++l) {
    for (uint32_t y = 0; y < size.height; ++y) {
      for (uint32_t x = 0; x < size.width; ++x) {
        const gpu::UpscaleTap t = gpu::upscale_tap({x, y}, p);
        const glm::vec4 top = glm::mix(at(l, t.p0), at(l, {t.p1.x, t.p0.y}), t.t.x);
        const glm::vec4 bottom = glm::mix(at(l, {t.p0.x, t.p1.y}), at(l, t.p1), t.t.x);
        out.push_back(glm::mix(top, bottom, t.t.y));
      }
    }
  }
  return out;
}

bool VolumeRenderer::same_cast(const Cast& c) const {
  return last_cast_ && last_cast_->transfer == c.transfer &&
         last_cast_->allocation == c.allocation &&
         std::memcmp(&last_cast_->frame, &c.frame, sizeof c.frame) == 0;
}

graph::Extent VolumeRenderer::cast_size(graph::Extent viewport) const {
  return cast_extent(viewport, settings_.interactive ? settings_.divisor : 1u);
}

void VolumeRenderer::record_build(graph::PassContext& pc) const {
  if (inputs_.meshes.empty()) return;  // volume boxes are the resolve's ray-box tests
  const graph::Extent e = cast_size(pc.viewport);
  VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
  rendering.renderArea = {{0, 0}, {e.width, e.height}};
  rendering.layerCount = 1;
  vkCmdBeginRendering(pc.cmd, &rendering);
  const VkViewport viewport{0.0f, 0.0f, float(e.width), float(e.height), 0.0f, 1.0f};
  vkCmdSetViewport(pc.cmd, 0, 1, &viewport);
  vkCmdSetScissor(pc.cmd, 0, 1, &rendering.renderArea);
  pc.bind(build_);
  for (uint32_t m = 0; m < inputs_.meshes.size(); ++m) {
    const RenderInputs::MeshDraw& draw = inputs_.meshes[m];
    const gpu::DrawGpu push{draw.transform, draw.color, draw.first_index, m, 0, 0};
    build_.push_constants(pc.cmd, push);
    vkCmdDraw(pc.cmd, draw.index_count, 1, 0, 0);
  }
  vkCmdEndRendering(pc.cmd);
}

std::vector<PipelineReport> VolumeRenderer::pipeline_statistics() const {
  return {{resolve_.name(), resolve_.statistics()}};
}

RenderStats VolumeRenderer::collect(graph::GraphRunner& runner) {
  uint32_t c[VR_COUNTER_COUNT];
  std::memcpy(c, counters_readback_.data().data(), sizeof c);
  RenderStats stats;
  stats.overflow = c[VR_COUNTER_OVERFLOW];
  stats.fragments = c[VR_COUNTER_FRAGMENTS];
  stats.resolve_overflow = c[VR_COUNTER_RESOLVE_OVERFLOW];
  stats.samples = c[VR_COUNTER_SAMPLES];
  stats.shaded = c[VR_COUNTER_SHADED];
  stats.fetches = c[VR_COUNTER_FETCHES];
  const uint32_t now = slots_for(runner.viewport());
  stats.table_size = now;
  // Counters of a frame made with a smaller table (in flight when the table last grew) say
  // nothing about the table now: growing again for them doubled the table twice.
  const bool current = c[VR_COUNTER_TABLE_SIZE] >= now;
  if (current && (stats.overflow > 0 || stats.fragments > 0.75 * now)) {
    const double needed = (double(stats.fragments) + stats.overflow) / settings_.load_factor;
    forced_slots_ = static_cast<uint32_t>(std::min(std::max(needed, 2.0 * now), 4.0e9));
    runner.reallocate();
  }
  return stats;
}

RenderStats VolumeRenderer::run_until_no_overflow(
    graph::GraphRunner& runner, const std::function<void(const RenderStats&)>& on_overflow) {
  RenderStats stats;
  for (int attempt = 0; attempt < 4; ++attempt) {
    runner.run_now();
    stats = collect(runner);
    if (stats.overflow == 0) break;
    if (on_overflow) on_overflow(stats);
  }
  return stats;
}

}  // namespace strata
