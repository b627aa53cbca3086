// The viewer's own cut-aways: a crop box and a clipping plane on every volume, set from the panel,
// from a script, or by dragging their handles in the picture (ParaView's box and plane widgets).
#include <algorithm>
#include <cmath>

#include <GLFW/glfw3.h>
#include <imgui.h>

#include "app/viewer/viewer.h"
#include "engine/core/error.h"
#include "engine/scene/scene_bounds.h"

namespace strata::app {

namespace {

constexpr float kHandleRadius = 5.0f;  // pixels; a press within 2 radii takes a handle
const ImU32 kCropColour = IM_COL32(255, 200, 60, 220);
const ImU32 kPlaneColour = IM_COL32(80, 220, 255, 220);

// The six directions a plane's kept side may face in the panel (LPS: +x left, +y posterior,
// +z superior), and the view's.
struct Side {
  const char* name;
  glm::vec3 normal;
};
constexpr Side kSides[] = {{"keep left (L)", {1, 0, 0}},      {"keep right (R)", {-1, 0, 0}},
                           {"keep posterior (P)", {0, 1, 0}}, {"keep anterior (A)", {0, -1, 0}},
                           {"keep superior (S)", {0, 0, 1}},  {"keep inferior (I)", {0, 0, -1}}};

glm::vec3 box_corner(const std::array<glm::vec3, 2>& b, int k) {
  return {b[(k & 1) ? 1 : 0].x, b[(k & 2) ? 1 : 0].y, b[(k & 4) ? 1 : 0].z};
}

// Where the plane (n, w) meets the box: its corners in order around n (none when it misses).
std::vector<glm::vec3> plane_in_box(glm::vec4 plane, const std::array<glm::vec3, 2>& box) {
  const glm::vec3 n(plane);
  std::vector<glm::vec3> points;
  for (int c = 0; c < 8; ++c) {
    for (int axis = 0; axis < 3; ++axis) {
      if (c & (1 << axis)) continue;
      const glm::vec3 a = box_corner(box, c), b = box_corner(box, c | (1 << axis));
      const float sa = glm::dot(n, a) + plane.w, sb = glm::dot(n, b) + plane.w;
      if ((sa < 0.0f) != (sb < 0.0f)) points.push_back(a + (b - a) * (sa / (sa - sb)));
    }
  }
  if (points.size() < 3) return {};
  glm::vec3 centre(0.0f);
  for (const glm::vec3& p : points) centre += p / float(points.size());
  const glm::vec3 u = glm::normalize(glm::abs(n.x) < 0.9f ? glm::cross(n, glm::vec3(1, 0, 0))
                                                          : glm::cross(n, glm::vec3(0, 1, 0)));
  const glm::vec3 v = glm::cross(n, u);
  std::sort(points.begin(), points.end(), [&](glm::vec3 p, glm::vec3 q) {
    return std::atan2(glm::dot(p - centre, v), glm::dot(p - centre, u)) <
           std::atan2(glm::dot(q - centre, v), glm::dot(q - centre, u));
  });
  return points;
}

std::array<glm::vec3, 2> content_box(const Scene& scene) {
  const Bounds b = scene_bounds(scene);
  return {b.lo, b.hi};
}

// The plane's position along its normal: from the lowest to the highest corner of the box.
glm::vec2 plane_range(glm::vec3 normal, const std::array<glm::vec3, 2>& box) {
  glm::vec2 range(INFINITY, -INFINITY);
  for (int k = 0; k < 8; ++k) {
    const float d = glm::dot(normal, box_corner(box, k));
    range = {std::min(range.x, d), std::max(range.y, d)};
  }
  return range;
}

}  // namespace

void Viewer::set_crop(std::optional<std::array<glm::vec3, 2>> box) {
  if (box && !glm::all(glm::lessThan((*box)[0], (*box)[1])))
    throw Error("crop box: each low corner value must be below the high one");
  ViewerCuts cuts = cuts_;
  cuts.crop = box;
  apply_cuts(cuts);
}

void Viewer::add_clip(glm::vec4 plane) {
  if (!clip_normal_usable(glm::vec3(plane)) || !std::isfinite(plane.w))
    throw Error("clipping plane: the normal must not be zero");
  const float length = glm::length(glm::vec3(plane));
  if (cuts_.planes.size() >= kViewerPlanes)
    throw Error("clipping plane: the viewer keeps at most " + std::to_string(kViewerPlanes));
  ViewerCuts cuts = cuts_;
  cuts.planes.push_back(plane / length);
  apply_cuts(cuts);
}

void Viewer::clear_clips() {
  ViewerCuts cuts = cuts_;
  cuts.planes.clear();
  apply_cuts(cuts);
}

void Viewer::apply_cuts(const ViewerCuts& cuts) {
  std::vector<glm::vec4> own;
  if (cuts.crop) own = crop_planes((*cuts.crop)[0], (*cuts.crop)[1]);
  own.insert(own.end(), cuts.planes.begin(), cuts.planes.end());
  for (size_t v = 0; v < scene_.volumes.size(); ++v) {
    if (scene_cuts_[v].size() + own.size() > kMaxCutPlanes)
      throw Error("volume '" + scene_.volumes[v].name + "': its " +
                  std::to_string(scene_cuts_[v].size()) + " cut-away planes and the viewer's " +
                  std::to_string(own.size()) + " are more than " + std::to_string(kMaxCutPlanes));
  }
  cuts_ = cuts;
  // (the volumes' records are copied at the start of the next frame, after the frames in flight:
  // nothing waits)
  Uploads uploads;
  for (size_t v = 0; v < scene_.volumes.size(); ++v) {
    std::vector<glm::vec4> cut = scene_cuts_[v];
    cut.insert(cut.end(), own.begin(), own.end());
    scene_.volumes[v].cut = std::move(cut);
    labelled_->renderer().set_cut(uint32_t(v), scene_.volumes[v], &uploads);
  }
  labelled_->runner().upload_in_next_frame(std::move(uploads));
  settings_changed(true);  // (labels whose anchors are cut away hide)
}

std::vector<std::optional<Viewer::CutHandle>> Viewer::cut_handles(const ViewerCuts& cuts) const {
  std::vector<std::optional<CutHandle>> handles(6);
  if (cuts.crop) {
    const std::array<glm::vec3, 2>& b = *cuts.crop;
    for (int face = 0; face < 6; ++face) {
      const int axis = face / 2, side = face % 2;
      glm::vec3 at = 0.5f * (b[0] + b[1]);
      at[axis] = b[side][axis];
      glm::vec3 direction(0.0f);
      direction[axis] = 1.0f;
      handles[size_t(face)] = CutHandle{at, direction};
    }
  }
  const std::array<glm::vec3, 2> box = content_box(scene_);
  for (const glm::vec4& plane : cuts.planes) {
    const glm::vec3 n(plane);
    const std::vector<glm::vec3> polygon = plane_in_box(plane, box);
    glm::vec3 at = 0.5f * (box[0] + box[1]);
    at -= n * (glm::dot(n, at) + plane.w);  // (the content's centre on the plane)
    if (!polygon.empty()) {
      at = glm::vec3(0.0f);
      for (const glm::vec3& p : polygon) at += p / float(polygon.size());
    }
    handles.push_back(CutHandle{at, n});
  }
  return handles;
}

std::optional<int> Viewer::cut_handle_near(glm::vec2 at) const {
  const graph::Extent e = labelled_->size();
  const Camera camera = control_.camera();
  std::optional<int> found;
  float nearest = 2.0f * kHandleRadius;
  const auto handles = cut_handles(cuts_);
  for (size_t i = 0; i < handles.size(); ++i) {
    if (!handles[i]) continue;
    const ProjectedPoint p = project(camera, handles[i]->at, {e.width, e.height});
    if (p.eye_depth <= camera.near_plane) continue;
    const float d = glm::distance(p.pixel, at);
    if (d <= nearest) nearest = d, found = int(i);
  }
  return found;
}

bool Viewer::press_cut_handle(int button, int action) {
  if (button != GLFW_MOUSE_BUTTON_LEFT) return false;
  if (action == GLFW_PRESS && drag_button_ < 0 && !handle_drag_) {
    handle_drag_ = cut_handle_near(mouse_);
    if (handle_drag_) cuts_dragged_ = cuts_;
    return handle_drag_.has_value();
  }
  if (action == GLFW_RELEASE && handle_drag_) {
    const ViewerCuts dragged = cuts_dragged_.value_or(cuts_);
    handle_drag_.reset();
    cuts_dragged_.reset();
    apply_cuts(dragged);
    return true;
  }
  return false;
}

// A handle follows the pointer along its direction as the picture shows it: the pointer's move
// along the direction's image, in millimetres.
void Viewer::drag_cut_handle(glm::vec2 delta) {
  if (!handle_drag_ || !cuts_dragged_) return;
  ViewerCuts& cuts = *cuts_dragged_;
  const std::vector<std::optional<CutHandle>> handles = cut_handles(cuts);
  if (size_t(*handle_drag_) >= handles.size() || !handles[size_t(*handle_drag_)]) return;
  const std::optional<CutHandle>& handle = handles[size_t(*handle_drag_)];
  const graph::Extent e = labelled_->size();
  const Camera camera = control_.camera();
  const ProjectedPoint from = project(camera, handle->at, {e.width, e.height});
  const ProjectedPoint to = project(camera, handle->at + handle->direction, {e.width, e.height});
  const glm::vec2 per_mm = to.pixel - from.pixel;
  if (glm::dot(per_mm, per_mm) < 1e-4f || from.eye_depth <= camera.near_plane ||
      to.eye_depth <= camera.near_plane)
    return;  // (the direction points at the eye: the handle stays)
  const float mm = glm::dot(delta, per_mm) / glm::dot(per_mm, per_mm);
  ui_event();  // (drawn where it is dragged to)
  const std::array<glm::vec3, 2> content = content_box(scene_);
  if (*handle_drag_ < 6) {
    std::array<glm::vec3, 2>& b = *cuts.crop;
    const int axis = *handle_drag_ / 2, side = *handle_drag_ % 2;
    const float least = std::max(0.001f, (content[1][axis] - content[0][axis]) / 400.0f);
    float& face = b[size_t(side)][axis];
    face = side == 0 ? std::clamp(face + mm, std::min(content[0][axis], b[1][axis] - least),
                                  b[1][axis] - least)
                     : std::clamp(face + mm, b[0][axis] + least,
                                  std::max(content[1][axis], b[0][axis] + least));
  } else {
    glm::vec4& plane = cuts.planes.at(size_t(*handle_drag_ - 6));
    const glm::vec2 range = plane_range(glm::vec3(plane), content);
    plane.w = -std::clamp(-plane.w + mm, range.x, range.y);
  }
}

void Viewer::panel_cut_aways() {
  const std::array<glm::vec3, 2> content = content_box(scene_);
  ViewerCuts cuts = cuts_dragged_ ? *cuts_dragged_ : cuts_;
  bool crop_on = cuts.crop.has_value();
  bool edited = ImGui::Checkbox("crop box", &crop_on);
  if (crop_on) {
    std::array<glm::vec3, 2> box = cuts.crop.value_or(content);
    const char* names[3] = {"x (L)", "y (P)", "z (S)"};
    for (int a = 0; a < 3; ++a) {
      const float step = std::max(0.001f, (content[1][a] - content[0][a]) / 400.0f);
      edited |= ImGui::DragFloatRange2(names[a], &box[0][a], &box[1][a], step, content[0][a],
                                       content[1][a], "%.1f mm");
      box[1][a] = std::max(box[1][a], box[0][a] + step);
    }
    cuts.crop = box;
  } else {
    cuts.crop.reset();
  }
  const glm::vec3 centre = 0.5f * (content[0] + content[1]);
  const auto through_centre = [&](glm::vec3 n) { return glm::vec4(n, -glm::dot(n, centre)); };
  const glm::vec3 forward = -glm::vec3(glm::inverse(control_.camera().view)[2]);
  for (size_t i = 0; i < cuts.planes.size(); ++i) {
    ImGui::PushID(int(i));
    glm::vec4& plane = cuts.planes[i];
    ImGui::Text("clipping plane %zu", i + 1);
    ImGui::SameLine();
    if (ImGui::SmallButton("remove")) {
      cuts.planes.erase(cuts.planes.begin() + long(i));
      edited = true;
      ImGui::PopID();
      break;
    }
    const auto side = std::find_if(std::begin(kSides), std::end(kSides), [&](const Side& s) {
      return glm::dot(s.normal, glm::vec3(plane)) > 0.9999f;
    });
    if (ImGui::BeginCombo("side",
                          side == std::end(kSides) ? "keep the far side of a view" : side->name)) {
      for (const Side& s : kSides) {
        if (ImGui::Selectable(s.name, &s == side)) plane = through_centre(s.normal), edited = true;
      }
      if (ImGui::Selectable("keep the far side of this view"))
        plane = through_centre(forward), edited = true;
      ImGui::EndCombo();
    }
    const glm::vec2 range = plane_range(glm::vec3(plane), content);
    float position = -plane.w;
    if (ImGui::DragFloat("position", &position, std::max(0.001f, (range.y - range.x) / 400.0f),
                         range.x, range.y, "%.1f mm")) {
      plane.w = -position;
      edited = true;
    }
    ImGui::PopID();
  }
  ImGui::BeginDisabled(cuts.planes.size() >= kViewerPlanes);
  if (ImGui::Button("add a clipping plane")) {  // (through the centre: the near half cut away)
    cuts.planes.push_back(through_centre(forward));
    edited = true;
  }
  ImGui::EndDisabled();
  ImGui::TextDisabled("or drag the handles in the picture");
  if (edited) cuts_dragged_ = cuts;
  if (cuts_dragged_ && !handle_drag_ && !ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
    const ViewerCuts applied = *cuts_dragged_;
    cuts_dragged_.reset();
    apply_cuts(applied);
  }
}

// The crop box's twelve edges and the plane's outline in the content's box over the picture,
// with their handles, while they are on (drawn as dragged, before they apply).
void Viewer::draw_cut_aways() {
  const ViewerCuts& cuts = cuts_dragged_ ? *cuts_dragged_ : cuts_;
  if (!cuts.crop && cuts.planes.empty()) return;
  const graph::Extent e = labelled_->size();
  const Camera camera = control_.camera();
  ImDrawList* draw = ImGui::GetBackgroundDrawList();
  const auto line = [&](glm::vec3 a, glm::vec3 b, ImU32 colour) {
    const ProjectedPoint p = project(camera, a, {e.width, e.height});
    const ProjectedPoint q = project(camera, b, {e.width, e.height});
    if (p.eye_depth <= camera.near_plane || q.eye_depth <= camera.near_plane) return;
    draw->AddLine(ImVec2(p.pixel.x, p.pixel.y), ImVec2(q.pixel.x, q.pixel.y), colour, 1.5f);
  };
  if (cuts.crop) {
    for (int c = 0; c < 8; ++c) {
      for (int axis = 0; axis < 3; ++axis) {
        if (!(c & (1 << axis)))
          line(box_corner(*cuts.crop, c), box_corner(*cuts.crop, c | (1 << axis)), kCropColour);
      }
    }
  }
  for (const glm::vec4& plane : cuts.planes) {
    const std::vector<glm::vec3> polygon = plane_in_box(plane, content_box(scene_));
    for (size_t i = 0; i < polygon.size(); ++i)
      line(polygon[i], polygon[(i + 1) % polygon.size()], kPlaneColour);
  }
  const auto handles = cut_handles(cuts);
  const std::optional<int> hovered = handle_drag_ ? handle_drag_ : hovered_handle_;
  for (size_t i = 0; i < handles.size(); ++i) {
    if (!handles[i]) continue;
    const ProjectedPoint p = project(camera, handles[i]->at, {e.width, e.height});
    if (p.eye_depth <= camera.near_plane) continue;
    const float radius = hovered == int(i) ? 1.5f * kHandleRadius : kHandleRadius;
    draw->AddCircleFilled(ImVec2(p.pixel.x, p.pixel.y), radius, i < 6 ? kCropColour : kPlaneColour);
  }
}

}  // namespace strata::app
