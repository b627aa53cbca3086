// Labels of one's own (docs/viewer.md): picked, placed, moved, renamed, deleted, undone and
// saved; a scene label hidden or shown.
#include "app/viewer/viewer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "engine/scene/atlas.h"
#include "engine/scene/io/scene_loader.h"
#include "engine/scene/value_limits.h"

namespace strata::app {
namespace {

// What a label file can hold (label_file_writer.h decides UTF-8 by nlohmann's rules too).
bool is_utf8(const std::string& text) {
  try {
    (void)nlohmann::json(text).dump();
    return true;
  } catch (const nlohmann::json::type_error&) {
    return false;
  }
}

}  // namespace

void Viewer::set_label_hidden(int id, bool hidden) {
  for (size_t i = 0; i < scene_.labels.size(); ++i) {
    if (scene_.labels[i].id != id) continue;
    labelled_->set_label_hidden(i, hidden);
    changed();
    return;
  }
  throw Error("the scene has no label " + std::to_string(id));
}

void Viewer::ask_pick(const PendingPick& pick) {
  const graph::Extent e = labelled_->size();
  const glm::vec2 at = pick.at;
  if (!(at.x >= 0.0f && at.y >= 0.0f && at.x < float(e.width) && at.y < float(e.height))) {
    throw Error("pixel " + value_limits::shown(at.x) + "," + value_limits::shown(at.y) +
                " lies outside the " + std::to_string(e.width) + "x" + std::to_string(e.height) +
                " picture");
  }
  labelled_->request_pick(at);
  pending_picks_.push_back(pick);
}

// The picks come back with their frame's slot: each places or moves its label now. Where the ray
// met only background the message says so (and pick_now throws it).
void Viewer::apply_picks() {
  for (const PickHit& hit : labelled_->take_picks()) {
    if (pending_picks_.empty()) break;
    const PendingPick pick = pending_picks_.front();
    pending_picks_.pop_front();
    if (!hit.hit) {
      const std::string what =
          !pick.move_id
              ? "nothing under the pixel to place a label on (background)"
              : "nothing under the pixel to move label " + std::to_string(*pick.move_id) + " to";
      missed_pick_ = what;
      if (!pick.drag) message_ = what;  // (a drag over the background: the anchor waits)
      ui_event();
      continue;
    }
    if (!pick.move_id) {
      add_label(hit.point);
    } else if (std::any_of(scene_.labels.begin(), scene_.labels.end(),
                           [&](const Label& l) { return l.id == *pick.move_id; })) {
      // (a drag is one edit to undo: the labels before its first move)
      const size_t i = label_index(*pick.move_id);
      edit_labels([&](std::vector<Label>& labels) { labels[i].anchor = hit.point; },
                  !pick.drag || !drag_undone_);
      drag_undone_ = drag_undone_ || pick.drag;
    }
  }
}

// A pick for a script or a benchmark: asked, then frames until it comes back.
void Viewer::pick_now(const PendingPick& pick) {
  ask_pick(pick);
  missed_pick_.reset();
  for (int frames = 0; !pending_picks_.empty(); ++frames) {
    if (frames > 16) throw Error("the pick did not come back within 16 frames");
    frame();
  }
  if (missed_pick_) throw Error(*missed_pick_);
}

size_t Viewer::label_index(int id) const {
  for (size_t i = 0; i < scene_.labels.size(); ++i)
    if (scene_.labels[i].id == id) return i;
  throw Error("the scene has no label " + std::to_string(id));
}

void Viewer::edit_labels(const std::function<void(std::vector<Label>&)>& edit, bool undoable) {
  std::vector<Label> before = scene_.labels;
  edit(scene_.labels);
  if (undoable) history_.edited(std::move(before));
  labelled_->labels_changed();
  moving_labels_.clear();
  if (picked_label_ >= int(scene_.labels.size())) picked_label_ = -1;
  changed();
  ui_event();
}

int Viewer::place_label(glm::vec2 at) {
  const size_t labels = scene_.labels.size();
  pick_now({at, {}, false});
  if (scene_.labels.size() == labels) throw Error("no label was placed");
  return scene_.labels.back().id;
}

void Viewer::add_label(glm::vec3 point) {
  Label label;
  label.id = unused_label_ids(scene_.labels, 1).front();
  label.anchor = point;
  label.text = atlas_region_at(scene_, point);
  if (label.text.empty()) label.text = "Label " + std::to_string(label.id);
  edit_labels([&](std::vector<Label>& labels) { labels.push_back(label); });
  picked_label_ = int(scene_.labels.size()) - 1;  // (selected: its text ready to edit)
  std::snprintf(edit_text_, sizeof edit_text_, "%s", label.text.c_str());
  message_ = "placed '" + label.text + "' (label " + std::to_string(label.id) + ")";
  if (options_.print_actions) {
    std::printf("view: %s\n", message_.c_str());
    std::fflush(stdout);
  }
}

void Viewer::set_label_text(int id, const std::string& text) {
  const size_t i = label_index(id);
  if (text.empty()) throw Error("a label's text cannot be empty");
  if (!is_utf8(text)) throw Error("label " + std::to_string(id) + ": the text is not UTF-8");
  edit_labels([&](std::vector<Label>& labels) { labels[i].text = text; });
}

void Viewer::move_label(int id, glm::vec2 at) {
  label_index(id);  // (an Error when there is no such label)
  pick_now({at, id, false});
}

void Viewer::delete_label(int id) {
  const size_t i = label_index(id);
  edit_labels([&](std::vector<Label>& labels) { labels.erase(labels.begin() + ptrdiff_t(i)); });
}

// After an undo or redo: the labels came back.
bool Viewer::restored_labels(bool done) {
  if (!done) return false;
  if (picked_label_ >= int(scene_.labels.size())) picked_label_ = -1;
  labelled_->labels_changed();
  changed();
  return true;
}

bool Viewer::undo_labels() {
  return restored_labels(history_.undo(scene_.labels));
}

bool Viewer::redo_labels() {
  return restored_labels(history_.redo(scene_.labels));
}

void Viewer::save_labels(const std::filesystem::path& path, LabelAxes axes) {
  // (the scene's own labels stay in its file: loaded with it, the saved ones are not doubled)
  std::vector<Label> own;
  for (const Label& label : scene_.labels) {
    if (std::none_of(scene_labels_.begin(), scene_labels_.end(),
                     [&](const Label& l) { return l.id == label.id && same_label(l, label); }))
      own.push_back(label);
  }
  write_label_file(path, own, axes);
  message_ = "wrote " + std::to_string(own.size()) + " labels to " + path.string() +
             (axes == LabelAxes::lps ? " (LPS)" : " (RAS)") + ", placed or edited; the scene's " +
             std::to_string(scene_.labels.size() - own.size()) + " stay in its file";
  std::printf("view: %s\n", message_.c_str());
  std::fflush(stdout);
  ui_event();
}

std::filesystem::path Viewer::default_labels_path() const {
  std::filesystem::path path = options_.scene_path;
  std::string stem = path.filename().string();
  for (const char* extension : {".json", ".nii.gz", ".nii", ".nrrd", ".mhd", ".mha", ".xml"}) {
    const std::string e = extension;
    if (stem.size() > e.size() && stem.compare(stem.size() - e.size(), e.size(), e) == 0) {
      stem.resize(stem.size() - e.size());
      break;
    }
  }
  return path.replace_filename(stem + "-labels.mrk.json");
}

// The label whose anchor (an enabled label's, within 6 pixels; the nearest) or drawn box (as the
// last frame read back drew it) holds `at`.
std::optional<size_t> Viewer::label_near(glm::vec2 at, bool anchor) const {
  const std::vector<gpu::LabelGpu>& labels = labelled_->labels();
  const std::span<const gpu::PlacementGpu> drawn = labelled_->drawn();
  std::optional<size_t> found;
  float nearest = 6.0f;
  for (size_t i = 0; i < labels.size(); ++i) {
    if ((labels[i].flags & LABEL_ENABLED) == 0u) continue;
    if (anchor) {
      const float d = glm::distance(at, labels[i].anchor);
      if (d <= nearest) {
        nearest = d;
        found = i;
      }
    } else if (i < drawn.size() && drawn[i].shown == PLACEMENT_SHOWN && drawn[i].opacity > 0.0f &&
               glm::all(
                   glm::lessThanEqual(glm::abs(at - drawn[i].position), 0.5f * labels[i].size))) {
      found = i;
    }
  }
  return found;
}

void Viewer::select_label(size_t index) {
  if (index >= scene_.labels.size()) return;
  picked_label_ = int(index);
  std::snprintf(edit_text_, sizeof edit_text_, "%s", scene_.labels[index].text.c_str());
  message_ = "selected '" + scene_.labels[index].text + "' (label " +
             std::to_string(scene_.labels[index].id) + ")";
  ui_event();
}

void Viewer::set_place_mode(bool on) {
  place_mode_ = on;
  message_ = on ? "place mode: a click places a label (P: off)" : "place mode off";
  ui_event();
}

}  // namespace strata::app
