// Camera paths: the camera moving through the scene's named positions over time, for videos and
// for several stills of one scene. The text form is the thesis program's: `front,left_2,top_3`
// starts at `front`, moves to `left` in 2 s, then to `top` in 3 s (docs/scene-format.md, "Camera
// paths"). A turntable (3D Slicer's screen capture) turns the camera about the scene's centre.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "engine/scene/camera.h"
#include "engine/scene/scene.h"

namespace strata {

// Limits that keep a video's work and memory bounded, checked before anything is allocated: a
// path (each move and their sum) or a turntable lasts at most an hour, and sample() gives at most
// 100,000 frames (an hour at about 28 fps; 55 minutes at 30).
inline constexpr double kMaxPathSeconds = 3600.0;
inline constexpr uint32_t kMaxVideoFrames = 100000;

// The pose reached at `time`, and how the camera gets there from the key before.
struct CameraKey {
  Camera camera;
  double time = 0.0;  // seconds from the path's start
  // 0: an eased move around the poses' targets (see CameraPath::at). Otherwise a turn of the
  // previous pose by this many degrees about the path's centre and up axis, at constant speed.
  double turn_degrees = 0.0;
};

struct CameraPath {
  std::vector<CameraKey> keys;     // by time, the first at 0; never empty once parsed
  glm::vec3 centre{0.0f};          // the scene's centre: where targets are derived from, the pivot
  glm::vec3 up{0.0f, 0.0f, 1.0f};  // the axis turns go about

  double duration() const { return keys.empty() ? 0.0 : keys.back().time; }
  // The camera at `seconds`, clamped to [0, duration()]: exactly the key's pose at a key's time.
  Camera at(double seconds) const;
  // Whether it moves and ends where it starts (a turntable of whole turns, a path back to its
  // first position): its video loops.
  bool loops() const;
};

// The name a path gives the scene's own camera (`Scene::camera`), unless the scene has a position
// of that name.
inline constexpr const char* scene_camera_name = "default";

// The scene's position `name`, or its own camera for `default`; an Error naming it otherwise.
Camera camera_position(const Scene& scene, const std::string& name);

// Comma-separated parts, each without the spaces around it (`"front, left"` is front and left).
std::vector<std::string> split_camera_list(const std::string& text);

// `front,left_2,top_3`: each part is a position name with `_SECONDS` for the time the move to it
// takes (default 1 s); a part that is itself a position's name is that position (`left_side`).
// The first part is where the path starts and takes no duration. One Error per problem (an empty
// path or part, an unknown name listing the scene's names, a duration that is not a number of
// seconds in (0, kMaxPathSeconds], a path longer than kMaxPathSeconds), naming the part. The lens
// (field of view, near, far) is the scene camera's throughout.
CameraPath parse_camera_path(const Scene& scene, const std::string& text);

// A turntable: the scene turns `degrees` counter-clockwise about its up axis through its centre,
// seen from above (right-handed about `CameraPath::up`), at constant speed over `seconds`, from
// `start`. No easing: a 360-degree turn loops without a pause.
CameraPath orbit_path(const Scene& scene, const Camera& start, double degrees, double seconds);

// The frames of a video at `fps`: round(duration * fps) + 1 cameras, evenly spaced from t = 0 to
// t = duration (so exactly 1 / fps apart when duration * fps is whole). A looping path
// (CameraPath::loops) drops the last frame, which repeats the first. One frame for a path of one
// position.
// An Error, before any allocation, past kMaxVideoFrames or for an fps that is not positive.
std::vector<Camera> sample(const CameraPath& path, double fps);
// The frames sample() would give (before a looping video drops its last): duration * fps + 1.
double sampled_frames(const CameraPath& path, double fps);

}  // namespace strata
