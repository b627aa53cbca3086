#include "engine/scene/io/scene_loader.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "engine/core/image.h"
#include "engine/core/json_field.h"
#include "engine/core/text_file.h"
#include "engine/scene/atlas.h"
#include "engine/scene/fitted_camera.h"
#include "engine/scene/io/label_file_loader.h"
#include "engine/scene/io/mesh_loader.h"
#include "engine/scene/io/transfer_function_loader.h"
#include "engine/scene/io/volume_loader.h"
#include "engine/scene/scene_bounds.h"
#include "engine/scene/segmentation.h"
#include "engine/scene/transfer_function_presets.h"
#include "engine/scene/value_limits.h"

namespace strata {

namespace {

using nlohmann::json;

using Field = JsonField;

void check_keys(const json& object, const Field& field, std::initializer_list<const char*> keys) {
  if (!object.is_object()) field.fail("expected an object");
  for (const auto& [key, value] : object.items()) {
    if (std::find(keys.begin(), keys.end(), key) != keys.end()) continue;
    std::string expected;
    for (const char* k : keys) expected += (expected.empty() ? "" : ", ") + std::string(k);
    field.fail("unknown key '" + key + "' (expected " + expected + ")");
  }
}

// A label file's labels, their ids after the scene's; refused, naming the file, where together
// they pass kMaxLabels.
std::vector<Label> labels_to_add(const std::filesystem::path& path, const Scene& scene) {
  std::vector<Label> labels = load_label_file(path, next_label_id(scene));
  if (const auto problem = label_limit_problem(labels.size(), scene.labels.size()))
    throw Error(path.string() + ": " + *problem);
  return labels;
}

float number(const json& value, const Field& field) {
  if (!value.is_number() || !std::isfinite(value.get<double>())) field.fail("expected a number");
  // (1e39 is a finite double but no float)
  if (!std::isfinite(value.get<float>())) field.fail("expected a number of at most 3.4e38");
  return value.get<float>();
}

float non_negative(const json& value, const Field& field) {
  const float v = number(value, field);
  if (v < 0.0f) field.fail("expected a number >= 0, got " + value.dump());
  return v;
}

int integer(const json& value, const Field& field) {
  if (!value.is_number_integer()) field.fail("expected an integer");
  const bool fits = value.is_number_unsigned()
                        ? value.get<uint64_t>() <= uint64_t(std::numeric_limits<int>::max())
                        : value.get<int64_t>() >= std::numeric_limits<int>::min() &&
                              value.get<int64_t>() <= std::numeric_limits<int>::max();
  if (!fits) field.fail("expected an integer from -2147483648 to 2147483647, got " + value.dump());
  return value.get<int>();
}

std::string string(const json& value, const Field& field) {
  if (!value.is_string()) field.fail("expected a string");
  return value.get<std::string>();
}

std::vector<float> numbers(const json& value, const Field& field, size_t count) {
  const std::vector<double> read = json_numbers(value, field, count);
  for (double d : read) {
    if (!std::isfinite(float(d))) field.fail("expected numbers of at most 3.4e38");
  }
  return {read.begin(), read.end()};
}

glm::vec3 vec3(const json& value, const Field& field) {
  const auto v = numbers(value, field, 3);
  return {v[0], v[1], v[2]};
}

glm::vec4 color(const json& value, const Field& field) {
  const auto v = numbers(value, field, 4);
  for (float c : v) {
    if (c < 0.0f || c > 1.0f) field.fail("expected 4 numbers [r, g, b, a] in [0, 1]");
  }
  return {v[0], v[1], v[2], v[3]};
}

// Scene files write matrices row by row, as one reads them; glm indexes [column][row].
glm::mat4 matrix(const json& value, const Field& field) {
  const auto v = numbers(value, field, 16);
  glm::mat4 m(1.0f);
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) m[col][row] = v[size_t(row * 4 + col)];
  }
  // A transform or view of zeros (or of infinities) would give a black picture without a word.
  const float determinant = glm::determinant(m);
  if (!std::isfinite(determinant) || std::abs(determinant) < 1e-12f)
    field.fail("the matrix is singular (determinant " + json(determinant).dump() + ")");
  return m;
}

