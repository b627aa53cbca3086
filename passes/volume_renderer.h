// The renderer: transparent meshes hashed into the HA-Buffer by one thin graphics pass, then one
// compute pass that sorts each pixel's mesh fragments, adds the volumes' boxes by a ray-box test,
// ray-casts the volumes live between them from the volume atlas, and writes one premultiplied image
// per depth layer, the label-free final image and a depth image. docs/ARCHITECTURE.md ("Design
// reasons") says why.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "engine/core/background.h"
#include "engine/gpu/resources.h"
#include "engine/gpu/shader_library.h"
#include "engine/graph/graph_runner.h"
#include "engine/graph/readback.h"
#include "engine/graph/render_graph.h"
#include "engine/scene/io/volume_loader.h"
#include "engine/scene/scene.h"
#include "shared/upscale.h"
#include "shared/volume_render.h"

namespace strata {

struct RenderSettings {
  uint32_t layer_count = 4;   // 1 .. 8
  std::vector<float> splits;  // layer_count - 1 eye depths; empty: even over the scene's depth
  float step = 0.0f;          // world units between samples; 0: half the finest voxel spacing
  bool skip_empty = true;     // empty-space skipping with the per-volume brick grids
  float termination_alpha = 0.99f;
  float depth_alpha = 0.5f;
  // The final image's (render --no-labels): a labelled frame's placement reads that image, so
  // LabelledRenderer leaves it black and puts its own under the labels' composite.
  Background background;
  float expected_depth_complexity = 4.0f;  // HA-Buffer sizing: mesh fragments per pixel expected
  float load_factor = 0.5f;                // ... and the share of slots they should fill
  // Interactive rendering (shared/upscale.h): the graph casts rays into lower-resolution images
  // and upscales them (a graph shape: add_to reads it), and each frame casts every `divisor`-th
  // pixel each way (1: all of them; read when the frame is recorded).
  bool interactive = false;
  uint32_t divisor = 1;
};

// The pixels a frame casts rays for: `viewport` divided by `divisor`, rounded up.
graph::Extent cast_extent(graph::Extent viewport, uint32_t divisor);

// The CPU reference of the upscale's layers: `size` images (layer after layer) from the cast
// pixels `low` (cast_extent(size, divisor) images, layer after layer).
std::vector<glm::vec4> upscale_reference(std::span<const glm::vec4> low, graph::Extent size,
                                         uint32_t divisor, uint32_t layer_count);

// What the GPU counted during the last completed frame.
struct RenderStats {
  uint32_t overflow = 0;          // fragments that found no slot (the table grows)
  uint32_t fragments = 0;         // mesh fragments in the table
  uint32_t resolve_overflow = 0;  // mesh fragments beyond the resolve's per-pixel capacity
  uint64_t samples = 0;           // ray positions sampled
  uint64_t shaded = 0;            // volume samples shaded
  uint64_t fetches = 0;           // atlas texture fetches (trilinear, 4 x 16-bit)
  uint32_t table_size = 0;        // slots during that frame
  double load_factor() const { return table_size ? double(fragments) / table_size : 0.0; }
};

// Everything the renderer derives from a scene on the CPU, once: what the GPU receives and what
// the CPU reference renderer (volume_render_reference.h) samples.
struct RenderInputs {
  glm::uvec3 atlas_dims{1};
  std::vector<int16_t> atlas;  // per texel: gradient xyz (per voxel) and normalised intensity,
                               // 16-bit SNORM; volumes stacked along z
  std::vector<gpu::VolumeGpu> volumes;
  std::vector<TransferFunction> transfer_functions;  // one per volume
  std::vector<glm::vec4> transfer_table;             // VR_TF_SIZE x max(1, volumes); alpha per the
                                                     // volume's reference distance (atlas_scale.w)
  std::vector<glm::vec2> brick_ranges;  // per brick: min and max normalised value (dilated)
  std::vector<uint32_t> occupancy;      // per brick: 1 if the transfer function can show it
  struct MeshDraw {
    uint32_t first_index, index_count;
    glm::vec4 color;
    glm::mat4 transform;
  };
  std::vector<glm::vec4> vertices;  // model-space position, normal pairs
  std::vector<uint32_t> indices;
  std::vector<MeshDraw> meshes;
  glm::vec3 scene_min{0.0f}, scene_max{0.0f};
  float finest_spacing = 1.0f;

  // Rebuilds the transfer table and the occupancy from transfer_functions.
  void update_transfer();
};

// What the renderer can place on this device, as limits for reading volumes (load_scene checks
// each volume's header against them before reading a voxel): the atlas's side and its size in
// one allocation (VolumeLimits::device_voxel_bytes a voxel).
VolumeLimits device_volume_limits(const Context& ctx);

// The atlas, transfer table, occupancy and mesh arrays of a scene; an Error naming the limit when
// the atlas has a side over max_image_dimension_3d or more than max_bytes.
RenderInputs prepare_render_inputs(const Scene& scene, uint32_t max_image_dimension_3d,
                                   uint64_t max_bytes = UINT64_MAX);

// The transfer table as the resolve reads it: each entry's alpha corrected for samples `step`
// world units apart (corrected_alpha with the volume's reference distance), once per frame.
std::vector<glm::vec4> corrected_transfer(const RenderInputs& inputs, float step);

// The layer boundaries (eye depths): settings.splits, or even over the scene's depth range.
std::vector<float> split_depths(const RenderInputs& inputs, const Camera& camera,
                                const RenderSettings& settings);

gpu::FrameGpu frame_data(const RenderInputs& inputs, const Camera& camera,
                         const RenderSettings& settings, graph::Extent viewport,
                         uint32_t table_size);

class VolumeRenderer {
 public:
  struct Outputs {
    graph::ResourceId layers;  // rgba16f array, one layer per depth layer, premultiplied
    graph::ResourceId final;   // rgba8, layers over the background
    graph::ResourceId depth;   // r32f eye depth, 0 where nothing is opaque enough
    graph::ResourceId frame;   // FrameGpu (uniform): camera, layers, the HA-Buffer's size
    graph::ResourceId keys;    // the HA-Buffer: uint64_t per slot (debug views, picking)
    // What the resolve reads besides (picking walks rays again): the HA-Buffer's payloads, the
    // volumes' records (uniform), the atlas (sampled), the transfer table and the occupancy.
    graph::ResourceId payload, volumes, atlas, transfer, occupancy;
  };

