#include "engine/scene/fitted_camera.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/scene/scene_bounds.h"

namespace strata {
namespace {

constexpr double kMargin = 1.05;  // the box's projection fills 95% of the view

// The content's box; without volumes or meshes the labels' anchors, then a unit box, so a
// camera always exists.
Bounds content_bounds(const Scene& scene) {
  Bounds bounds = scene_bounds(scene);
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
  double distance = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec3 p((corner & 1) ? bounds.hi.x : bounds.lo.x,
                       (corner & 2) ? bounds.hi.y : bounds.lo.y,
                       (corner & 4) ? bounds.hi.z : bounds.lo.z);
    const glm::dvec3 d = p - centre;
    const double lateral = std::max(std::abs(glm::dot(d, right)), std::abs(glm::dot(d, side.up)));
    distance = std::max(distance,
                        glm::dot(d, side.eye_direction) + kMargin * lateral / std::tan(half_fov));
  }
  return distance;
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

glm::mat4 fitted_view(const Scene& scene, AnatomicalView view, float fov_y_degrees) {
  const Bounds bounds = content_bounds(scene);
  const ViewSide side = side_of(view);
  const double distance = fitting_distance(bounds, side, glm::radians(double(fov_y_degrees)) / 2.0);
  const glm::dvec3 centre(bounds.centre());
  return glm::mat4(glm::lookAt(centre + side.eye_direction * distance, centre, side.up));
}

AnatomicalPositions anatomical_positions(const Scene& scene, float fov_y_degrees) {
  AnatomicalPositions out;
  const Bounds bounds = content_bounds(scene);
  const double radius = 0.5 * glm::length(glm::dvec3(bounds.hi - bounds.lo));
  const double half_fov = glm::radians(double(fov_y_degrees)) / 2.0;
  double nearest = std::numeric_limits<double>::max(), farthest = 0.0;
  for (size_t v = 0; v < kAnatomicalViewNames.size(); ++v) {
    const double d = fitting_distance(bounds, side_of(AnatomicalView(v)), half_fov);
    nearest = std::min(nearest, d);
    farthest = std::max(farthest, d);
    out.positions.push_back(
        {kAnatomicalViewNames[v], fitted_view(scene, AnatomicalView(v), fov_y_degrees)});
  }
  out.nearest = float(nearest - radius);
  out.farthest = float(farthest + radius);
  return out;
}

FittedCamera fitted_camera(const Scene& scene) {
  FittedCamera fitted;
  Camera& camera = fitted.camera;
  camera.fov_y_degrees = 30.0f;  // a long lens: little perspective distortion of anatomy
  const Bounds bounds = content_bounds(scene);
  const double radius = 0.5 * glm::length(glm::dvec3(bounds.hi - bounds.lo));
  AnatomicalPositions views = anatomical_positions(scene, camera.fov_y_degrees);
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