// "view": [16 numbers] or "eye"/"target"/"up"; nullopt when the object gives neither.
std::optional<glm::mat4> view_matrix(const json& object, const Field& field) {
  const json* view = optional(object, "view");
  const json* eye = optional(object, "eye");
  if (view && (eye || optional(object, "target") || optional(object, "up"))) {
    field.fail("give either 'view' or 'eye'/'target'/'up', not both");
  }
  if (view) {
    const glm::mat4 m = matrix(*view, field / "view");
    const glm::dvec3 from(glm::inverse(glm::dmat4(m))[3]);
    if (const auto problem =
            value_limits::position_problem("the eye", from, value_limits::kMaxSceneCoordinateMm))
      (field / "view").fail(*problem);
    return m;
  }
  if (!eye) {
    if (optional(object, "target") || optional(object, "up")) field.fail("missing key 'eye'");
    return std::nullopt;
  }
  const glm::vec3 from = vec3(*eye, field / "eye");
  if (const auto problem = value_limits::position_problem("the eye", glm::dvec3(from),
                                                          value_limits::kMaxSceneCoordinateMm))
    (field / "eye").fail(*problem);
  const glm::vec3 to = vec3(required(object, field, "target"), field / "target");
  const json* up_json = optional(object, "up");
  const glm::vec3 up = up_json ? vec3(*up_json, field / "up") : glm::vec3(0.0f, 1.0f, 0.0f);
  if (glm::length(glm::cross(to - from, up)) <= 0.0f) {
    field.fail("eye and target coincide, or 'up' is parallel to the view direction");
  }
  return glm::lookAt(from, to, up);
}

// The name before the first dot: "ch2.nii.gz" is "ch2".
std::string base_name(const std::filesystem::path& path) {
  const std::string name = path.filename().string();
  return name.substr(0, name.find('.'));
}

class SceneReader {
 public:
  SceneReader(const std::filesystem::path& path, const VolumeLimits& limits)
      : file_(path.string()), folder_(path.parent_path()), limits_(limits) {
    scene_.source = path;
  }

  Scene read(const json& root);

 private:
  std::filesystem::path resolve(const json& value, const Field& field) const {
    const std::filesystem::path relative(string(value, field));
    return (relative.is_absolute() ? relative : folder_ / relative).lexically_normal();
  }
  int transfer_function(const json& value, const Field& field);
  void volume(const json& object, const Field& field);
  void mesh(const json& object, const Field& field);
  void atlas(const json& object, const Field& field);
  void segmentation(const json& object, const Field& field);
  std::vector<AtlasRegion> atlas_regions(const json& object, const Field& field);
  void label(const json& object, const Field& field);
  std::optional<LabelImage> label_image(const json& object, const Field& field);
  void camera(const json& object, const Field& field);
  void settings(const json& object, const Field& field);

  std::string file_;
  std::filesystem::path folder_;
  VolumeLimits limits_;
  Scene scene_;
  std::map<std::filesystem::path, int> transfer_function_by_file_;
};

// A path (loaded once however many volumes share it) or an inline transfer-function object.
int SceneReader::transfer_function(const json& value, const Field& field) {
  if (value.is_object()) {
    TransferFunction tf = transfer_function_from_json(value, file_, field.path);
    if (tf.name.empty()) tf.name = field.path;
    scene_.transfer_functions.push_back(std::move(tf));
    return int(scene_.transfer_functions.size()) - 1;
  }
  if (!value.is_string()) field.fail("expected a file name or a transfer-function object");
  const std::filesystem::path path = resolve(value, field).lexically_normal();
  const auto known = transfer_function_by_file_.find(path);
  if (known != transfer_function_by_file_.end()) return known->second;
  scene_.transfer_functions.push_back(field.wrap([&] { return load_transfer_function(path); }));
  const int index = int(scene_.transfer_functions.size()) - 1;
  transfer_function_by_file_[path] = index;
  return index;
}

// A volume's cut-aways: "crop" [x0, y0, z0, x1, y1, z1] (world, lo < hi) and "clip", planes
// {"point": [x, y, z], "normal": [x, y, z]} that keep the side the normal points to.
std::vector<glm::vec4> cut_planes(const json& object, const Field& field) {
  std::vector<glm::vec4> planes;
  if (const json* crop = optional(object, "crop")) {
    const std::vector<float> v = numbers(*crop, field / "crop", 6);
    const glm::vec3 lo(v[0], v[1], v[2]), hi(v[3], v[4], v[5]);
    if (!glm::all(glm::lessThan(lo, hi)))
      (field / "crop").fail("expected [x0, y0, z0, x1, y1, z1] with x0 < x1, y0 < y1, z0 < z1");
    planes = crop_planes(lo, hi);
  }
  if (const json* clip = optional(object, "clip")) {
    const Field clips = field / "clip";
    if (!clip->is_array()) clips.fail("expected an array of planes {\"point\", \"normal\"}");
    for (size_t i = 0; i < clip->size(); ++i) {
      const Field plane = clips[i];
      if (!(*clip)[i].is_object())
        plane.fail("expected {\"point\": [x, y, z], \"normal\": [x, y, z]}");
      check_keys((*clip)[i], plane, {"point", "normal"});
      const glm::vec3 point = vec3(required((*clip)[i], plane, "point"), plane / "point");
      const glm::vec3 normal = vec3(required((*clip)[i], plane, "normal"), plane / "normal");
      if (!(glm::length(normal) > 1e-6f)) (plane / "normal").fail("expected a non-zero normal");
      planes.push_back(clip_plane(point, normal));
    }
  }
  if (planes.size() > kMaxCutPlanes)
    field.fail(std::to_string(planes.size()) + " cut-away planes (a crop box is six): at most " +
               std::to_string(kMaxCutPlanes));
  return planes;
}

