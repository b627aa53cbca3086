// The scene model: what strata renders and labels. Plain data; loaders fill it (scene_loader.h),
// the renderer and placement read it. Units: world space is millimetres for medical data (the
// thesis's own scenes use their own unit), label sizes are pixels.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "engine/core/png.h"
#include "engine/scene/camera.h"

namespace strata {

enum class VoxelType { uint8, int16, uint16, float32 };

const char* to_string(VoxelType type);
size_t voxel_size(VoxelType type);

struct Volume {
  std::string name;
  std::filesystem::path source;
  VoxelType type = VoxelType::uint8;
  glm::uvec3 dims{0};
  glm::vec3 spacing{1.0f};        // mm between voxel centres along i, j, k
  glm::vec3 origin{0.0f};         // patient/world position of voxel (0, 0, 0)
  glm::mat3 direction{1.0f};      // columns: unit directions of i, j, k in patient space
  glm::mat4 transform{1.0f};      // placement in the scene, applied after index_to_patient()
  std::vector<std::byte> voxels;  // i fastest, then j, then k; rescale slope/intercept applied
  glm::vec2 value_range{0.0f};    // min and max voxel value (transfer functions normalise by it)
  int transfer_function = -1;     // index into Scene::transfer_functions, -1 for none
  // How its transfer function was chosen, which the scene writer writes back: a preset by name
  // (transfer_function_presets.h) or a grey window (center, width in its values); neither for a
  // function of its own.
  std::string preset;
  std::optional<glm::vec2> window;
  bool look_edited = false;  // changed since read (the viewer): saved from the model, not the file
  // Cut-aways: planes in world space (xyz the normal, w the offset); a point p of the volume is
  // shown where dot(xyz, p) + w >= 0 for every plane. A crop box is six of them
  // (crop_planes); at most kMaxCutPlanes.
  std::vector<glm::vec4> cut;
  // The SeriesInstanceUID it was read from, where its DICOM folder holds several series (the
  // scene writer keeps it, so the same series opens again).
  std::string series;

  size_t voxel_count() const { return size_t{dims.x} * dims.y * dims.z; }
  size_t byte_size() const { return voxels.size(); }
  // Voxel index (i, j, k) to patient space: origin + direction * (spacing * index).
  glm::mat4 index_to_patient() const;
  glm::mat4 index_to_world() const { return transform * index_to_patient(); }
  // World-space axis-aligned bounds of the voxel centres' box.
  std::pair<glm::vec3, glm::vec3> world_bounds() const;
  // The value of voxel (i, j, k) as float, whatever the type.
  float value(uint32_t i, uint32_t j, uint32_t k) const;
};

inline constexpr size_t kMaxCutPlanes = 12;  // VR_MAX_CUT_PLANES
inline constexpr size_t kMaxVolumes = 8;     // VR_MAX_VOLUMES: volumes one picture renders

// The six planes that keep the box [lo, hi] (world space).
std::vector<glm::vec4> crop_planes(glm::vec3 lo, glm::vec3 hi);
// The plane through `point` that keeps the side `normal` points to.
glm::vec4 clip_plane(glm::vec3 point, glm::vec3 normal);
// Whether `normal` gives a clipping plane a direction: longer than 1e-6 (--clip and the
// viewer's planes, one rule).
inline bool clip_normal_usable(glm::vec3 normal) {
  return glm::length(normal) > 1e-6f;
}
// Whether a volume's cut-aways remove world point p (false for a volume without any).
bool cut_away(const Volume& volume, glm::vec3 p);

// Piecewise-linear RGBA over intensity normalised to [0, 1] by the volume's value range.
struct TransferFunction {
  struct Stop {
    float position = 0.0f;  // 0..1 of the volume's value range (or in `units`)
    glm::vec4 color{0.0f};  // straight (not premultiplied) RGBA, 0..1
  };
  std::string name;
  std::filesystem::path source;
  std::vector<Stop> stops;  // sorted by position
  // "": positions are 0..1 of the volume's value range; "HU" or "raw": they are the volume's own
  // values (Hounsfield units for CT, after the file's rescale), the same on any scan.
  // complete_scene makes each volume a 0..1 copy for its range (in_value_range).
  std::string units;
  // Colour at t in [0, 1]: clamped to the first and last stop outside them.
  glm::vec4 sample(float t) const;
};

struct Mesh {
  std::string name;
  std::filesystem::path source;
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;           // one per position
  std::vector<uint32_t> indices;            // triangles
  glm::vec4 color{0.8f, 0.8f, 0.8f, 1.0f};  // straight RGBA; alpha < 1 is transparent
  glm::mat4 transform{1.0f};

