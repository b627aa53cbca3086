// The mouse and keys (3D Slicer's conventions) and the camera's actions: named positions,
// anatomical views, reset, a position saved into the scene.
#include "app/viewer/viewer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "app/viewer/script_run.h"
#include "engine/core/error.h"
#include "engine/scene/io/scene_loader.h"
#include "labeling/camera_path.h"

namespace strata::app {
namespace {

constexpr double kAnimationSeconds = 1.0;  // moves to named positions and anatomical views

// A new scene file beside `opened` (a volume, a DICOM folder, a thesis .xml scene), named after
// it and clashing with no file there: scan.nii.gz gives scan.scene.json, else scan.scene-2.json...
// Written with Replace::no, so a file that appears meanwhile is not replaced either.
std::filesystem::path save_new_scene_file(const std::filesystem::path& opened, const Scene& scene) {
  std::filesystem::path normal = opened.lexically_normal();
  if (normal.filename().empty()) normal = normal.parent_path();  // "ct/": the folder ct
  const std::string file = normal.filename().string();
  const std::string stem = file.substr(0, file.find('.'));
  for (int n = 1; n < 1000; ++n) {
    const std::filesystem::path path =
        normal.parent_path() /
        (stem + ".scene" + (n == 1 ? "" : "-" + std::to_string(n)) + ".json");
    std::error_code error;
    if (std::filesystem::exists(std::filesystem::symlink_status(path, error))) continue;
    try {
      save_scene_json(path, scene, AtomicFile::Replace::no);
      return path;
    } catch (const Error&) {
      if (!std::filesystem::exists(std::filesystem::symlink_status(path, error))) throw;
    }
  }
  throw Error(normal.string() + ": no free name for a new scene file beside it");
}

}  // namespace

void Viewer::mouse_button(int button, int action, int mods) {
  const bool left = button == GLFW_MOUSE_BUTTON_LEFT && !(mods & GLFW_MOD_SHIFT);
  try {
    // A press on a cut-away's handle drags it (before placing labels and turning the camera).
    if (!(mods & GLFW_MOD_SHIFT) && press_cut_handle(button, action)) return;
    // Place mode: a press on an anchor drags it along the surface under the pointer, elsewhere
    // a press places a label (both once the frame's pick comes back: no wait).
    if (place_mode_ && left && action == GLFW_PRESS && drag_button_ < 0) {
      anchor_drag_.reset();
      if (const std::optional<size_t> i = label_near(mouse_, true)) {
        anchor_drag_ = scene_.labels[*i].id;
        anchor_drag_from_ = mouse_;
        drag_undone_ = false;
        select_label(*i);
      } else {
        ask_pick({mouse_, {}, false});
      }
      return;
    }
    if (left && action == GLFW_RELEASE && anchor_drag_) {
      if (glm::distance(mouse_, anchor_drag_from_) > 2.0f) ask_pick({mouse_, *anchor_drag_, true});
      anchor_drag_.reset();
      return;
    }
    if (place_mode_ && left) return;
    // Otherwise the camera; a click (no movement) on a label's box or anchor selects it.
    if (left && action == GLFW_RELEASE && button == drag_button_ &&
        glm::distance(mouse_, press_at_) <= 2.0f) {
      std::optional<size_t> i = label_near(mouse_, false);
      if (!i) i = label_near(mouse_, true);
      if (i) select_label(*i);
    }
  } catch (const Error& e) {
    message_ = e.what();
    ui_event();
    anchor_drag_.reset();
    return;
  }
  if (action == GLFW_PRESS && drag_button_ < 0) {
    press_at_ = mouse_;
    drag_button_ = button;
    drag_pan_ = button == GLFW_MOUSE_BUTTON_MIDDLE ||
                (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_SHIFT));
  } else if (action == GLFW_RELEASE && button == drag_button_) {
    drag_button_ = -1;
  }
}