// A volume's "preset": one of transfer_function_presets(), not beside a transfer_function ("" for
// none; complete_scene makes it for the volume's values).
std::string volume_preset(const json& object, const Field& field) {
  const json* preset = optional(object, "preset");
  if (!preset) return "";
  const Field at = field / "preset";
  if (optional(object, "transfer_function"))
    at.fail("give one of transfer_function, preset and window");
  const std::string name = string(*preset, at);
  std::string names;
  for (const TransferFunctionPreset& p : transfer_function_presets()) {
    if (name == p.name) return name;
    names += std::string(names.empty() ? "" : ", ") + p.name;
  }
  at.fail("no preset '" + name + "' (" + names + ")");
}

// Every field is checked before the (slow) file is read, so a typo is reported at once.
void SceneReader::volume(const json& object, const Field& field) {
  check_keys(object, field,
             {"name", "file", "frame", "series", "transfer_function", "preset", "window", "crop",
              "clip", "transform"});
  const std::filesystem::path path = resolve(required(object, field, "file"), field / "file");
  VolumeReadOptions options{.limits = limits_};
  if (const json* frame = optional(object, "frame")) {
    options.frame = integer(*frame, field / "frame");
    if (*options.frame < 0) (field / "frame").fail("expected an integer >= 0");
  }
  if (const json* series = optional(object, "series")) {
    options.series = string(*series, field / "series");
    if (options.series.empty()) (field / "series").fail("expected a SeriesNumber or UID");
  }
  const json* name = optional(object, "name");
  const std::string volume_name = name ? string(*name, field / "name") : base_name(path);
  const json* transform = optional(object, "transform");
  const glm::mat4 placement = transform ? matrix(*transform, field / "transform") : glm::mat4(1.0f);
  const std::string preset = volume_preset(object, field);
  const json* tf = optional(object, "transfer_function");
  int tf_index = tf ? transfer_function(*tf, field / "transfer_function") : -1;
  std::optional<glm::vec2> window;
  if (const json* w = optional(object, "window")) {
    if (tf || !preset.empty())
      (field / "window").fail("give one of transfer_function, preset and window");
    const std::vector<float> v = numbers(*w, field / "window", 2);
    if (!(std::abs(v[0]) <= 1e9f && v[1] > 0.0f && v[1] <= 1e9f))
      (field / "window").fail("expected [center, width] in the volume's values, width > 0");
    window = glm::vec2(v[0], v[1]);
  }
  const std::vector<glm::vec4> cut = cut_planes(object, field);
  Volume volume =
      (field / "file").wrap([&] { return load_volume(path, options, scene_.warnings); });
  volume.cut = cut;
  volume.name = volume_name;
  volume.transform = placement;
  volume.transfer_function = tf_index;
  volume.preset = preset;
  volume.window = window;
  scene_.volumes.push_back(std::move(volume));
}

void SceneReader::mesh(const json& object, const Field& field) {
  check_keys(object, field, {"file", "color", "transform"});
  const std::filesystem::path path = resolve(required(object, field, "file"), field / "file");
  const json* color_json = optional(object, "color");
  const json* transform_json = optional(object, "transform");
  const glm::vec4 override_color = color_json ? color(*color_json, field / "color") : glm::vec4(0);
  const glm::mat4 transform =
      transform_json ? matrix(*transform_json, field / "transform") : glm::mat4(1.0f);
  std::vector<Mesh> meshes = (field / "file").wrap([&] { return load_meshes(path); });
  for (Mesh& mesh : meshes) {
    if (color_json) mesh.color = override_color;
    mesh.transform = transform;
    scene_.meshes.push_back(std::move(mesh));
  }
}

// "all" (the names file's order) or a list of names, each of which must be in the names file.
std::vector<AtlasRegion> SceneReader::atlas_regions(const json& object, const Field& field) {
  const std::filesystem::path names_path =
      resolve(required(object, field, "names"), field / "names");
  std::vector<AtlasRegion> all =
      (field / "names").wrap([&] { return load_atlas_names(names_path); });
  const json& wanted = required(object, field, "regions");
  const Field regions_field = field / "regions";
  if (wanted == "all") return all;
  if (!wanted.is_array()) regions_field.fail("expected \"all\" or an array of region names");
  std::vector<AtlasRegion> chosen;
  for (size_t i = 0; i < wanted.size(); ++i) {
    const std::string name = string(wanted[i], regions_field[i]);
    const auto it =
        std::find_if(all.begin(), all.end(), [&](const auto& r) { return r.name == name; });
    if (it == all.end())
      regions_field[i].fail("no region '" + name + "' in " + names_path.string());
    chosen.push_back(*it);
  }
  return chosen;
}