  size_t triangle_count() const { return indices.size() / 3; }
};

// A picture shown in a label's box above or left of its text (the thesis's future work: labels
// with attached photographs). The box grows to hold it.
struct LabelImage {
  enum class Side { above, left };
  std::filesystem::path file;
  Rgba8Image pixels;     // straight alpha, as read
  float height = 64.0f;  // pixels at label scale 1; the width keeps the picture's aspect
  Side side = Side::above;
};

struct Label {
  int id = 0;
  std::string text;
  glm::vec3 anchor{0.0f};  // world space
  glm::vec2 size{0.0f};    // pixels; zero means "from the text" (decided when drawing)
  std::optional<LabelImage> image;
  // Higher is placed first, so when labels must be hidden (hard constraints, crowding) a lower
  // priority goes first; equal priorities keep the insertion order's own rule.
  float priority = 0.0f;
  // RGB 0..1 of what it names, where that has one (a segmentation region's colour): a legend's
  // swatch. Not in scene files.
  std::optional<glm::vec3> colour;
};

// One label written to a label file and read back: the same text and anchor (a label file
// gives its labels ids of its own).
inline bool same_label(const Label& a, const Label& b) {
  return a.text == b.text && a.anchor == b.anchor;
}

// The thesis program's final paper settings (eq. 3.1; docs/ARCHITECTURE.md, "Thesis equations
// in the code").
struct CostWeights {
  float label_shadow = 1e5f;
  float anchor_constraint = 1e6f;
  float connector_shadow = 100.0f;
  float integral_costs = 20.0f;
  float distance_to_anchor = 0.015f;
  float connector_direction = 1.0f;
  float previous_position = 0.0f;
  // Not the thesis's: the tidy-up after the placement (shaders/shared/tidy.h)
  // counts this per pair of crossing leaders and per leader through another label's box.
  float leader_crossing = 1000.0f;
  // Not the thesis's: a box the layers in front of the label's would hide (less than
  // LEGIBLE_SHARE of it visible, shaders/shared/placement.h) costs this; hard mode forbids it.
  float illegible = 1000.0f;
};

// Depth layers a frame can have (VR_MAX_LAYERS in shaders/shared/volume_render.h, asserted equal
// in passes/volume_renderer.cpp): the scene side checks settings against it without the shaders.
inline constexpr int kMaxLayers = 8;
// Labels a scene can have (LABEL_MAX in shaders/shared/labels.h, asserted equal in
// passes/placement.cpp): the constraint regions placement keeps grow with its square (4096 labels:
// 1.4 GiB, docs/scene-format.md).
inline constexpr int kMaxLabels = 4096;

struct SceneSettings {
  int layer_count = 4;  // 1 to kMaxLayers
  CostWeights weights;
  // Ghosting: how far the layers in front of a rear label's anchor open (0: off, to 1; on by
  // default), and the lens's radius, a share of the picture's shorter side (kGhostRadiusMin to
  // kGhostRadiusMax).
  float ghost = 1.0f;
  float ghost_radius = 0.1f;
};
inline constexpr float kGhostRadiusMin = 0.005f;
inline constexpr float kGhostRadiusMax = 0.5f;

// An atlas the scene read: its label volume and every region its names file lists, so that a
// point can be named by the region it lies in (atlas_region_at in engine/scene/atlas.h).
struct SceneAtlas {
  Volume labels;
  std::map<int, std::string> names;  // region index -> name as in the file ("Thalamus_R")
};

// What a scene's "segmentations" entry or --segmentation asks for.
// (engine/scene/segmentation.h reads it.)
struct SegmentationEntry {
  std::filesystem::path file;
  std::optional<std::filesystem::path> names;  // a names table replacing the file's names
  std::vector<std::string> regions;            // by name ('_' or ' ' alike); empty: all
  bool labels = true, masks = false, surfaces = false;
};

struct Scene {
  std::filesystem::path source;
  std::vector<Volume> volumes;
  std::vector<TransferFunction> transfer_functions;
  std::vector<Mesh> meshes;
  std::vector<Label> labels;
  // The last this many labels came from a label file opened with the scene (--labels), not
  // from the scene's own file: the viewer saves them with the labels placed in it.
  size_t added_labels = 0;
  Camera camera;
  bool has_camera = false;  // the file gave the camera's view (else complete_scene fits one)
  std::vector<CameraPose> camera_positions;  // named poses ("--camera NAME")
  std::vector<SceneAtlas> atlases;
  // The segmentations read (their masks and surfaces have no file of their own: the scene
  // writer writes the entry that makes them).
  std::vector<SegmentationEntry> segmentations;
  SceneSettings settings;
  std::vector<std::string> warnings;  // e.g. a referenced file that does not exist
  // The strata scene JSON text `source` held when read (empty for other sources): save_scene_json
  // writes its entries back as they were, since the model holds what an entry made (an atlas's
  // surfaces, a label file's labels), not the entry.
  std::string source_json;
};

// The scene's position `name`, or, where it has none of that name, the standard view the name
// means (standard_view_name: `front`, `oblique`, `ars`); nullptr if neither.
const CameraPose* find_position(const Scene& scene, std::string_view name);

// The scene's camera, or its named position `name` (find_position; an Error listing the names
// if there is none).
Camera camera_for(const Scene& scene, const std::string& name);

// For each point (world), whether it lies in the volume's box (its voxels', in its own index
// space: oblique volumes too).
std::vector<bool> inside_volume(const Volume& volume, const std::vector<glm::vec3>& points);
// For each anchor, whether the volumes around it all cut it away: some volume's box (its voxel
// centres') holds it and cuts it, none that holds it keeps it.
std::vector<bool> anchors_cut_away(const Scene& scene, const std::vector<glm::vec3>& anchors);

}  // namespace strata
