// Writing strata scene JSON (docs/scene-format.md): what a loaded or imported scene holds, with
// paths relative to the written file.
#include <algorithm>
#include <fstream>

#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/io/transfer_function_loader.h"

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

ordered_json camera_json(const Camera& camera, const std::vector<CameraPose>& poses) {
  ordered_json positions = ordered_json::array();
  for (const CameraPose& pose : poses) {
    positions.push_back({{"name", pose.name}, {"view", matrix_json(pose.view)}});
  }
  return {{"fov_y", shortest_double(camera.fov_y_degrees)},
          {"near", shortest_double(camera.near_plane)},
          {"far", shortest_double(camera.far_plane)},
          {"view", matrix_json(camera.view)},
          {"positions", positions}};
}

ordered_json settings_json(const SceneSettings& settings) {
  const CostWeights& w = settings.weights;
  return {{"layers", settings.layer_count},
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

}  // namespace

void save_scene_json(const std::filesystem::path& path, const Scene& scene) {
  const std::filesystem::path folder = std::filesystem::absolute(path).parent_path();
  const auto relative = [&](const std::filesystem::path& file) {
    const std::filesystem::path r = std::filesystem::absolute(file).lexically_relative(folder);
    return (r.empty() ? std::filesystem::absolute(file) : r).generic_string();
  };
  ordered_json volumes = ordered_json::array();
  for (const Volume& volume : scene.volumes) {
    if (volume.source.empty()) continue;
    ordered_json entry = {{"name", volume.name}, {"file", relative(volume.source)}};
    if (volume.transfer_function >= 0) {
      entry["transfer_function"] =
          transfer_function_to_json(scene.transfer_functions.at(size_t(volume.transfer_function)));
    }
    if (volume.transform != glm::mat4(1.0f)) entry["transform"] = matrix_json(volume.transform);
    volumes.push_back(std::move(entry));
  }
  ordered_json labels = ordered_json::array();
  for (const Label& label : scene.labels) {
    ordered_json entry = {{"id", label.id},
                          {"text", label.text},
                          {"anchor", vector_json(&label.anchor[0], 3)},
                          {"size", vector_json(&label.size[0], 2)}};
    if (label.priority != 0.0f) entry["priority"] = label.priority;
    if (const auto& image = label.image) {
      entry["image"] = relative(image->file);
      entry["image_height"] = shortest_double(image->height);
      entry["image_side"] = image->side == LabelImage::Side::left ? "left" : "above";
    }
    labels.push_back(std::move(entry));
  }
  const ordered_json root = {{"strata_scene", 1},
                             {"volumes", volumes},
                             {"meshes", meshes_json(scene.meshes, relative)},
                             {"labels", labels},
                             {"camera", camera_json(scene.camera, scene.camera_positions)},
                             {"settings", settings_json(scene.settings)}};
  std::ofstream out(path, std::ios::binary);
  out << root.dump(2) << '\n';
  if (!out) throw Error(path.string() + ": cannot write the file");
}

}  // namespace strata