// "make": any of "labels", "masks", "surfaces"; ["labels"] when absent.
std::set<std::string> atlas_products(const json& object, const Field& field) {
  const json* make = optional(object, "make");
  if (!make) return {"labels"};
  if (!make->is_array()) field.fail("expected an array of \"labels\", \"masks\", \"surfaces\"");
  std::set<std::string> products;
  for (size_t i = 0; i < make->size(); ++i) {
    const std::string what = string((*make)[i], field[i]);
    if (what != "labels" && what != "masks" && what != "surfaces") {
      field[i].fail("'" + what + "' is not one of labels, masks, surfaces");
    }
    products.insert(what);
  }
  return products;
}

void SceneReader::atlas(const json& object, const Field& field) {
  check_keys(
      object, field,
      {"labels", "names", "regions", "limit", "make", "surface_color", "mask_transfer_function"});
  const std::set<std::string> make = atlas_products(object, field / "make");
  const json* limit_json = optional(object, "limit");
  const int limit = limit_json ? integer(*limit_json, field / "limit") : -1;
  if (limit_json && limit < 1) (field / "limit").fail("expected an integer >= 1");
  const json* surface_color = optional(object, "surface_color");
  const glm::vec4 surface = surface_color ? color(*surface_color, field / "surface_color")
                                          : glm::vec4(0.9f, 0.75f, 0.6f, 0.5f);
  const json* mask_tf_json = optional(object, "mask_transfer_function");
  int mask_tf =
      mask_tf_json ? transfer_function(*mask_tf_json, field / "mask_transfer_function") : -1;
  if (make.count("masks") && mask_tf < 0) {
    scene_.transfer_functions.push_back(mask_transfer_function("atlas mask", surface));
    mask_tf = int(scene_.transfer_functions.size()) - 1;
  }

  const std::vector<AtlasRegion> regions = atlas_regions(object, field);
  const std::filesystem::path labels_path =
      resolve(required(object, field, "labels"), field / "labels");
  const Volume labels = (field / "labels").wrap([&] {
    return load_volume(labels_path, {.limits = limits_}, scene_.warnings);
  });
  SceneAtlas named{labels, {}};
  for (const AtlasRegion& r : (field / "names").wrap([&] {
         return load_atlas_names(resolve(required(object, field, "names"), field / "names"));
       })) {
    named.names[r.index] = r.name;
  }
  scene_.atlases.push_back(std::move(named));
  // atlas_labels skips regions without voxels, so its result says which regions "limit" counts.
  const std::vector<Label> centroids = atlas_labels(labels, regions);
  int kept = 0;
  for (const AtlasRegion& region : regions) {
    if (kept == limit) break;
    const auto it = std::find_if(centroids.begin(), centroids.end(),
                                 [&](const Label& l) { return l.id == region.index; });
    if (it == centroids.end()) continue;
    ++kept;
    if (make.count("labels")) scene_.labels.push_back(*it);
    if (make.count("masks")) {
      scene_.volumes.push_back(atlas_mask(labels, region));
      scene_.volumes.back().name = region.name;
      scene_.volumes.back().transfer_function = mask_tf;
    }
    if (make.count("surfaces")) {
      scene_.meshes.push_back(atlas_surface(labels, region));
      scene_.meshes.back().name = region.name;
      scene_.meshes.back().color = surface;
    }
  }
}

// {"file", "names", "regions": "all" | [names], "make": [...]} (segmentation.h).
void SceneReader::segmentation(const json& object, const Field& field) {
  check_keys(object, field, {"file", "names", "regions", "make"});
  SegmentationEntry entry;
  entry.file = resolve(required(object, field, "file"), field / "file");
  if (const json* names = optional(object, "names")) entry.names = resolve(*names, field / "names");
  if (const json* regions = optional(object, "regions"); regions && *regions != "all") {
    if (!regions->is_array())
      (field / "regions").fail("expected \"all\" or an array of region names");
    for (size_t i = 0; i < regions->size(); ++i)
      entry.regions.push_back(string((*regions)[i], (field / "regions")[i]));
  }
  const std::set<std::string> make = atlas_products(object, field / "make");
  entry.labels = make.count("labels") > 0;
  entry.masks = make.count("masks") > 0;
  entry.surfaces = make.count("surfaces") > 0;
  (field / "file").wrap([&] { add_segmentation(scene_, entry, {.limits = limits_}); });
}