void Viewer::cursor(glm::vec2 position) {
  const glm::vec2 delta = position - mouse_;
  mouse_ = position;
  // (an anchor follows the pointer: one pick in flight at a time, the newest position next)
  if (anchor_drag_ && delta != glm::vec2(0.0f) && glm::distance(mouse_, anchor_drag_from_) > 2.0f &&
      std::none_of(pending_picks_.begin(), pending_picks_.end(),
                   [](const PendingPick& p) { return p.drag; })) {
    ask_pick({mouse_, *anchor_drag_, true});
  }
  if (handle_drag_) return drag_cut_handle(delta);
  if (cuts_.crop || !cuts_.planes.empty()) {  // (the handle under the pointer is drawn larger)
    const std::optional<int> hovered = cut_handle_near(mouse_);
    if (hovered != hovered_handle_) hovered_handle_ = hovered, ui_event();
  }
  if (drag_button_ < 0 || delta == glm::vec2(0.0f)) return;
  const graph::Extent e = output_.extent();
  const glm::uvec2 viewport{std::max(1u, e.width), std::max(1u, e.height)};
  if (drag_pan_) {
    control_.pan(delta, viewport);
  } else if (drag_button_ == GLFW_MOUSE_BUTTON_LEFT) {
    control_.rotate(delta, viewport);
  } else if (drag_button_ == GLFW_MOUSE_BUTTON_RIGHT) {
    control_.zoom_drag(delta.y, viewport);
  }
}

void Viewer::scroll(double ticks) {
  control_.zoom_wheel(ticks);
}

void Viewer::key(int key, int mods) {
  try {
    if (mods & GLFW_MOD_CONTROL) {
      if (key == GLFW_KEY_Z && !(mods & GLFW_MOD_SHIFT)) submit(viewer_command({"undo"}));
      if (key == GLFW_KEY_Y || (key == GLFW_KEY_Z && (mods & GLFW_MOD_SHIFT)))
        submit(viewer_command({"redo"}));
      if (key == GLFW_KEY_S) submit(viewer_command({"save", default_labels_path().string()}));
      return;
    }
    if (const std::optional<std::string> name = key_name(key))
      submit(viewer_command({"key", *name}));
  } catch (const Error& e) {
    message_ = e.what();
  }
}

void Viewer::press_key(int key) {
  switch (key) {
    case GLFW_KEY_P:
      set_place_mode(!place_mode_);
      break;
    case GLFW_KEY_Q:
    case GLFW_KEY_ESCAPE:
      quit_ = true;
      break;
    case GLFW_KEY_LEFT:
      control_.rotate_step(-1, 0);
      break;
    case GLFW_KEY_RIGHT:
      control_.rotate_step(1, 0);
      break;
    case GLFW_KEY_UP:
      control_.rotate_step(0, 1);
      break;
    case GLFW_KEY_DOWN:
      control_.rotate_step(0, -1);
      break;
    case GLFW_KEY_R:
      reset_camera();
      break;
    case GLFW_KEY_F12:
      screenshot();
      break;
    case GLFW_KEY_H:
      options_.show_panel = !options_.show_panel;
      ui_event();
      break;
    default:
      if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9) jump_to_position(size_t(key - GLFW_KEY_1));
      break;
  }
}

// --- actions -----------------------------------------------------------------------------------

void Viewer::jump_to_position(size_t index) {
  const std::optional<Camera> goal = numbered_position(scene_, index);
  if (!goal) {
    message_ = "the scene has no position " + std::to_string(index + 1);
    ui_event();
    return;
  }
  control_.animate_to(*goal, kAnimationSeconds);
}

void Viewer::view_from(AnatomicalView view) {
  control_.animate_to(control_.view_from(view), kAnimationSeconds);
}

void Viewer::reset_camera() {
  control_.reset();
}

// A strata .json scene is written back to itself; anything else gets a new scene file of its
// own (never a file that is there already: scan.json may be a transfer function).
void Viewer::save_position(const std::string& name) {
  const std::string chosen = name.empty() ? new_position_name(scene_) : name;
  for (const CameraPose& p : scene_.camera_positions) {
    if (p.name == chosen) throw Error("the scene already has a position '" + chosen + "'");
  }
  scene_.camera_positions.push_back(control_.pose(chosen));
  try {
    if (!saved_scene_path_.empty()) {
      save_scene_json(saved_scene_path_, scene_);
      message_ = "saved position '" + chosen + "' in " + saved_scene_path_.string();
    } else if (!scene_.source_json.empty()) {
      save_scene_json(options_.scene_path, scene_);
      saved_scene_path_ = options_.scene_path;
      message_ = "saved position '" + chosen + "' in " + saved_scene_path_.string();
    } else {
      saved_scene_path_ = save_new_scene_file(options_.scene_path, scene_);
      message_ = "saved position '" + chosen + "' in a new scene file " +
                 saved_scene_path_.string() + " (" + options_.scene_path.string() +
                 " is not a strata scene)";
    }
  } catch (const Error&) {
    scene_.camera_positions.pop_back();  // not saved: a later save must not write it unasked
    throw;
  }
  std::printf("view: %s\n", message_.c_str());
  ui_event();
}

}  // namespace strata::app
