#include "engine/scene/fitted_camera.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/scene/scene_bounds.h"

namespace strata {
namespace {

constexpr double kMargin = 1.05;  // the box's projection fills 95% of the view

// The content's box (or what the cut-aways keep of it); without volumes or meshes the labels'
// anchors, then a unit box, so a camera always exists.
Bounds content_bounds(const Scene& scene, FitTo fit = FitTo::content) {
  Bounds bounds = fit == FitTo::kept ? kept_bounds(scene) : scene_bounds(scene);
  if (bounds.empty() && fit == FitTo::kept) bounds = scene_bounds(scene);  // all cut away
  if (bounds.empty()) {
    for (const Label& label : scene.labels) bounds.add(label.anchor);
  }
  if (bounds.empty() || bounds.lo == bounds.hi) {
    const glm::vec3 c = bounds.centre();
    bounds.add(c - glm::vec3(0.5f));
    bounds.add(c + glm::vec3(0.5f));
  }
  return bounds;
}

// The eye's distance from the box's centre at which every corner lies inside the view cone.
double fitting_distance(const Bounds& bounds, const ViewSide& side, double half_fov) {
  const glm::dvec3 centre(bounds.centre());
  const glm::dvec3 right = glm::normalize(glm::cross(-side.eye_direction, side.up));
  const glm::dvec3 up = glm::cross(right, -side.eye_direction);  // (side.up tilted, for obliques)
  double distance = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec3 p((corner & 1) ? bounds.hi.x : bounds.lo.x,
                       (corner & 2) ? bounds.hi.y : bounds.lo.y,
                       (corner & 4) ? bounds.hi.z : bounds.lo.z);
    const glm::dvec3 d = p - centre;
    const double lateral = std::max(std::abs(glm::dot(d, right)), std::abs(glm::dot(d, up)));
    distance = std::max(distance,
                        glm::dot(d, side.eye_direction) + kMargin * lateral / std::tan(half_fov));
  }
  return distance;
}

// The words of an oblique view's name, by axis (front, side, height), each pair's first the
// positive sense of `oblique`'s arguments.
constexpr const char* kSideWords[3][2] = {
    {"anterior", "posterior"}, {"left", "right"}, {"superior", "inferior"}};

// "anterior-right-superior" for the words' indices {0, 1, 0}.
std::string oblique_name(const int (&which)[3]) {
  return std::string(kSideWords[0][which[0]]) + "-" + kSideWords[1][which[1]] + "-" +
         kSideWords[2][which[2]];
}

// A three-quarter view: `front` (+-1: anterior or posterior), `side` (+-1: left or right) and
// `height` (+-1: superior or inferior) in LPS, 45 degrees round and 30 up or down.
StandardView oblique(int front, int side, int height) {
  const double round = std::sqrt(0.5) * std::cos(glm::radians(30.0));
  const glm::dvec3 eye(side * round, -front * round, height * std::sin(glm::radians(30.0)));
  return {oblique_name({front < 0, side < 0, height < 0}), {eye, glm::dvec3(0, 0, 1)}};
}

glm::mat4 look_from(const Bounds& bounds, const ViewSide& side, float fov_y_degrees) {
  const double distance = fitting_distance(bounds, side, glm::radians(double(fov_y_degrees)) / 2.0);
  const glm::dvec3 centre(bounds.centre());
  return glm::mat4(glm::lookAt(centre + side.eye_direction * distance, centre, side.up));
}

// "ars", "right-superior-anterior": an oblique view's initials or words, one of each pair, in
// any order; "" for anything else.
std::string oblique_named(std::string_view name) {
  std::vector<std::string_view> parts;
  if (name.size() == 3) {
    for (size_t i = 0; i < 3; ++i) parts.push_back(name.substr(i, 1));
  } else {
    for (size_t start = 0;;) {
      const size_t dash = name.find('-', start);
      parts.push_back(name.substr(start, dash == std::string_view::npos ? dash : dash - start));
      if (dash == std::string_view::npos) break;
      start = dash + 1;
    }
  }
  if (parts.size() != 3) return "";
  int chosen[3] = {-1, -1, -1};
  for (std::string_view part : parts) {
    bool found = false;
    for (int axis = 0; axis < 3 && !found; ++axis) {
      for (int which = 0; which < 2 && !found; ++which) {
        const std::string_view word = kSideWords[axis][which];
        if ((part.size() == 1 ? word.substr(0, 1) : word) != part || chosen[axis] >= 0) continue;
        chosen[axis] = which;
        found = true;
      }
    }
    if (!found) return "";
  }
  return oblique_name(chosen);
}

}  // namespace

const char* to_string(AnatomicalView view) {
  return kAnatomicalViewNames[static_cast<size_t>(view)];
}

std::optional<AnatomicalView> anatomical_view_named(std::string_view name) {
  for (size_t i = 0; i < kAnatomicalViewNames.size(); ++i) {
    if (name == kAnatomicalViewNames[i]) return AnatomicalView(i);
  }
  return std::nullopt;
}