// "image" with its optional "image_height" and "image_side"; the picture is read here, so a bad
// file is reported as the label's field.
std::optional<LabelImage> SceneReader::label_image(const json& object, const Field& field) {
  const json* file = optional(object, "image");
  const json* height = optional(object, "image_height");
  const json* side = optional(object, "image_side");
  if (!file) {
    if (height || side) field.fail("'image_height' and 'image_side' need an 'image'");
    return std::nullopt;
  }
  LabelImage image;
  image.file = resolve(*file, field / "image");
  if (height) {
    image.height = number(*height, field / "image_height");
    if (!(image.height >= 1.0f && image.height <= 1024.0f))
      (field / "image_height").fail("expected pixels from 1 to 1024");
  }
  if (side) {
    const std::string name = string(*side, field / "image_side");
    if (name != "above" && name != "left")
      (field / "image_side").fail("'" + name + "' is not one of above, left");
    image.side = name == "left" ? LabelImage::Side::left : LabelImage::Side::above;
  }
  image.pixels = (field / "image").wrap([&] { return read_image(image.file); });
  return image;
}

void SceneReader::label(const json& object, const Field& field) {
  check_keys(object, field,
             {"id", "text", "anchor", "size", "priority", "image", "image_height", "image_side"});
  Label label;
  label.id = integer(required(object, field, "id"), field / "id");
  label.text = string(required(object, field, "text"), field / "text");
  label.anchor = vec3(required(object, field, "anchor"), field / "anchor");
  if (const auto problem = value_limits::position_problem("anchor", glm::dvec3(label.anchor)))
    (field / "anchor").fail(*problem);
  if (const json* size = optional(object, "size")) {
    const auto v = numbers(*size, field / "size", 2);
    if (v[0] < 0.0f || v[1] < 0.0f)
      (field / "size").fail("expected 2 numbers >= 0 (0 = from the text)");
    label.size = {v[0], v[1]};
  }
  if (const json* priority = optional(object, "priority")) {
    label.priority = number(*priority, field / "priority");
  }
  label.image = label_image(object, field);
  scene_.labels.push_back(std::move(label));
}

void SceneReader::camera(const json& object, const Field& field) {
  check_keys(object, field, {"fov_y", "near", "far", "eye", "target", "up", "view", "positions"});
  Camera& camera = scene_.camera;
  if (const json* fov = optional(object, "fov_y"))
    camera.fov_y_degrees = number(*fov, field / "fov_y");
  if (const json* n = optional(object, "near")) camera.near_plane = number(*n, field / "near");
  if (const json* f = optional(object, "far")) camera.far_plane = number(*f, field / "far");
  if (const auto problem = lens_problem(camera)) (field / problem->field).fail(problem->reason);
  if (const auto view = view_matrix(object, field)) {
    camera.view = *view;
    scene_.has_camera = true;
  }
  const json* positions = optional(object, "positions");
  if (!positions) return;
  if (!positions->is_array()) (field / "positions").fail("expected an array");
  for (size_t i = 0; i < positions->size(); ++i) {
    const Field position_field = (field / "positions")[i];
    const json& position = (*positions)[i];
    check_keys(position, position_field, {"name", "eye", "target", "up", "view"});
    CameraPose pose;
    pose.name = string(required(position, position_field, "name"), position_field / "name");
    const auto view = view_matrix(position, position_field);
    if (!view) position_field.fail("missing 'view' or 'eye'/'target'");
    pose.view = *view;
    scene_.camera_positions.push_back(std::move(pose));
  }
}

void SceneReader::settings(const json& object, const Field& field) {
  check_keys(object, field, {"layers", "weights", "ghost", "ghost_radius"});
  if (const json* layers = optional(object, "layers")) {
    scene_.settings.layer_count = integer(*layers, field / "layers");
    if (scene_.settings.layer_count < 1 || scene_.settings.layer_count > kMaxLayers)
      (field / "layers").fail("expected an integer from 1 to " + std::to_string(kMaxLayers));
  }
  if (const json* ghost = optional(object, "ghost")) {
    scene_.settings.ghost = number(*ghost, field / "ghost");
    if (scene_.settings.ghost < 0.0f || scene_.settings.ghost > 1.0f)
      (field / "ghost").fail("expected a number from 0 (off) to 1, got " + ghost->dump());
  }
  if (const json* radius = optional(object, "ghost_radius")) {
    scene_.settings.ghost_radius = number(*radius, field / "ghost_radius");
    if (scene_.settings.ghost_radius < kGhostRadiusMin ||
        scene_.settings.ghost_radius > kGhostRadiusMax) {
      (field / "ghost_radius")
          .fail("expected a share of the picture's shorter side from 0.005 to 0.5, got " +
                radius->dump());
    }
  }
  const json* weights = optional(object, "weights");
  if (!weights) return;
  const Field weights_field = field / "weights";
  CostWeights& w = scene_.settings.weights;
  const std::pair<const char*, float*> all[] = {{"label_shadow", &w.label_shadow},
                                                {"anchor_constraint", &w.anchor_constraint},
                                                {"connector_shadow", &w.connector_shadow},
                                                {"integral_costs", &w.integral_costs},
                                                {"distance_to_anchor", &w.distance_to_anchor},
                                                {"connector_direction", &w.connector_direction},
                                                {"previous_position", &w.previous_position},
                                                {"leader_crossing", &w.leader_crossing},
                                                {"illegible", &w.illegible}};
  check_keys(*weights, weights_field,
             {"label_shadow", "anchor_constraint", "connector_shadow", "integral_costs",
              "distance_to_anchor", "connector_direction", "previous_position", "leader_crossing",
              "illegible"});
  for (const auto& [key, target] : all) {
    if (const json* value = optional(*weights, key))
      *target = non_negative(*value, weights_field / key);
  }
}

