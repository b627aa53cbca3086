// Writing strata scene JSON (docs/scene-format.md): a scene read from strata JSON as it was read,
// any other from the model, with paths relative to the written file.
#include <algorithm>

#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "engine/core/json_field.h"
#include "engine/core/text_file.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/io/transfer_function_loader.h"
#include "engine/scene/transfer_function_presets.h"

namespace strata {
namespace {

using ordered_json = nlohmann::ordered_json;

ordered_json matrix_json(const glm::mat4& m) {
  ordered_json rows = ordered_json::array();
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) rows.push_back(shortest_double(m[col][row]));
  }
  return rows;
}

ordered_json vector_json(const float* values, int count) {
  ordered_json result = ordered_json::array();
  for (int i = 0; i < count; ++i) result.push_back(shortest_double(values[i]));
  return result;
}

ordered_json position_json(const CameraPose& pose) {
  return {{"name", pose.name}, {"view", matrix_json(pose.view)}};
}

ordered_json settings_json(const SceneSettings& settings) {
  const CostWeights& w = settings.weights;
  ordered_json out = {{"layers", settings.layer_count},
                      {"weights",
                       {{"label_shadow", shortest_double(w.label_shadow)},
                        {"anchor_constraint", shortest_double(w.anchor_constraint)},
                        {"connector_shadow", shortest_double(w.connector_shadow)},
                        {"integral_costs", shortest_double(w.integral_costs)},
                        {"distance_to_anchor", shortest_double(w.distance_to_anchor)},
                        {"connector_direction", shortest_double(w.connector_direction)},
                        {"previous_position", shortest_double(w.previous_position)},
                        {"leader_crossing", shortest_double(w.leader_crossing)},
                        {"illegible", shortest_double(w.illegible)}}}};
  if (settings.ghost != SceneSettings{}.ghost) out["ghost"] = shortest_double(settings.ghost);
  if (settings.ghost_radius != SceneSettings{}.ghost_radius) {
    out["ghost_radius"] = shortest_double(settings.ghost_radius);
  }
  return out;
}

ordered_json meshes_json(const std::vector<Mesh>& meshes, const auto& relative) {
  ordered_json result = ordered_json::array();
  std::vector<std::filesystem::path> written;
  for (const Mesh& mesh : meshes) {
    if (mesh.source.empty() ||
        std::find(written.begin(), written.end(), mesh.source) != written.end()) {
      continue;
    }
    written.push_back(mesh.source);
    ordered_json entry = {{"file", relative(mesh.source)}};
    // One colour for the whole file is kept as an override; per-part colours come from the file.
    if (std::all_of(meshes.begin(), meshes.end(), [&](const Mesh& m) {
          return m.source != mesh.source || m.color == mesh.color;
        })) {
      entry["color"] = vector_json(&mesh.color[0], 4);
    }
    if (mesh.transform != glm::mat4(1.0f)) entry["transform"] = matrix_json(mesh.transform);
    result.push_back(std::move(entry));
  }
  return result;
}

// A volume's look in its entry: a preset by name, a window, or its transfer function by file or
// inline in the volume's values (HU for CT), never in 0..1 of one scan's value range.
void look_json(ordered_json& entry, const Volume& volume, const Scene& scene,
               const auto& relative) {
  for (const char* key : {"transfer_function", "preset", "window"}) entry.erase(key);
  if (!volume.preset.empty()) {
    entry["preset"] = volume.preset;
  } else if (volume.window) {
    entry["window"] = vector_json(&volume.window->x, 2);
  } else if (volume.transfer_function >= 0) {
    const TransferFunction& tf = scene.transfer_functions.at(size_t(volume.transfer_function));
    entry["transfer_function"] = tf.source.empty() || volume.look_edited
                                     ? transfer_function_to_json(in_volume_values(tf, volume))
                                     : ordered_json(relative(tf.source));
  }
}

// A path as the file at `from` wrote it, as the file at `to` must write it: unchanged within one
// folder or when absolute, else relative to the new folder (absolute where there is no relative).
class Rebase {
 public:
  Rebase(const std::filesystem::path& from, const std::filesystem::path& to)
      : from_(std::filesystem::absolute(from).parent_path()),
        to_(std::filesystem::absolute(to).parent_path()) {}

  std::string operator()(const std::filesystem::path& file) const {
    const std::filesystem::path absolute = std::filesystem::absolute(file).lexically_normal();
    const std::filesystem::path r = absolute.lexically_relative(to_);
    return (r.empty() ? absolute : r).generic_string();
  }
  // A path key of the read file, if there is one and it is a string (else it is not a path).
  void key(ordered_json& object, const char* name) const {
    if (!object.is_object() || !object.contains(name) || !object[name].is_string()) return;
    const std::filesystem::path written(object[name].get<std::string>());
    if (written.is_absolute() || from_ == to_) return;
    object[name] = (*this)((from_ / written).lexically_normal());
  }
  void each(ordered_json& root, const char* array, std::initializer_list<const char*> names) const {
    if (!root.contains(array) || !root[array].is_array()) return;
    for (ordered_json& entry : root[array]) {
      for (const char* name : names) key(entry, name);
    }
  }

 private:
  std::filesystem::path from_, to_;
};

