#include "passes/volume_renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/context.h"
#include "engine/error.h"
#include "engine/graph_runner.h"
#include "shared/volume_render.h"

namespace strata {

using graph::ResourceId;
using graph::Use;

namespace {

// Volumes live in one 3D atlas, stacked along z with replicated borders, as normalised 16-bit
// intensity: one sampler, no descriptor indexing (lavapipe lacks it), any input voxel type.
constexpr VkFormat kAtlasFormat = VK_FORMAT_R16_UNORM;
constexpr VkFormat kTableFormat = VK_FORMAT_R32G32B32A32_SFLOAT;

glm::mat4 texture_to_world(const Volume& v) {
  const glm::mat4 voxel_from_texture = glm::translate(glm::mat4(1.0f), glm::vec3(-0.5f)) *
                                       glm::scale(glm::mat4(1.0f), glm::vec3(v.dims));
  return v.index_to_world() * voxel_from_texture;
}

// Each voxel as normalised intensity over the volume's value range, quantised to 16 bits.
std::vector<uint16_t> normalised(const Volume& v) {
  std::vector<uint16_t> out(v.voxel_count());
  const float lo = v.value_range.x;
  const float span = v.value_range.y > lo ? v.value_range.y - lo : 1.0f;
  size_t n = 0;
  for (uint32_t k = 0; k < v.dims.z; ++k) {
    for (uint32_t j = 0; j < v.dims.y; ++j) {
      for (uint32_t i = 0; i < v.dims.x; ++i) {
        const float t = std::clamp((v.value(i, j, k) - lo) / span, 0.0f, 1.0f);
        out[n++] = static_cast<uint16_t>(std::lround(t * 65535.0f));
      }
    }
  }
  return out;
}

// Min and max of every brick's samples, dilated by one voxel: the trilinear footprint of any
// point inside a brick stays within it.
void brick_ranges(const std::vector<uint16_t>& t, glm::uvec3 dims, glm::uvec3 bricks,
                  std::vector<glm::vec2>& out) {
  for (uint32_t bz = 0; bz < bricks.z; ++bz) {
    for (uint32_t by = 0; by < bricks.y; ++by) {
      for (uint32_t bx = 0; bx < bricks.x; ++bx) {
        const glm::ivec3 lo = glm::ivec3(bx, by, bz) * VR_BRICK - 1;
        const glm::ivec3 hi = glm::min(lo + (VR_BRICK + 1), glm::ivec3(dims) - 1);
        const glm::ivec3 first = glm::max(lo, glm::ivec3(0));
        uint16_t mn = 65535, mx = 0;
        for (int z = first.z; z <= hi.z; ++z) {
          for (int y = first.y; y <= hi.y; ++y) {
            for (int x = first.x; x <= hi.x; ++x) {
              const uint16_t s = t[(size_t(z) * dims.y + y) * dims.x + x];
              mn = std::min(mn, s);
              mx = std::max(mx, s);
            }
          }
        }
        out.emplace_back(float(mn) / 65535.0f, float(mx) / 65535.0f);
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

VkDeviceSize at_least(VkDeviceSize bytes) { return std::max<VkDeviceSize>(bytes, 64); }

}  // namespace

CameraSetup camera_for(const Scene& scene, const std::string& name) {
  CameraSetup setup{scene.camera.view, scene.camera.fov_y_degrees, scene.camera.near_plane,
                    scene.camera.far_plane};
  if (name.empty()) return setup;
  std::string names;
  for (const CameraPose& pose : scene.camera.positions) {
    if (pose.name == name) {
      setup.view = pose.view;
      return setup;
    }
    names += (names.empty() ? "" : ", ") + pose.name;
  }
  throw Error(scene.source.string() + ": no camera position named '" + name + "' (the scene has: " +
              (names.empty() ? "none" : names) + ")");
}

VolumeRenderer::VolumeRenderer(Context& ctx, const Scene& scene, RenderSettings settings)
    : ctx_(ctx),
      settings_(std::move(settings)),
      build_(ctx, "habuffer_build.vert", "habuffer_build.frag", {}),
      resolve_(ctx, "habuffer_resolve.comp") {
  if (scene.volumes.size() > VR_MAX_VOLUMES) {
    throw Error(scene.source.string() + ": " + std::to_string(scene.volumes.size()) +
                " volumes; strata renders at most " + std::to_string(VR_MAX_VOLUMES));
  }
  if (settings_.layer_count < 1 || settings_.layer_count > VR_MAX_LAYERS) {
    throw Error("layers: " + std::to_string(settings_.layer_count) + " is not in 1.." +
                std::to_string(VR_MAX_LAYERS));
  }
  camera_ = camera_for(scene, "");
  scene_min_ = glm::vec3(3.4e38f);
  scene_max_ = glm::vec3(-3.4e38f);
  finest_spacing_ = 3.4e38f;

  // The atlas: every volume stacked along z with a border of replicated edge voxels.
  glm::uvec3 atlas_dims(1, 1, 0);
  for (const Volume& v : scene.volumes) {
    atlas_dims.x = std::max(atlas_dims.x, v.dims.x + 2 * VR_ATLAS_BORDER);
    atlas_dims.y = std::max(atlas_dims.y, v.dims.y + 2 * VR_ATLAS_BORDER);
    atlas_dims.z += v.dims.z + 2 * VR_ATLAS_BORDER;
  }
  atlas_dims.z = std::max(atlas_dims.z, 1u);
  const uint32_t max_3d = ctx.properties().limits.maxImageDimension3D;
  if (atlas_dims.x > max_3d || atlas_dims.y > max_3d || atlas_dims.z > max_3d) {
    throw Error(scene.source.string() + ": the volumes need a " + std::to_string(atlas_dims.x) + "x" +
                std::to_string(atlas_dims.y) + "x" + std::to_string(atlas_dims.z) +
                " atlas; this device allows " + std::to_string(max_3d) + " per side");
  }
  std::vector<uint16_t> atlas(size_t(atlas_dims.x) * atlas_dims.y * atlas_dims.z, 0);
  uint32_t z0 = 0, first_brick = 0;
  for (uint32_t index = 0; index < scene.volumes.size(); ++index) {
    const Volume& v = scene.volumes[index];
    const std::vector<uint16_t> t = normalised(v);
    const glm::ivec3 dims(v.dims);
    for (uint32_t az = 0; az < v.dims.z + 2 * VR_ATLAS_BORDER; ++az) {
      const int k = std::clamp(int(az) - int(VR_ATLAS_BORDER), 0, dims.z - 1);
      for (uint32_t ay = 0; ay < atlas_dims.y; ++ay) {
        const int j = std::clamp(int(ay) - int(VR_ATLAS_BORDER), 0, dims.y - 1);
        uint16_t* row = &atlas[(size_t(z0 + az) * atlas_dims.y + ay) * atlas_dims.x];
        for (uint32_t ax = 0; ax < atlas_dims.x; ++ax) {
          const int i = std::clamp(int(ax) - int(VR_ATLAS_BORDER), 0, dims.x - 1);
          row[ax] = t[(size_t(k) * dims.y + j) * dims.x + i];
        }
      }
    }
    gpu::VolumeGpu info{};
    info.texture_to_world = texture_to_world(v);
    info.world_to_texture = glm::inverse(info.texture_to_world);
    const glm::vec3 atlas_size(atlas_dims);
    info.atlas_offset = glm::vec4(glm::vec3(VR_ATLAS_BORDER, VR_ATLAS_BORDER, z0 + VR_ATLAS_BORDER) / atlas_size,
                                  (float(index) + 0.5f) / float(scene.volumes.size()));
    const float spacing = finest_world_spacing(info.texture_to_world, v.dims);
    info.atlas_scale = glm::vec4(glm::vec3(v.dims) / atlas_size, spacing);
    info.texel = glm::vec4(1.0f / glm::vec3(v.dims), 0.0f);
    const glm::uvec3 bricks = (v.dims + uint32_t(VR_BRICK - 1)) / uint32_t(VR_BRICK);
    info.bricks = glm::uvec4(bricks, first_brick);
    brick_ranges(t, v.dims, bricks, brick_ranges_);
    first_brick += bricks.x * bricks.y * bricks.z;
    volume_info_.push_back(info);
    finest_spacing_ = std::min(finest_spacing_, spacing);
    for (int c = 0; c < 8; ++c) {
      const glm::vec3 corner(c & 1, (c >> 1) & 1, (c >> 2) & 1);
      const glm::vec3 p(info.texture_to_world * glm::vec4(corner, 1.0f));
      scene_min_ = glm::min(scene_min_, p);
      scene_max_ = glm::max(scene_max_, p);
    }
    transfer_functions_.push_back(v.transfer_function >= 0
                                      ? scene.transfer_functions.at(size_t(v.transfer_function))
                                      : TransferFunction{});
    z0 += v.dims.z + 2 * VR_ATLAS_BORDER;
  }
  atlas_ = Image(ctx, {kAtlasFormat, {atlas_dims.x, atlas_dims.y, atlas_dims.z}, VK_IMAGE_TYPE_3D,
                       VK_IMAGE_USAGE_SAMPLED_BIT});
  upload(ctx, atlas_, as_bytes(atlas), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);

  // Meshes: one vertex buffer (position, normal as vec4 pairs) and one index buffer.
  std::vector<glm::vec4> vertices;
  std::vector<uint32_t> indices;
  for (const Mesh& mesh : scene.meshes) {
    const uint32_t base = static_cast<uint32_t>(vertices.size() / 2);
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      vertices.emplace_back(mesh.positions[i], 1.0f);
      vertices.emplace_back(i < mesh.normals.size() ? mesh.normals[i] : glm::vec3(0.0f, 0.0f, 1.0f), 0.0f);
      const glm::vec3 p(mesh.transform * glm::vec4(mesh.positions[i], 1.0f));
      scene_min_ = glm::min(scene_min_, p);
      scene_max_ = glm::max(scene_max_, p);
    }
    mesh_draws_.push_back({static_cast<uint32_t>(indices.size()),
                           static_cast<uint32_t>(mesh.indices.size()), mesh.color, mesh.transform});
    for (uint32_t index : mesh.indices) indices.push_back(base + index);
  }
  if (finest_spacing_ > 1e30f) finest_spacing_ = glm::length(scene_max_ - scene_min_) / 256.0f;
  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  vertices_ = Buffer(ctx, at_least(vertices.size() * sizeof(glm::vec4)), storage, MemoryKind::device_local);
  indices_ = Buffer(ctx, at_least(indices.size() * sizeof(uint32_t)), storage, MemoryKind::device_local);
  volumes_ = Buffer(ctx, at_least(volume_info_.size() * sizeof(gpu::VolumeGpu)), storage,
                    MemoryKind::device_local);
  occupancy_ = Buffer(ctx, at_least(brick_ranges_.size() * sizeof(uint32_t)), storage,
                      MemoryKind::device_local);
  counters_readback_ = Buffer(ctx, VR_COUNTER_COUNT * sizeof(uint32_t), VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                              MemoryKind::host_readback);
  std::memset(counters_readback_.mapped(), 0, VR_COUNTER_COUNT * sizeof(uint32_t));
  upload(ctx, vertices_, as_bytes(vertices));
  upload(ctx, indices_, as_bytes(indices));
  upload(ctx, volumes_, as_bytes(volume_info_));
  transfer_table_ = Image(ctx, {kTableFormat, {VR_TF_SIZE, std::max<uint32_t>(1, uint32_t(volume_info_.size())), 1},
                                VK_IMAGE_TYPE_2D, VK_IMAGE_USAGE_SAMPLED_BIT});
  upload_transfer_table();
  upload_occupancy();
}

void VolumeRenderer::upload_transfer_table() {
  std::vector<glm::vec4> table(size_t(VR_TF_SIZE) * std::max<size_t>(1, transfer_functions_.size()),
                               glm::vec4(0.0f));
  for (size_t row = 0; row < transfer_functions_.size(); ++row) {
    for (uint32_t i = 0; i < VR_TF_SIZE; ++i) {
      table[row * VR_TF_SIZE + i] = transfer_functions_[row].sample((float(i) + 0.5f) / VR_TF_SIZE);
    }
  }
  upload(ctx_, transfer_table_, as_bytes(table), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
}

// A brick is occupied when any table entry its value range can reach (with the linear filter's
// neighbours) has alpha above zero.
void VolumeRenderer::upload_occupancy() {
  std::vector<uint32_t> occupied(brick_ranges_.size(), 0);
  for (size_t v = 0; v < volume_info_.size(); ++v) {
    std::vector<float> alpha(VR_TF_SIZE);
    for (uint32_t i = 0; i < VR_TF_SIZE; ++i) {
      alpha[i] = transfer_functions_[v].sample((float(i) + 0.5f) / VR_TF_SIZE).a;
    }
    const glm::uvec4 b = volume_info_[v].bricks;
    for (uint32_t n = 0; n < b.x * b.y * b.z; ++n) {
      const glm::vec2 range = brick_ranges_[b.w + n];
      const int lo = std::clamp(int(std::floor(range.x * VR_TF_SIZE - 0.5f)), 0, VR_TF_SIZE - 1);
      const int hi = std::clamp(int(std::ceil(range.y * VR_TF_SIZE - 0.5f)), 0, VR_TF_SIZE - 1);
      for (int i = lo; i <= hi && !occupied[b.w + n]; ++i) occupied[b.w + n] = alpha[i] > 0.0f;
    }
  }
  upload(ctx_, occupancy_, as_bytes(occupied));
}

void VolumeRenderer::set_transfer_function(uint32_t volume, const TransferFunction& tf) {
  transfer_functions_.at(volume) = tf;
  upload_transfer_table();
  upload_occupancy();
}

void VolumeRenderer::set_table_size(uint32_t slots) { forced_slots_ = std::max(slots, 1u); }

uint32_t VolumeRenderer::slots_for(graph::Extent e) const {
  if (forced_slots_) return forced_slots_;
  const double wanted = double(e.width) * e.height * settings_.expected_depth_complexity / settings_.load_factor;
  return static_cast<uint32_t>(std::min(std::ceil(wanted), 4.0e9));
}

std::vector<float> VolumeRenderer::split_depths(graph::Extent) const {
  const uint32_t layers = settings_.layer_count;
  if (!settings_.splits.empty()) {
    if (settings_.splits.size() != layers - 1) {
      throw Error("layers: " + std::to_string(layers) + " layers need " + std::to_string(layers - 1) +
                  " split depths, " + std::to_string(settings_.splits.size()) + " given");
    }
    return settings_.splits;
  }
  // Evenly over the eye depths the scene's bounds cover, inside the near and far planes.
  float lo = 3.4e38f, hi = -3.4e38f;
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner((c & 1) ? scene_max_.x : scene_min_.x, (c & 2) ? scene_max_.y : scene_min_.y,
                           (c & 4) ? scene_max_.z : scene_min_.z);
    const float depth = -(camera_.view * glm::vec4(corner, 1.0f)).z;
    lo = std::min(lo, depth);
    hi = std::max(hi, depth);
  }
  lo = std::clamp(lo, camera_.near_plane, camera_.far_plane);
  hi = std::clamp(hi, lo, camera_.far_plane);
  std::vector<float> splits;
  for (uint32_t i = 1; i < layers; ++i) splits.push_back(lo + (hi - lo) * float(i) / float(layers));
  return splits;
}

gpu::FrameGpu VolumeRenderer::frame_data(graph::Extent e) const {
  gpu::FrameGpu f{};
  f.world_to_view = camera_.view;
  f.view_to_world = glm::inverse(camera_.view);
  glm::mat4 projection = glm::perspectiveRH_ZO(glm::radians(camera_.fov_y_degrees),
                                               float(e.width) / float(e.height), camera_.near_plane,
                                               camera_.far_plane);
  projection[1][1] *= -1.0f;  // Vulkan's clip space has y down
  f.view_to_clip = projection;
  f.clip_to_view = glm::inverse(projection);
  const std::vector<float> splits = split_depths(e);
  for (size_t i = 0; i < splits.size(); ++i) f.splits[i / 4][int(i % 4)] = splits[i];
  f.background = glm::vec4(settings_.background, 1.0f);
  f.width = e.width;
  f.height = e.height;
  f.layer_count = settings_.layer_count;
  f.volume_count = static_cast<uint32_t>(volume_info_.size());
  f.table_size = slots_for(e);
  f.skip_empty = settings_.skip_empty ? 1u : 0u;
  f.near_depth = camera_.near_plane;
  f.far_depth = camera_.far_plane;
  f.step = settings_.step > 0.0f ? settings_.step : 0.5f * finest_spacing_;
  f.termination_alpha = settings_.termination_alpha;
  f.depth_alpha = settings_.depth_alpha;
  return f;
}

VolumeRenderer::Outputs VolumeRenderer::add_to(graph::Graph& graph) {
  const auto slots = [this](graph::Extent e) { return VkDeviceSize{slots_for(e)} * 8; };
  const ResourceId frame = graph.add_buffer("render.frame", {[](graph::Extent) { return VkDeviceSize{sizeof(gpu::FrameGpu)}; }});
  const ResourceId keys = graph.add_buffer("render.keys", {slots});
  const ResourceId payload = graph.add_buffer("render.payload", {slots});
  const ResourceId max_age = graph.add_buffer("render.max_age", {[](graph::Extent e) {
    return VkDeviceSize{e.width} * e.height * sizeof(uint32_t);
  }});
  const ResourceId counters = graph.add_buffer("render.counters", {[](graph::Extent) {
    return VkDeviceSize{VR_COUNTER_COUNT * sizeof(uint32_t)};
  }});
  Outputs out;
  out.layers = graph.add_image("render.layers", {VK_FORMAT_R16G16B16A16_SFLOAT, {}, settings_.layer_count});
  out.final = graph.add_image("render.final", {VK_FORMAT_R8G8B8A8_UNORM});
  out.depth = graph.add_image("render.depth", {VK_FORMAT_R32_SFLOAT});
  const graph::ImportInfo sampled_image{true, true, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  const graph::ImportInfo filled_buffer{false, true};
  ids_.atlas = graph.import_resource("render.atlas", sampled_image);
  ids_.transfer = graph.import_resource("render.transfer_table", sampled_image);
  ids_.volumes = graph.import_resource("render.volumes", filled_buffer);
  ids_.occupancy = graph.import_resource("render.occupancy", filled_buffer);
  ids_.vertices = graph.import_resource("render.vertices", filled_buffer);
  ids_.indices = graph.import_resource("render.indices", filled_buffer);
  ids_.readback = graph.import_resource("render.counters_readback",
                                        {false, false, VK_IMAGE_LAYOUT_UNDEFINED, Use::host_read});

  graph.add_pass({"render.clear",
                  graph::PassKind::transfer,
                  {{frame, Use::transfer_dst}, {keys, Use::transfer_dst}, {max_age, Use::transfer_dst},
                   {counters, Use::transfer_dst}},
                  [this, frame, keys, max_age, counters](graph::PassContext& pc) {
                    const gpu::FrameGpu data = frame_data(pc.viewport);
                    vkCmdUpdateBuffer(pc.cmd, pc.buffer(frame), 0, sizeof data, &data);
                    vkCmdFillBuffer(pc.cmd, pc.buffer(keys), 0, VK_WHOLE_SIZE, 0);
                    vkCmdFillBuffer(pc.cmd, pc.buffer(max_age), 0, VK_WHOLE_SIZE, 0);
                    vkCmdFillBuffer(pc.cmd, pc.buffer(counters), 0, VK_WHOLE_SIZE, 0);
                  },
                  "render"});
  graph.add_pass({"render.habuffer_build",
                  graph::PassKind::graphics,
                  {{frame, Use::uniform, VR_BINDING_FRAME},
                   {ids_.vertices, Use::storage_read, VR_BINDING_VERTICES},
                   {ids_.indices, Use::storage_read, VR_BINDING_INDICES},
                   {keys, Use::storage_read_write, VR_BINDING_KEYS},
                   {payload, Use::storage_write, VR_BINDING_PAYLOAD},
                   {max_age, Use::storage_read_write, VR_BINDING_MAX_AGE},
                   {counters, Use::storage_read_write, VR_BINDING_COUNTERS}},
                  [this](graph::PassContext& pc) { record_build(pc); },
                  "render"});
  graph.add_pass({"render.resolve",
                  graph::PassKind::compute,
                  {{frame, Use::uniform, VR_BINDING_FRAME},
                   {ids_.volumes, Use::storage_read, VR_BINDING_VOLUMES},
                   {keys, Use::storage_read, VR_BINDING_KEYS},
                   {payload, Use::storage_read, VR_BINDING_PAYLOAD},
                   {max_age, Use::storage_read, VR_BINDING_MAX_AGE},
                   {counters, Use::storage_read_write, VR_BINDING_COUNTERS},
                   {ids_.atlas, Use::sampled, VR_BINDING_ATLAS},
                   {ids_.transfer, Use::sampled, VR_BINDING_TRANSFER},
                   {ids_.occupancy, Use::storage_read, VR_BINDING_OCCUPANCY},
                   {out.layers, Use::storage_write, VR_BINDING_LAYERS},
                   {out.final, Use::storage_write, VR_BINDING_FINAL},
                   {out.depth, Use::storage_write, VR_BINDING_DEPTH}},
                  [this](graph::PassContext& pc) {
                    pc.bind(resolve_);
                    vkCmdDispatch(pc.cmd, group_count(pc.viewport.width, VR_RESOLVE_GROUP),
                                  group_count(pc.viewport.height, VR_RESOLVE_GROUP), 1);
                  },
                  "render"});
  const ResourceId readback = ids_.readback;
  graph.add_pass({"render.counters",
                  graph::PassKind::transfer,
                  {{counters, Use::transfer_src}, {readback, Use::transfer_dst}},
                  [counters, readback](graph::PassContext& pc) {
                    const VkBufferCopy region{0, 0, VR_COUNTER_COUNT * sizeof(uint32_t)};
                    vkCmdCopyBuffer(pc.cmd, pc.buffer(counters), pc.buffer(readback), 1, &region);
                  }});
  return out;
}

void VolumeRenderer::bind(graph::GraphRunner& runner) {
  const graph::Extent e = runner.viewport();
  if (uint64_t{e.width} * e.height > (1u << 24)) {
    throw Error("render: " + std::to_string(e.width) + "x" + std::to_string(e.height) +
                " is more than the HA-Buffer's 16M pixels");
  }
  runner.bind_image(ids_.atlas, atlas_.handle(), atlas_.view(), kAtlasFormat);
  runner.bind_image(ids_.transfer, transfer_table_.handle(), transfer_table_.view(), kTableFormat);
  runner.bind_buffer(ids_.volumes, volumes_.handle());
  runner.bind_buffer(ids_.occupancy, occupancy_.handle());
  runner.bind_buffer(ids_.vertices, vertices_.handle());
  runner.bind_buffer(ids_.indices, indices_.handle());
  runner.bind_buffer(ids_.readback, counters_readback_.handle());
}

void VolumeRenderer::record_build(graph::PassContext& pc) const {
  VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
  rendering.renderArea = {{0, 0}, {pc.viewport.width, pc.viewport.height}};
  rendering.layerCount = 1;
  vkCmdBeginRendering(pc.cmd, &rendering);
  const VkViewport viewport{0.0f, 0.0f, float(pc.viewport.width), float(pc.viewport.height), 0.0f, 1.0f};
  vkCmdSetViewport(pc.cmd, 0, 1, &viewport);
  vkCmdSetScissor(pc.cmd, 0, 1, &rendering.renderArea);
  pc.bind(build_);
  for (uint32_t m = 0; m < mesh_draws_.size(); ++m) {
    const MeshDraw& draw = mesh_draws_[m];
    const gpu::DrawGpu push{draw.transform, draw.color, draw.first_index, m, VR_KIND_MESH, 0};
    build_.push_constants(pc.cmd, push);
    vkCmdDraw(pc.cmd, draw.index_count, 1, 0, 0);
  }
  for (uint32_t v = 0; v < volume_info_.size(); ++v) {
    const gpu::DrawGpu push{volume_info_[v].texture_to_world, glm::vec4(0.0f), 0, v,
                            VR_KIND_VOLUME_FACE, 0};
    build_.push_constants(pc.cmd, push);
    vkCmdDraw(pc.cmd, 36, 1, 0, 0);
  }
  vkCmdEndRendering(pc.cmd);
}

RenderStats VolumeRenderer::collect(graph::GraphRunner& runner) {
  uint32_t c[VR_COUNTER_COUNT];
  std::memcpy(c, counters_readback_.mapped(), sizeof c);
  RenderStats stats;
  stats.overflow = c[VR_COUNTER_OVERFLOW];
  stats.fragments = c[VR_COUNTER_FRAGMENTS];
  stats.resolve_overflow = c[VR_COUNTER_RESOLVE_OVERFLOW];
  stats.samples = c[VR_COUNTER_SAMPLES];
  stats.table_size = slots_for(runner.viewport());
  if (stats.overflow > 0 || stats.fragments > 0.75 * stats.table_size) {
    const double needed = (double(stats.fragments) + stats.overflow) / settings_.load_factor;
    forced_slots_ = static_cast<uint32_t>(std::min(std::max(needed, 2.0 * stats.table_size), 4.0e9));
    runner.reallocate();
  }
  return stats;
}

}  // namespace strata
