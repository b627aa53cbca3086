#include "labeling/camera_path.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "engine/core/error.h"
#include "engine/scene/scene_bounds.h"

namespace strata {
namespace {

// A pose as the path moves it: the camera's orientation (camera to world), the point it looks
// at and how far its eye is from that point. Interpolating these, not the eye, keeps the camera
// circling the content instead of cutting through it.
struct OrbitPose {
  glm::dquat orientation{1.0, 0.0, 0.0, 0.0};
  glm::dvec3 target{0.0};
  double distance = 0.0;
};

// A view matrix stores no target, so take the point of the viewing ray closest to the scene's
// centre: for a camera aimed at the content that is about where it looks. A camera facing away
// from the centre gets its own eye (distance 0): the move then turns it on the spot.
OrbitPose orbit_pose(const glm::mat4& view, glm::dvec3 centre) {
  const glm::dmat4 v(view);
  const glm::dmat3 to_world = glm::transpose(glm::dmat3(v));
  const glm::dvec3 eye = -(to_world * glm::dvec3(v[3]));
  const glm::dvec3 forward = -to_world[2];
  OrbitPose pose;
  pose.orientation = glm::normalize(glm::quat_cast(to_world));
  pose.distance = std::max(0.0, glm::dot(centre - eye, forward));
  pose.target = eye + forward * pose.distance;
  return pose;
}

glm::mat4 view_matrix(const OrbitPose& pose) {
  const glm::dmat3 to_world = glm::mat3_cast(pose.orientation);
  const glm::dvec3 eye = pose.target + to_world[2] * pose.distance;  // back along -forward
  const glm::dmat3 to_eye = glm::transpose(to_world);
  glm::dmat4 view(to_eye);
  view[3] = glm::dvec4(-(to_eye * eye), 1.0);
  return glm::mat4(view);
}

// Zero speed at both ends of a move, so a path starts, passes its positions and stops smoothly.
double smoothstep(double s) {
  return s * s * (3.0 - 2.0 * s);
}

// From `from` to `to` at s in [0, 1], eased: orientation by slerp (the shorter way), target and
// distance linearly.
Camera eased_move(const Camera& from, const Camera& to, glm::dvec3 centre, double s) {
  const OrbitPose a = orbit_pose(from.view, centre), b = orbit_pose(to.view, centre);
  const double e = smoothstep(s);
  OrbitPose pose;
  pose.orientation = glm::slerp(a.orientation, b.orientation, e);
  pose.target = glm::mix(a.target, b.target, e);
  pose.distance = glm::mix(a.distance, b.distance, e);
  Camera camera = from;
  camera.view = view_matrix(pose);
  return camera;
}

// The scene turned by `degrees` about `axis` through `centre` before the camera sees it: the eye
// circles the centre the other way at a constant distance.
Camera turned(const Camera& camera, glm::dvec3 centre, glm::dvec3 axis, double degrees) {
  glm::dmat4 turn = glm::translate(glm::dmat4(1.0), centre);
  turn = glm::rotate(turn, glm::radians(degrees), axis);
  turn = glm::translate(turn, -centre);
  Camera out = camera;
  out.view = glm::mat4(glm::dmat4(camera.view) * turn);
  return out;
}

// The world axis closest to the camera's up vector, with its sign. Not the up vector itself: a
// view matrix keeps only the up made orthogonal to the viewing direction, which tilts with the
// camera's elevation, while scenes write up as an axis (`"up": [0, 0, 1]`, the patient's head
// direction in LPS). Turning about the axis keeps an oblique camera at its height, the way an
// object turns on a turntable, instead of circling in a tilted plane.
glm::vec3 up_axis(const Camera& camera) {
  const glm::vec3 up(camera.view[0][1], camera.view[1][1], camera.view[2][1]);  // row 1
  int axis = 0;
  for (int i = 1; i < 3; ++i) {
    if (std::abs(up[i]) > std::abs(up[axis])) axis = i;
  }
  glm::vec3 out(0.0f);
  out[axis] = up[axis] < 0.0f ? -1.0f : 1.0f;
  return out;
}

bool scene_names(const Scene& scene, const std::string& name) {
  return find_position(scene, name) != nullptr;
}

bool has_position(const Scene& scene, const std::string& name) {
  return name == scene_camera_name || scene_names(scene, name);
}

std::string position_names(const Scene& scene) {
  std::string names;
  for (const CameraPose& pose : scene.camera_positions) names += pose.name + ", ";
  if (scene_names(scene, scene_camera_name)) return names.substr(0, names.size() - 2);
  return names + scene_camera_name + " (the scene's camera)";
}

[[noreturn]] void fail(const Scene& scene, const std::string& text, const std::string& reason) {
  const std::string file = scene.source.empty() ? "" : scene.source.string() + ": ";
  throw Error(file + "camera path '" + text + "': " + reason);
}

// "2", "0.5", "1e1": a number in (0, kMaxPathSeconds] and nothing else.
bool parse_seconds(const std::string& text, double& seconds) {
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, seconds);
  return ec == std::errc() && ptr == end && std::isfinite(seconds) && seconds > 0.0 &&
         seconds <= kMaxPathSeconds;
}

// One part of a path's text: the pose it names and the seconds the move to it takes.
struct PathPart {
  Camera camera;
  double seconds = 0.0;
};

// `name` or `name_SECONDS`; the whole part is tried as a name first, so `left_side` is a name.
PathPart parse_part(const Scene& scene, const std::string& text, const std::string& part,
                    size_t index) {
  if (part.empty()) fail(scene, text, "part " + std::to_string(index + 1) + " is empty");
  const double default_seconds = index == 0 ? 0.0 : 1.0;
  if (has_position(scene, part)) return {camera_position(scene, part), default_seconds};
  const size_t cut = part.rfind('_');
  const std::string name = part.substr(0, cut);
  if (!has_position(scene, name)) {
    fail(scene, text,
         "'" + part + "': no position named '" + name +
             "' (the scene has: " + position_names(scene) + ")");
  }
  if (index == 0) {
    fail(scene, text, "'" + part + "': the first position is where the path starts; no duration");
  }
  const std::string duration = part.substr(cut + 1);
  PathPart out{camera_position(scene, name)};
  if (!parse_seconds(duration, out.seconds)) {
    fail(scene, text,
         "'" + part + "': '" + duration + "' is not a duration (seconds in (0, " +
             std::to_string(int(kMaxPathSeconds)) + "])");
  }
  return out;
}

}  // namespace