  // Uploads the scene once: volumes into the atlas, transfer functions into their table, the
  // empty-space grids, meshes into one vertex and one index buffer.
  VolumeRenderer(Context& ctx, const Scene& scene, RenderSettings settings = {});

  // Adds the renderer's passes; the uploaded scene and the counter readback are imported with
  // their handles.
  Outputs add_to(graph::Graph& graph);

  void set_camera(const Camera& camera) { camera_ = camera; }
  RenderSettings& settings() { return settings_; }
  // Rebuilds volume v's empty-space grid and its transfer-function row (the frames recorded
  // from now on use them): the grid copied by `in_frame` (GraphRunner::upload_in_next_frame: no
  // wait), else at once (waits: no frame may be in flight).
  void set_transfer_function(uint32_t volume, const TransferFunction& tf,
                             Uploads* in_frame = nullptr);
  // Volume v's cut-aways (`v.cut`, world planes) for the frames recorded from now on: copied by
  // `in_frame` (GraphRunner::upload_in_next_frame: no wait), else at once (waits: no frame may
  // be in flight).
  void set_cut(uint32_t volume, const Volume& v, Uploads* in_frame = nullptr);
  // What the driver reports about the resolve's compiled shader (registers, ...), if anything.
  std::vector<PipelineReport> pipeline_statistics() const;

  // Forces the HA-Buffer's slot count (tests force overflow with a tiny table); collect() grows it.
  void set_table_size(uint32_t slots);
  uint32_t table_slots(graph::Extent viewport) const { return slots_for(viewport); }

  // Reads the counters of the last completed frame; grows the table (and reallocates the
  // runner's transients) when fragments overflowed or it is fuller than 0.75. Returns the stats.
  RenderStats collect(graph::GraphRunner& runner);
  // An offline image waits for a clean frame: runs `runner` and collect()s until no fragment
  // overflowed the HA-Buffer (it grows after each overflow), four runs at most. `on_overflow`
  // hears of each overflow, after the table grew. Returns the last run's stats.
  RenderStats run_until_no_overflow(
      graph::GraphRunner& runner, const std::function<void(const RenderStats&)>& on_overflow = {});

  const RenderInputs& inputs() const { return inputs_; }
  // The counters' readback, one per frame in flight (collect() reads its current slot).
  graph::Readback& readback() { return counters_readback_; }
  const Camera& camera() const { return camera_; }

 private:
  uint32_t slots_for(graph::Extent viewport) const;
  void upload_transfer(Uploads* in_frame = nullptr);
  void record_build(graph::PassContext& pc) const;

  Context& ctx_;
  RenderSettings settings_;
  Camera camera_;
  RenderInputs inputs_;
  uint32_t group_order_;  // VR_ORDER_*: by the device's kind

  Image atlas_;
  Buffer volumes_, occupancy_, vertices_, indices_;
  graph::Readback counters_readback_;
  uint32_t forced_slots_ = 0;  // 0: sized from the viewport
  // Interactive rendering at rest: the cast images of the last frame are kept, and a frame that
  // would cast the same rays (the same frame data, transfer functions and images) casts none.
  struct Cast {
    gpu::FrameGpu frame{};
    uint64_t transfer = 0, allocation = 0;
  };
  std::optional<Cast> last_cast_;
  uint64_t transfer_version_ = 0;
  bool reuse_cast_ = false;  // the frame being recorded casts no rays
  bool same_cast(const Cast& c) const;

  GraphicsPipeline build_;
  ComputePipeline resolve_;
  ComputePipeline upscale_;
  // add_to's pieces: the frame's buffers, the images (".cast" ones kept for interactive
  // rendering), the uploaded scene imported, and the passes.
  struct Transients {
    graph::ResourceId frame, keys, payload, transfer, counters;
  };
  Transients add_transients(graph::Graph& graph) const;
  Outputs add_images(graph::Graph& graph, const std::string& suffix, bool keep) const;
  void import_scene(graph::Graph& graph);
  void add_clear_pass(graph::Graph& graph, const Transients& t);
  void add_cast_passes(graph::Graph& graph, const Transients& t, const Outputs& cast);
  void add_upscale(graph::Graph& graph, const Outputs& cast, const Outputs& out);
  graph::Extent cast_size(graph::Extent viewport) const;
  struct Ids {
    graph::ResourceId atlas, volumes, occupancy, vertices, indices, readback;
  } ids_{};
};

}  // namespace strata