// The read file's camera positions: its own entries as written where the scene still has them,
// then the scene's new ones.
void write_positions(ordered_json& root, const Scene& scene) {
  ordered_json* camera = root.contains("camera") ? &root["camera"] : nullptr;
  ordered_json read =
      camera && camera->contains("positions") ? (*camera)["positions"] : ordered_json::array();
  std::vector<bool> used(read.size(), false);
  // The standard views complete_scene appends (CameraPose::fitted): the loader appends them
  // again, so those at the end of the list are not written (ones before a saved position are, to
  // keep the order that the keys 1 to 9 follow).
  ordered_json positions = ordered_json::array();
  size_t kept = 0;  // positions up to the last one that is not fitted
  for (const CameraPose& pose : scene.camera_positions) {
    bool found = false;
    for (size_t i = 0; i < read.size() && !found; ++i) {
      if (used[i] || !read[i].is_object() || read[i].value("name", "") != pose.name) continue;
      used[i] = found = true;
      positions.push_back(read[i]);
    }
    if (!found) positions.push_back(position_json(pose));
    if (found || !pose.fitted) kept = positions.size();
  }
  positions.erase(positions.begin() + std::ptrdiff_t(kept), positions.end());
  if (positions.empty() && !(camera && camera->contains("positions"))) return;
  if (!camera) {
    root["camera"] = ordered_json::object();
    camera = &root["camera"];
  }
  (*camera)["positions"] = std::move(positions);
}

// The segmentations whose masks or surfaces the scene shows, making those alone: their labels
// are written with the scene's (where the viewer may have moved or edited them).
ordered_json segmentations_json(const Scene& scene, const auto& relative) {
  ordered_json result = ordered_json::array();
  for (const SegmentationEntry& s : scene.segmentations) {
    if (!s.masks && !s.surfaces) continue;
    ordered_json make = ordered_json::array();
    if (s.masks) make.push_back("masks");
    if (s.surfaces) make.push_back("surfaces");
    ordered_json entry = {{"file", relative(s.file)}};
    if (s.names) entry["names"] = relative(*s.names);
    if (!s.regions.empty()) entry["regions"] = s.regions;
    entry["make"] = std::move(make);
    result.push_back(std::move(entry));
  }
  return result;
}

// The scene's own file, as read, with its paths rebased to `path` and the scene's positions.
ordered_json as_read(const std::filesystem::path& path, const Scene& scene) {
  ordered_json root = ordered_json::parse(scene.source_json);
  const Rebase rebase(scene.source, path);
  rebase.each(root, "volumes", {"file", "transfer_function"});
  rebase.each(root, "meshes", {"file"});
  rebase.each(root, "atlas", {"labels", "names", "mask_transfer_function"});
  rebase.each(root, "segmentations", {"file", "names"});
  rebase.key(root, "labels");
  rebase.each(root, "labels", {"image"});
  // (the file's volumes come first in the scene, in its order)
  if (root.contains("volumes") && root["volumes"].is_array()) {
    for (size_t i = 0; i < root["volumes"].size() && i < scene.volumes.size(); ++i)
      if (scene.volumes[i].look_edited)
        look_json(root["volumes"][i], scene.volumes[i], scene, rebase);
  }
  write_positions(root, scene);
  return root;
}

// A scene from another source (a volume, a thesis .xml): what the model holds.
ordered_json from_model(const std::filesystem::path& path, const Scene& scene) {
  const Rebase relative(path, path);
  ordered_json volumes = ordered_json::array();
  for (const Volume& volume : scene.volumes) {
    if (volume.source.empty()) continue;
    ordered_json entry = {{"name", volume.name}, {"file", relative(volume.source)}};
    look_json(entry, volume, scene, relative);
    if (!volume.series.empty()) entry["series"] = volume.series;
    if (volume.transform != glm::mat4(1.0f)) entry["transform"] = matrix_json(volume.transform);
    volumes.push_back(std::move(entry));
  }
  ordered_json labels = ordered_json::array();
  for (const Label& label : scene.labels) {
    ordered_json entry = {{"id", label.id},
                          {"text", label.text},
                          {"anchor", vector_json(&label.anchor[0], 3)},
                          {"size", vector_json(&label.size[0], 2)}};
    if (label.priority != 0.0f) entry["priority"] = shortest_double(label.priority);
    if (const auto& image = label.image) {
      entry["image"] = relative(image->file);
      entry["image_height"] = shortest_double(image->height);
      entry["image_side"] = image->side == LabelImage::Side::left ? "left" : "above";
    }
    labels.push_back(std::move(entry));
  }
  ordered_json root = {{"strata_scene", 1},
                       {"volumes", volumes},
                       {"meshes", meshes_json(scene.meshes, relative)},
                       {"labels", labels}};
  if (const ordered_json made = segmentations_json(scene, relative); !made.empty())
    root["segmentations"] = made;
  // A fitted camera is not written: the loader fits it again (to the same scene, the same).
  if (scene.has_camera) {
    root["camera"] = {{"fov_y", shortest_double(scene.camera.fov_y_degrees)},
                      {"near", shortest_double(scene.camera.near_plane)},
                      {"far", shortest_double(scene.camera.far_plane)},
                      {"view", matrix_json(scene.camera.view)}};
  }
  write_positions(root, scene);
  root["settings"] = settings_json(scene.settings);
  return root;
}

}  // namespace

void save_scene_json(const std::filesystem::path& path, const Scene& scene,
                     AtomicFile::Replace replace) {
  const ordered_json root =
      scene.source_json.empty() ? from_model(path, scene) : as_read(path, scene);
  write_file_atomically(path, root.dump(2) + '\n', "the scene", replace);
}

}  // namespace strata
