// Import of the thesis program's scenes (voly-labeller, Boost serialization XML). The archive is a
// list of <item><px class_id=".." class_name="CameraNode">...</px></item>; only the first object
// of a class carries class_name, later ones refer to it by class_id_reference, and a px with
// object_id_reference repeats a pointer already written (skipped).
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include <pugixml.hpp>

#include "engine/core/error.h"
#include "engine/core/text_file.h"
#include "engine/scene/io/mesh_loader.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/io/transfer_function_loader.h"
#include "engine/scene/io/volume_loader.h"
#include "engine/scene/value_limits.h"

namespace strata {

namespace {

namespace fs = std::filesystem;

// An element of the archive and where it is, for errors: "item[3] (CameraNode).viewMatrix".
struct Node {
  pugi::xml_node xml;
  const std::string& file;
  std::string field;

  [[noreturn]] void fail(const std::string& reason) const {
    throw Error(file + ": " + field + ": " + reason);
  }
  Node child(const char* name) const {
    const pugi::xml_node c = xml.child(name);
    if (!c) fail(std::string("missing <") + name + ">");
    return {c, file, field + "." + name};
  }
  std::optional<Node> optional_child(const char* name) const {
    const pugi::xml_node c = xml.child(name);
    if (!c) return std::nullopt;
    return Node{c, file, field + "." + name};
  }
  std::string text() const { return xml.child_value(); }
  float number() const {
    std::string value = text();
    const size_t begin = value.find_first_not_of(" \t\r\n");
    value = begin == std::string::npos
                ? ""
                : value.substr(begin, value.find_last_not_of(" \t\r\n") + 1 - begin);
    double result = 0.0;
    const auto [rest, error] = std::from_chars(value.data(), value.data() + value.size(), result);
    // Beyond float's range the conversion below is undefined (and gave inf).
    if (error != std::errc() || rest != value.data() + value.size() || value.empty() ||
        !(std::fabs(result) <= double(std::numeric_limits<float>::max()))) {
      fail("expected a number, got '" + value + "'");
    }
    return static_cast<float>(result);
  }
  glm::vec3 vec3() const { return {child("x").number(), child("y").number(), child("z").number()}; }
  glm::vec2 vec2() const { return {child("x").number(), child("y").number()}; }
  // Elements r{row}c{col}; glm indexes [column][row].
  glm::mat4 matrix() const {
    glm::mat4 m(1.0f);
    for (int row = 0; row < 4; ++row) {
      for (int col = 0; col < 4; ++col) {
        const std::string name = "r" + std::to_string(row) + "c" + std::to_string(col);
        m[col][row] = child(name.c_str()).number();
      }
    }
    return m;
  }
};

class VolyImporter {
 public:
  VolyImporter(const fs::path& path, const VolumeLimits& limits)
      : file_(path.string()), limits_(limits) {
    scene_.source = path;
    for (fs::path folder = fs::absolute(path).parent_path();; folder = folder.parent_path()) {
      ancestors_.push_back(folder);
      if (folder == folder.parent_path()) break;
    }
  }

  Scene import(const pugi::xml_node& data);

 private:
  std::optional<fs::path> find_file(const std::string& reference) const;
  void camera(const Node& px);
  void label(const Node& px);
  void volume(const Node& px);
  void meshes(const Node& px);
  void warn(const std::string& what) { scene_.warnings.push_back(file_ + ": " + what); }