template <typename F>
void each(const json& root, const Field& root_field, const char* key, F&& read) {
  const json* array = optional(root, key);
  if (!array) return;
  const Field field = root_field / key;
  if (!array->is_array()) field.fail("expected an array");
  for (size_t i = 0; i < array->size(); ++i) read((*array)[i], field[i]);
}

Scene SceneReader::read(const json& root) {
  const Field field{file_, ""};
  if (!root.is_object() || !root.contains("strata_scene")) {
    field.fail("not a strata scene (no \"strata_scene\": 1)");
  }
  if (root["strata_scene"] != 1) {
    (field / "strata_scene")
        .fail("version " + json_for_message(root["strata_scene"]) +
              " is not supported (this strata reads version 1)");
  }
  check_keys(root, field,
             {"strata_scene", "volumes", "meshes", "atlas", "segmentations", "labels", "camera",
              "settings"});
  each(root, field, "volumes", [&](const json& v, const Field& f) { volume(v, f); });
  each(root, field, "meshes", [&](const json& v, const Field& f) { mesh(v, f); });
  each(root, field, "atlas", [&](const json& v, const Field& f) { atlas(v, f); });
  if (const json* labels = optional(root, "labels"); labels && labels->is_string()) {
    const std::filesystem::path path = resolve(*labels, field / "labels");
    for (Label& l : (field / "labels").wrap([&] { return labels_to_add(path, scene_); }))
      scene_.labels.push_back(std::move(l));
  } else {
    each(root, field, "labels", [&](const json& v, const Field& f) { label(v, f); });
  }
  // After the labels: a segmentation's labels take ids the scene's own do not use.
  each(root, field, "segmentations", [&](const json& v, const Field& f) { segmentation(v, f); });
  if (const json* c = optional(root, "camera")) camera(*c, field / "camera");
  if (const json* s = optional(root, "settings")) settings(*s, field / "settings");
  // Placement keys its state by label id; two labels with one id would silently share it.
  std::set<int> ids;
  for (const Label& l : scene_.labels) {
    if (!ids.insert(l.id).second) {
      (field / "labels").fail("id " + std::to_string(l.id) + " is used by two labels");
    }
  }
  return std::move(scene_);
}

}  // namespace

Scene load_scene_json(const std::filesystem::path& path, const VolumeLimits& limits) {
  std::string text = read_text_file(path);
  json root;
  try {
    root = json::parse(text);
  } catch (const json::exception& e) {
    const std::string what = e.what();
    const size_t end = what.find("] ");
    throw Error(path.string() + ": " + (end == std::string::npos ? what : what.substr(end + 2)));
  }
  Scene scene = SceneReader(path, limits).read(root);
  scene.source_json = std::move(text);
  return scene;
}

Scene load_scene(const std::filesystem::path& path, const SceneOpenOptions& options) {
  const std::string extension = path.extension().string();
  Scene scene;
  if (!options.series.empty() && !is_volume_path(path))
    throw Error(path.string() +
                ": --series chooses the series of a DICOM folder opened directly; "
                "a scene file names it in its volume's \"series\"");
  if (extension == ".json") {
    scene = load_scene_json(path, options.limits);
  } else if (extension == ".xml") {
    scene = import_voly_scene(path, options.limits);
  } else if (is_volume_path(path)) {
    scene = scene_from_volume(path, options);
  } else {
    std::error_code error;
    if (!std::filesystem::exists(path, error)) throw Error(path.string() + ": no such file");
    throw Error(path.string() + ": unknown scene format '" + extension +
                "' (expected a scene: .json, or .xml from the thesis program; or a volume: " +
                kVolumeExtensions + ")");
  }
  if (options.segmentation) {
    VolumeReadOptions read{.limits = options.limits};
    add_segmentation(scene, *options.segmentation, read);
  }
  if (!options.labels.empty()) add_label_file(scene, options.labels);
  if (scene.labels.size() > size_t(kMaxLabels))
    throw Error(path.string() + ": " + std::to_string(scene.labels.size()) +
                " labels; strata places at most " + std::to_string(kMaxLabels) + " in a scene");
  for (Volume& volume : scene.volumes) {
    volume.cut.insert(volume.cut.end(), options.cut.begin(), options.cut.end());
    if (volume.cut.size() > kMaxCutPlanes)
      throw Error(path.string() + ": volume '" + volume.name + "' with --crop and --clip has " +
                  std::to_string(volume.cut.size()) + " cut-away planes, at most " +
                  std::to_string(kMaxCutPlanes));
  }
  complete_scene(scene, options.preset, options.window, options.fit);
  return scene;
}