// Slicer's lookFromAxis is in RAS; strata's LPS has x and y negated.
ViewSide side_of(AnatomicalView view) {
  const glm::dvec3 superior(0, 0, 1), anterior(0, -1, 0), left(1, 0, 0);
  switch (view) {
    case AnatomicalView::anterior:
      return {anterior, superior};
    case AnatomicalView::posterior:
      return {-anterior, superior};
    case AnatomicalView::left:
      return {left, superior};
    case AnatomicalView::right:
      return {-left, superior};
    case AnatomicalView::superior:
      return {superior, anterior};
    case AnatomicalView::inferior:
      return {-superior, anterior};
  }
  return {anterior, superior};
}

const std::vector<StandardView>& standard_views() {
  static const std::vector<StandardView> views = [] {
    std::vector<StandardView> out;
    for (size_t v = 0; v < kAnatomicalViewNames.size(); ++v)
      out.push_back({kAnatomicalViewNames[v], side_of(AnatomicalView(v))});
    for (int height : {1, -1})
      for (int front : {1, -1})
        for (int side : {1, -1}) out.push_back(oblique(front, side, height));
    return out;
  }();
  return views;
}

std::optional<std::string> standard_view_name(std::string_view name) {
  static const std::pair<const char*, const char*> others[] = {{"front", "anterior"},
                                                               {"back", "posterior"},
                                                               {"top", "superior"},
                                                               {"bottom", "inferior"},
                                                               {"oblique", kObliqueViewName}};
  if (anatomical_view_named(name)) return std::string(name);
  for (const auto& [other, view] : others)
    if (name == other) return std::string(view);
  const std::string named = oblique_named(name);
  if (named.empty()) return std::nullopt;
  return named;
}

glm::mat4 fitted_view(const Scene& scene, AnatomicalView view, float fov_y_degrees) {
  return look_from(content_bounds(scene), side_of(view), fov_y_degrees);
}

glm::mat4 refitted_view(const Scene& scene, const glm::mat4& view, float fov_y_degrees, FitTo fit) {
  const glm::dmat3 to_world = glm::transpose(glm::dmat3(glm::dmat4(view)));
  const ViewSide side{glm::normalize(to_world[2]), glm::normalize(to_world[1])};
  return look_from(content_bounds(scene, fit), side, fov_y_degrees);
}

AnatomicalPositions anatomical_positions(const Scene& scene, float fov_y_degrees, FitTo fit) {
  AnatomicalPositions out;
  const Bounds bounds = content_bounds(scene, fit), whole = content_bounds(scene);
  const double radius = 0.5 * glm::length(glm::dvec3(whole.hi - whole.lo));
  double nearest = std::numeric_limits<double>::max(), farthest = 0.0;
  const double half_fov = glm::radians(double(fov_y_degrees)) / 2.0;
  const glm::dvec3 shift = glm::dvec3(whole.centre()) - glm::dvec3(bounds.centre());
  for (const StandardView& v : standard_views()) {
    const glm::mat4 view = look_from(bounds, v.side, fov_y_degrees);
    // (the depth of the whole content's centre: the planes hold all of it, cut or not)
    const double depth =
        fitting_distance(bounds, v.side, half_fov) - glm::dot(shift, v.side.eye_direction);
    nearest = std::min(nearest, depth);
    farthest = std::max(farthest, depth);
    out.positions.push_back({v.name, view, true});
  }
  out.nearest = float(nearest - radius);
  out.farthest = float(farthest + radius);
  return out;
}

FittedCamera fitted_camera(const Scene& scene, FitTo fit) {
  FittedCamera fitted;
  Camera& camera = fitted.camera;
  camera.fov_y_degrees = 30.0f;  // a long lens: little perspective distortion of anatomy
  const Bounds bounds = content_bounds(scene, fit), whole = content_bounds(scene);
  const double radius = 0.5 * glm::length(glm::dvec3(whole.hi - whole.lo));
  AnatomicalPositions views = anatomical_positions(scene, camera.fov_y_degrees, fit);
  fitted.positions = std::move(views.positions);
  const double nearest = double(views.nearest) + radius, farthest = double(views.farthest) - radius;
  // Room to zoom in to the centre and out to four times the distance (the viewer's wheel).
  camera.near_plane = float(std::max(0.01 * nearest, 0.1 * (nearest - radius)));
  camera.far_plane = float(4.0 * farthest + radius);
  // From the front, unless the content is flat (a single slice): then facing it, whatever its
  // orientation, since a slice seen edge-on shows nothing.
  const glm::vec3 extent = bounds.hi - bounds.lo;
  const float largest = std::max({extent.x, extent.y, extent.z});
  AnatomicalView facing = AnatomicalView::anterior;
  if (extent.z < 0.1f * largest) facing = AnatomicalView::superior;
  if (extent.y < 0.1f * largest) facing = AnatomicalView::anterior;
  if (extent.x < 0.1f * largest) facing = AnatomicalView::left;
  camera.view = fitted.positions[static_cast<size_t>(facing)].view;
  return fitted;
}

}  // namespace strata