  std::string file_;
  VolumeLimits limits_;
  std::vector<fs::path> ancestors_;  // the scene's folder, its parent, ..., the root
  Scene scene_;
};

// The thesis program resolved "assets/transferfunctions/dice4.gra" from its working folder. Try
// the reference under each ancestor of the scene's folder, then its file name inside a folder
// named like its parent ("transferfunctions/dice4.gra") under each ancestor, which finds the
// published scenes' transfer functions in the sibling folder.
std::optional<fs::path> VolyImporter::find_file(const std::string& reference) const {
  const fs::path given(reference);
  std::error_code ec;
  if (given.is_absolute()) return fs::exists(given, ec) ? std::optional(given) : std::nullopt;
  std::vector<fs::path> tails{given};
  if (given.has_parent_path()) tails.push_back(given.parent_path().filename() / given.filename());
  for (const fs::path& tail : tails) {
    for (const fs::path& folder : ancestors_) {
      if (fs::exists(folder / tail, ec)) return folder / tail;
    }
  }
  return std::nullopt;
}

void VolyImporter::camera(const Node& px) {
  Camera& camera = scene_.camera;
  camera.view = px.child("viewMatrix").matrix();
  scene_.has_camera = true;
  const Node projection_node = px.child("projectionMatrix");
  const glm::mat4 p = projection_node.matrix();
  // An OpenGL perspective matrix: P[1][1] = 1 / tan(fov_y / 2), r2c2 = -(f + n) / (f - n),
  // r2c3 = -2 f n / (f - n); so n = r2c3 / (r2c2 - 1) and f = r2c3 / (r2c2 + 1).
  const float p22 = p[2][2], p23 = p[3][2];
  if (!(p[1][1] > 0.0f) || p22 == 1.0f || p22 == -1.0f) {
    projection_node.fail("not an OpenGL perspective projection");
  }
  camera.fov_y_degrees = glm::degrees(2.0f * std::atan(1.0f / p[1][1]));
  camera.near_plane = p23 / (p22 - 1.0f);
  camera.far_plane = p23 / (p22 + 1.0f);
  if (!(camera.near_plane > 0.0f && camera.far_plane > camera.near_plane)) {
    projection_node.fail("near and far planes are not 0 < near < far");
  }
  if (const auto problem = lens_problem(camera))
    projection_node.fail(std::string(problem->field) + ": " + problem->reason);
  const std::optional<Node> positions = px.optional_child("cameraPositions");
  if (!positions) return;  // scenes saved before version 1 of CameraNode have none
  size_t index = 0;
  for (const pugi::xml_node item : positions->xml.children("item")) {
    const Node node{item, file_, positions->field + ".item[" + std::to_string(index++) + "]"};
    scene_.camera_positions.push_back(
        {node.child("name").text(), node.child("viewMatrix").matrix()});
  }
}

void VolyImporter::label(const Node& px) {
  const Node node = px.child("label");
  Label label;
  const Node id = node.child("label.id");
  const float id_value = id.number();
  // 2^31 is the first float past int's range; converting it or beyond is undefined.
  if (id_value != std::floor(id_value) || !(id_value >= -0x1p31f && id_value < 0x1p31f))
    id.fail("expected an integer from -2147483648 to 2147483647");
  label.id = int(id_value);
  label.text = node.child("label.text").text();
  const Node anchor = node.child("label.anchorPosition");
  label.anchor = anchor.vec3();
  if (const auto problem = value_limits::position_problem("anchor", glm::dvec3(label.anchor)))
    anchor.fail(*problem);
  label.size = node.child("label.size").vec2();
  scene_.labels.push_back(std::move(label));
}

void VolyImporter::volume(const Node& px) {
  const Node path_node = px.child("volumePath");
  const std::string reference = path_node.text();
  int tf_index = -1;
  if (const std::optional<Node> tf_node = px.optional_child("transferFunctionPath")) {
    // Loaded even when the volume is missing, so `strata info` still shows what the scene uses.
    const std::string tf_reference = tf_node->text();
    if (const std::optional<fs::path> tf_path = find_file(tf_reference)) {
      try {
        scene_.transfer_functions.push_back(load_transfer_function(*tf_path));
      } catch (const Error& e) {
        tf_node->fail(e.what());
      }
      tf_index = int(scene_.transfer_functions.size()) - 1;
    } else if (!tf_reference.empty()) {
      warn("transfer function '" + tf_reference + "' not found; skipped");
    }
  }
  const std::optional<fs::path> path = find_file(reference);
  if (!path) return warn("volume '" + reference + "' not found; skipped");
  Volume volume;
  try {
    volume = load_volume(*path, {.limits = limits_}, scene_.warnings);
  } catch (const Error& e) {
    path_node.fail(e.what());
  }
  volume.name = path->filename().string().substr(0, path->filename().string().find('.'));
  volume.transfer_function = tf_index;
  if (const std::optional<Node> transform = px.optional_child("overallTransformation")) {
    volume.transform = transform->matrix();
  }
  scene_.volumes.push_back(std::move(volume));
}

void VolyImporter::meshes(const Node& px) {
  const Node path_node = px.child("assetFilename");
  const std::string reference = path_node.text();
  const std::optional<fs::path> path = find_file(reference);
  if (!path) return warn("mesh '" + reference + "' not found; skipped");
  std::vector<Mesh> loaded;
  try {
    loaded = load_meshes(*path);
  } catch (const Error& e) {
    path_node.fail(e.what());
  }
  const std::optional<Node> transform_node = px.optional_child("transformation");
  const glm::mat4 transform = transform_node ? transform_node->matrix() : glm::mat4(1.0f);
  for (Mesh& mesh : loaded) {
    mesh.transform = transform;
    scene_.meshes.push_back(std::move(mesh));
  }
}

Scene VolyImporter::import(const pugi::xml_node& data) {
  std::map<std::string, std::string> class_names;  // class_id -> class_name
  std::set<std::string> skipped_classes;
  size_t index = 0;
  for (const pugi::xml_node item : data.children("item")) {
    const Node px{item.child("px"), file_, "item[" + std::to_string(index++) + "]"};
    if (!px.xml) px.fail("missing <px>");
    if (px.xml.attribute("object_id_reference")) continue;  // a pointer written before
    std::string class_name;
    if (const pugi::xml_attribute id = px.xml.attribute("class_id")) {
      class_name = px.xml.attribute("class_name").value();
      class_names[id.value()] = class_name;
    } else {
      const pugi::xml_attribute reference_attribute = px.xml.attribute("class_id_reference");
      if (!reference_attribute) px.fail("<px> has neither class_id nor class_id_reference");
      const std::string reference = reference_attribute.value();
      const auto known = class_names.find(reference);
      if (known == class_names.end())
        px.fail("class_id_reference '" + reference + "' names no class seen before");
      class_name = known->second;
    }
    const Node node{px.xml, file_, px.field + " (" + class_name + ")"};
    if (class_name == "CameraNode") {
      camera(node);
    } else if (class_name == "LabelNode") {
      label(node);
    } else if (class_name == "VolumeNode") {
      volume(node);
    } else if (class_name == "MeshesNode") {
      meshes(node);
    } else if (skipped_classes.insert(class_name).second) {
      warn("nodes of class '" + class_name + "' are not imported; skipped");
    }
  }
  return std::move(scene_);
}

}  // namespace

Scene import_voly_scene(const fs::path& path, const VolumeLimits& limits) {
  const std::string file = path.string();
  const std::string text = read_text_file(path);
  pugi::xml_document document;
  const pugi::xml_parse_result parsed = document.load_buffer(text.data(), text.size());
  if (!parsed) {
    throw Error(file + ": XML error at " + text_position(text, parsed.offset) + ": " +
                parsed.description());
  }
  const pugi::xml_node data = document.child("boost_serialization").child("data");
  if (!data) throw Error(file + ": not a voly-labeller scene (no <boost_serialization><data>)");
  return VolyImporter(path, limits).import(data);
}

}  // namespace strata