void add_label_file(Scene& scene, const std::filesystem::path& path) {
  const size_t own = scene.labels.size();
  size_t same = 0;
  std::vector<Label> read = load_label_file(path);
  const std::vector<int> ids = unused_label_ids(scene.labels, read.size());
  for (size_t i = 0; i < read.size(); ++i) {
    Label& l = read[i];
    l.id = ids[i];
    // (a file the viewer saved before it kept the scene's labels apart holds them too)
    const bool known = std::any_of(scene.labels.begin(), scene.labels.begin() + ptrdiff_t(own),
                                   [&](const Label& o) { return same_label(o, l); });
    if (known) {
      ++same;
    } else {
      scene.labels.push_back(std::move(l));
    }
  }
  scene.added_labels = scene.labels.size() - own;
  if (const auto problem = label_limit_problem(scene.added_labels, own))
    throw Error(path.string() + ": " + *problem);
  if (same > 0)
    scene.warnings.push_back(path.string() + ": " + std::to_string(same) +
                             " of its labels the scene has already (the same text and anchor): "
                             "added once");
}

std::vector<int> unused_label_ids(const std::vector<Label>& labels, size_t count) {
  std::set<int> used;
  for (const Label& l : labels) used.insert(l.id);
  std::vector<int> ids;
  for (int64_t id = 0; ids.size() < count; ++id) {
    if (id > std::numeric_limits<int>::max())
      throw Error(std::to_string(count) +
                  " new labels: no label id left; the scene's labels take " +
                  "every free one from 0 to 2147483647");
    if (!used.count(int(id))) ids.push_back(int(id));
  }
  return ids;
}

int64_t next_label_id(const Scene& scene) {
  int64_t id = 0;
  for (const Label& l : scene.labels) id = std::max(id, int64_t{l.id} + 1);
  return id;
}

Scene scene_from_volume(const std::filesystem::path& path, const SceneOpenOptions& options) {
  Scene scene;
  scene.source = path;
  const VolumeReadOptions read{
      .frame = options.frame, .series = options.series, .limits = options.limits};
  scene.volumes.push_back(load_volume(path, read, scene.warnings));
  Volume& volume = scene.volumes.back();
  if (volume.name.empty()) volume.name = base_name(path.lexically_normal());
  return scene;
}

