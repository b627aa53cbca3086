// The constraint regions of the placement (thesis 3.2.1) against an independent construction:
// for a placed box and its connector, the candidate centres whose new box (+ margin), together
// with the new anchor, overlaps them are found by clipping polygons in double precision, and the
// reference placement's constraint image must hold exactly that pixel set.
#include <doctest/doctest.h>

#include <algorithm>
#include <vector>

#include "passes/placement_reference.h"
#include "test_scenes.h"

namespace strata {
namespace {

using Polygon = std::vector<glm::dvec2>;

double cross(glm::dvec2 a, glm::dvec2 b) {
  return a.x * b.y - a.y * b.x;
}

// Counter-clockwise convex hull (monotone chain).
Polygon hull(std::vector<glm::dvec2> points) {
  std::sort(points.begin(), points.end(),
            [](auto a, auto b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  Polygon h(2 * points.size());
  size_t k = 0;
  for (int pass = 0; pass < 2; ++pass) {
    const size_t start = k;
    for (const glm::dvec2& p : points) {
      while (k >= start + 2 && cross(h[k - 1] - h[k - 2], p - h[k - 2]) <= 0.0) --k;
      h[k++] = p;
    }
    --k;
    std::reverse(points.begin(), points.end());
  }
  h.resize(k);
  return h;
}

// Sutherland-Hodgman: what is left of `subject` inside the convex counter-clockwise `clip`.
Polygon clip_polygon(Polygon subject, const Polygon& clip) {
  for (size_t e = 0; e < clip.size() && !subject.empty(); ++e) {
    const glm::dvec2 a = clip[e], b = clip[(e + 1) % clip.size()];
    const auto inside = [&](glm::dvec2 p) { return cross(b - a, p - a) >= 0.0; };
    Polygon out;
    for (size_t i = 0; i < subject.size(); ++i) {
      const glm::dvec2 p = subject[i], q = subject[(i + 1) % subject.size()];
      if (inside(p)) out.push_back(p);
      if (inside(p) != inside(q)) {
        const double t = cross(b - a, a - p) / cross(b - a, q - p);
        out.push_back(p + t * (q - p));
      }
    }
    subject = std::move(out);
  }
  return subject;
}

// Does the hull of anchor and box(centre, half) touch the convex set `other` (a box, or a thin
// quad around a segment)?
bool touches(glm::dvec2 anchor, glm::dvec2 centre, glm::dvec2 half, const Polygon& other) {
  const Polygon h =
      hull({anchor, centre + glm::dvec2(-half.x, -half.y), centre + glm::dvec2(half.x, -half.y),
            centre + glm::dvec2(half.x, half.y), centre + glm::dvec2(-half.x, half.y)});
  return !clip_polygon(other, h).empty();
}

gpu::LabelGpu label(glm::vec2 anchor, glm::vec2 size) {
  return test::label_at(anchor, size);
}

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("constraint_image_holds_exactly_the_dilated_shadows_of_a_box_and_a_line") {
    const graph::Extent size{48, 32};
    const size_t pixels = size_t{size.width} * size.height;
    // A mostly empty scene, so label 0 lands near its anchor; label 1 is the one whose
    // constraints are examined. Anchors off the pixel grid, so few centres lie on a region's edge.
    const std::vector<gpu::LabelGpu> labels = {label({12.3f, 16.7f}, {9.0f, 5.0f}),
                                               label({36.6f, 13.2f}, {7.0f, 3.0f})};
    const std::vector<uint32_t> order = {0, 1};
    std::vector<uint8_t> image(pixels * 4, 20);
    const std::vector<glm::vec4> layers(pixels, glm::vec4(0.0f));
    PlacementSettings settings;
    settings.write_constraints = true;
    settings.method = PlacementMethod::sequential;  // (its constraint image)
    settings.margin_em = 1.0f / 14.0f;  // a pixel at the default text size
    const ReferencePlacement r = place_reference(image, layers, 1, labels, order, settings, size);
    REQUIRE(r.placements[0].shown == PLACEMENT_SHOWN);

    const glm::dvec2 placed(r.placements[0].position), half0 = glm::dvec2(labels[0].size) * 0.5;
    const Polygon box0 = {placed - half0, placed + glm::dvec2(half0.x, -half0.y), placed + half0,
                          placed + glm::dvec2(-half0.x, half0.y)};
    // The connector as a very thin quad along the segment.
    const glm::dvec2 p0(labels[0].anchor), p1 = placed;
    const glm::dvec2 n = glm::normalize(glm::dvec2(-(p1 - p0).y, (p1 - p0).x)) * 1e-7;
    const Polygon line = hull({p0 - n, p0 + n, p1 + n, p1 - n});
    const glm::dvec2 anchor(labels[1].anchor), half = glm::dvec2(labels[1].size) * 0.5 + 1.0;

    size_t label_pixels = 0, line_pixels = 0, mismatches = 0, excused = 0;
    for (uint32_t y = 0; y < size.height; ++y) {
      for (uint32_t x = 0; x < size.width; ++x) {
        const glm::vec2 origin = gpu::box_origin(glm::uvec2(x, y), labels[1].size);
        if (origin.x < 0.0f || origin.y < 0.0f || origin.x + labels[1].size.x > float(size.width) ||
            origin.y + labels[1].size.y > float(size.height)) {
          continue;  // not a candidate: its box leaves the screen
        }
        const glm::dvec2 centre = glm::dvec2(origin) + glm::dvec2(labels[1].size) * 0.5;
        const uint32_t bits = r.constraints[size_t{y} * size.width + x];
        const bool expect_label = touches(anchor, centre, half, box0);
        const bool expect_line = touches(anchor, centre, half, line);
        label_pixels += expect_label;
        line_pixels += expect_line;
        // A centre within 1e-4 pixels of a region's slanted edge (the hull just grazing a
        // corner) is decided by rounding: a difference there is excused, and counted.
        const glm::dvec2 tiny(1e-4);
        const bool label_edge = touches(anchor, centre, half - tiny, box0) != expect_label ||
                                touches(anchor, centre, half + tiny, box0) != expect_label;
        const bool line_edge = touches(anchor, centre, half - tiny, line) != expect_line ||
                               touches(anchor, centre, half + tiny, line) != expect_line;
        const bool label_differs = ((bits & CONSTRAINT_LABEL) != 0u) != expect_label;
        const bool line_differs = ((bits & CONSTRAINT_CONNECTOR) != 0u) != expect_line;
        excused += (label_differs && label_edge) + (line_differs && line_edge);
        if ((label_differs && !label_edge) || (line_differs && !line_edge)) {
          MESSAGE("pixel " << x << "," << y << ": constraint bits " << bits);
          ++mismatches;
        }
      }
    }
    CHECK(label_pixels > 20);  // the regions are not empty...
    CHECK(line_pixels > 20);
    CHECK(label_pixels < 900);  // ...nor everything
    CHECK(excused <= 2);
    CHECK(mismatches == 0);
  }
}

}  // namespace strata