Camera CameraPath::at(double seconds) const {
  if (keys.empty()) throw Error("camera path: no positions");
  const double t = std::clamp(seconds, 0.0, duration());
  // The move in progress ends at the first key at or after t.
  const auto next =
      std::lower_bound(keys.begin(), keys.end(), t,
                       [](const CameraKey& key, double time) { return key.time < time; });
  if (next == keys.begin() || next->time == t) return next->camera;
  const CameraKey& from = *(next - 1);
  const double s = (t - from.time) / (next->time - from.time);
  if (next->turn_degrees != 0.0) {
    return turned(from.camera, glm::dvec3(centre), glm::dvec3(up), next->turn_degrees * s);
  }
  return eased_move(from.camera, next->camera, glm::dvec3(centre), s);
}

Camera camera_position(const Scene& scene, const std::string& name) {
  if (name == scene_camera_name && !scene_names(scene, name)) return scene.camera;
  return camera_for(scene, name);
}

std::vector<std::string> split_camera_list(const std::string& text) {
  std::vector<std::string> parts;
  size_t start = 0;
  for (;;) {
    const size_t comma = text.find(',', start);
    std::string part = text.substr(start, comma == std::string::npos ? comma : comma - start);
    const size_t first = part.find_first_not_of(" \t");
    part = first == std::string::npos
               ? ""
               : part.substr(first, part.find_last_not_of(" \t") + 1 - first);
    parts.push_back(part);
    if (comma == std::string::npos) return parts;
    start = comma + 1;
  }
}

CameraPath parse_camera_path(const Scene& scene, const std::string& text) {
  const std::vector<std::string> parts = split_camera_list(text);
  if (parts.size() == 1 && parts[0].empty()) {
    fail(scene, text, "empty: expected positions such as front,left_2,top_3");
  }
  CameraPath path;
  path.centre = scene_bounds(scene).centre();
  path.up = up_axis(scene.camera);
  double time = 0.0;
  for (size_t i = 0; i < parts.size(); ++i) {
    const PathPart part = parse_part(scene, text, parts[i], i);
    time += part.seconds;
    if (time > kMaxPathSeconds) {
      fail(scene, text,
           "'" + parts[i] + "': the path lasts more than " + std::to_string(int(kMaxPathSeconds)) +
               " s by here");
    }
    path.keys.push_back({part.camera, time});
  }
  return path;
}

CameraPath orbit_path(const Scene& scene, const Camera& start, double degrees, double seconds) {
  if (!std::isfinite(degrees)) throw Error("orbit: the angle must be a number of degrees");
  if (!(std::isfinite(seconds) && seconds > 0.0 && seconds <= kMaxPathSeconds)) {
    throw Error("orbit: the duration must be a number of seconds in (0, " +
                std::to_string(int(kMaxPathSeconds)) + "]");
  }
  CameraPath path;
  path.centre = scene_bounds(scene).centre();
  path.up = up_axis(start);
  const Camera end = turned(start, glm::dvec3(path.centre), glm::dvec3(path.up), degrees);
  path.keys = {{start, 0.0}, {end, seconds, degrees}};
  return path;
}

bool CameraPath::loops() const {
  if (keys.size() < 2 || !(duration() > 0.0)) return false;
  // (a full turn comes back only to the float rounding of its view matrix)
  const glm::mat4 start = keys.front().camera.view, end = at(duration()).view;
  float scale = 1.0f, difference = 0.0f;
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      scale = std::max(scale, std::abs(start[c][r]));
      difference = std::max(difference, std::abs(start[c][r] - end[c][r]));
    }
  }
  return difference <= 1e-5f * scale;
}

double sampled_frames(const CameraPath& path, double fps) {
  return std::round(path.duration() * fps) + 1.0;
}

std::vector<Camera> sample(const CameraPath& path, double fps) {
  if (!(std::isfinite(fps) && fps > 0.0)) throw Error("camera path: fps must be positive");
  if (!(sampled_frames(path, fps) <= double(kMaxVideoFrames))) {
    throw Error("camera path: " + std::to_string(path.duration()) + " s at " + std::to_string(fps) +
                " fps is more than " + std::to_string(kMaxVideoFrames) + " frames");
  }
  const long long intervals = std::llround(path.duration() * fps);
  std::vector<Camera> frames;
  frames.push_back(path.at(0.0));
  for (long long i = 1; i <= intervals; ++i) {
    // The last frame lands on the end exactly, whatever the rounding of duration * fps.
    frames.push_back(path.at(path.duration() * double(i) / double(intervals)));
  }
  // Played in a loop, the first frame follows the last a step later, as every other frame.
  if (frames.size() > 1 && path.loops()) frames.pop_back();
  return frames;
}

}  // namespace strata