namespace {

// Each volume's box (after its transform) and each mesh (after its) inside the limit: one far
// corner or vertex would stretch the fitted camera until the rest is a dot, or to infinity.
void check_content_bounds(const Scene& scene) {
  using value_limits::kMaxSceneCoordinateMm;
  const auto check = [&](const std::string& what, const std::filesystem::path& source,
                         const char* point, const Bounds& box) {
    for (const glm::vec3 corner : {box.lo, box.hi}) {
      if (const auto problem =
              value_limits::position_problem(point, glm::dvec3(corner), kMaxSceneCoordinateMm))
        throw Error(scene.source.string() + ": " + what + " (" + source.string() +
                    "), placed by its transform: " + *problem);
    }
  };
  for (const Volume& volume : scene.volumes) {
    if (volume.voxel_count() == 0) continue;
    Bounds box;
    const auto [lo, hi] = volume.world_bounds();
    box.add(lo);
    box.add(hi);
    check("volume '" + volume.name + "'", volume.source, "a corner at", box);
  }
  for (const Mesh& mesh : scene.meshes) {
    Bounds box;
    for (const glm::vec3& p : mesh.positions)
      box.add(glm::vec3(mesh.transform * glm::vec4(p, 1.0f)));
    if (!box.empty()) check("mesh '" + mesh.name + "'", mesh.source, "a vertex at", box);
  }
}

// The fitted camera follows from content inside the limits, so a problem here is a bug in
// fitting, reported rather than rendered as an empty picture.
void check_fitted_camera(const Scene& scene, const Camera& camera) {
  std::string problem;
  if (const auto lens = lens_problem(camera))
    problem = std::string(lens->field) + ": " + lens->reason;
  const glm::vec3 eye = camera.eye();
  if (!(std::isfinite(eye.x) && std::isfinite(eye.y) && std::isfinite(eye.z)))
    problem = "the eye is not a finite position";
  if (!problem.empty())
    throw Error(scene.source.string() + ": the camera fitted to the content: " + problem);
}

// Every scene has the standard views as named positions besides its own (an own position of the
// same name wins), fitted to its content (or what its cut-aways keep) with its lens.
void complete_camera(Scene& scene, FitTo fit) {
  std::vector<CameraPose> views;
  if (scene.has_camera) {
    const AnatomicalPositions fitted = anatomical_positions(scene, scene.camera.fov_y_degrees, fit);
    views = fitted.positions;
    // (the planes hold the content from those views too)
    if (fitted.nearest > 0.0f)
      scene.camera.near_plane = std::min(scene.camera.near_plane, fitted.nearest);
    scene.camera.far_plane = std::max(scene.camera.far_plane, fitted.farthest);
    if (fit == FitTo::kept) {  // the file's own camera and positions: the same way, closer
      const float fov = scene.camera.fov_y_degrees;
      const Bounds kept = kept_bounds(scene);
      // (the near plane before the kept part, seen closer now)
      const auto refit = [&](glm::mat4& view) {
        view = refitted_view(scene, view, fov, fit);
        for (int corner = 0; corner < 8 && !kept.empty(); ++corner) {
          const glm::vec3 p((corner & 1) ? kept.hi.x : kept.lo.x,
                            (corner & 2) ? kept.hi.y : kept.lo.y,
                            (corner & 4) ? kept.hi.z : kept.lo.z);
          const float depth = -(view * glm::vec4(p, 1.0f)).z;
          if (depth > 0.0f)
            scene.camera.near_plane = std::min(scene.camera.near_plane, 0.5f * depth);
        }
      };
      refit(scene.camera.view);
      for (CameraPose& pose : scene.camera_positions) refit(pose.view);
    }
  } else {
    FittedCamera fitted = fitted_camera(scene, fit);
    check_fitted_camera(scene, fitted.camera);
    scene.camera = fitted.camera;
    views = std::move(fitted.positions);
  }
  for (CameraPose& pose : views) {
    const bool taken = std::any_of(scene.camera_positions.begin(), scene.camera_positions.end(),
                                   [&](const CameraPose& p) { return p.name == pose.name; });
    if (!taken) scene.camera_positions.push_back(std::move(pose));
  }
}

// A volume's transfer function: the command line's window or preset, else the file's window,
// preset or own function (made one of its value range), else the preset that suits its values.
void complete_transfer_function(Scene& scene, Volume& volume, const std::string& preset,
                                std::optional<glm::vec2> window) {
  if (!(volume.value_range.y > volume.value_range.x)) {
    scene.warnings.push_back("volume '" + volume.name + "' holds the one value " +
                             json(volume.value_range.x).dump() +
                             " everywhere: no transfer function can show it");
  }
  // (the command line's choice before the file's)
  const std::optional<glm::vec2> grey =
      window ? window : (preset.empty() ? volume.window : std::nullopt);
  if (grey) {
    scene.transfer_functions.push_back(
        in_value_range(window_transfer_function(grey->x, grey->y), volume));
    volume.transfer_function = int(scene.transfer_functions.size()) - 1;
    volume.window = grey;
    volume.preset.clear();
    return;
  }
  if (preset.empty() && volume.preset.empty() && volume.transfer_function >= 0) {
    // A function in the volume's own values: made one of its value range (each volume its own).
    const TransferFunction tf = scene.transfer_functions[size_t(volume.transfer_function)];
    if (tf.units.empty()) return;
    const PresetChoice suits = choose_transfer_function_preset(volume);
    if (tf.units == "HU" && !preset_is_ct(suits.name))
      scene.warnings.push_back("volume '" + volume.name + "': transfer function " + tf.name +
                               " is in Hounsfield units, but " + suits.reason);
    scene.transfer_functions.push_back(in_value_range(tf, volume));
    volume.transfer_function = int(scene.transfer_functions.size()) - 1;
    return;
  }
  std::string name = preset.empty() ? volume.preset : preset;
  const PresetChoice choice = choose_transfer_function_preset(volume);
  if (name.empty()) {
    name = choice.name;
    scene.warnings.push_back("volume '" + volume.name + "' has no transfer function; preset " +
                             name + " (" + choice.reason + "; --preset NAME to choose)");
  } else if (preset_is_ct(name) != preset_is_ct(choice.name)) {
    // (a preset for the other modality maps the values to nothing or to everything)
    scene.warnings.push_back("volume '" + volume.name + "': preset " + name + " is for " +
                             (preset_is_ct(name) ? "CT" : "MR") + ", but " + choice.reason +
                             "; it may show nothing (" + choice.name + " would suit it)");
  }
  volume.preset = name;
  volume.window.reset();
  scene.transfer_functions.push_back(make_transfer_function_preset(name, volume));
  volume.transfer_function = int(scene.transfer_functions.size()) - 1;
}

}  // namespace

void complete_scene(Scene& scene, const std::string& preset, std::optional<glm::vec2> window,
                    std::optional<bool> fit) {
  for (Volume& volume : scene.volumes) complete_transfer_function(scene, volume, preset, window);
  check_content_bounds(scene);
  complete_camera(scene, fit.value_or(!scene.has_camera) ? FitTo::kept : FitTo::content);
}

}  // namespace strata
