// The voxels are never resampled: a stack whose slices are not evenly spaced on one line is
// refused rather than shown with slices where they are not. What rounding of the printed positions
// explains is not such a stack (docs/scene-format.md, "DICOM").
#include "engine/scene/io/dicom_stack.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <optional>
#include <tuple>

namespace strata::dicom {
namespace {

using namespace volume_io;
namespace fs = std::filesystem;

// Closer than this along the normal, two slices are at one position.
constexpr double kSamePositionMm = 1e-4;

// ---- time points

// The most slices at any one position along `normal`.
size_t most_at_one_position(const std::vector<Slice>& slices, glm::dvec3 normal) {
  std::vector<double> along;
  for (const Slice& s : slices) along.push_back(glm::dot(s.position, normal));
  std::sort(along.begin(), along.end());
  size_t most = 1, run = 1;
  for (size_t k = 1; k < along.size(); ++k) {
    run = along[k] - along[k - 1] < kSamePositionMm ? run + 1 : 1;
    most = std::max(most, run);
  }
  return most;
}

// Numbers in numeric order, then other text in text order.
bool key_before(const std::string& a, const std::string& b) {
  const auto number = [](const std::string& text) {
    double value = 0.0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    const bool whole = error == std::errc{} && end == text.data() + text.size();
    return std::tuple(!whole, whole ? value : 0.0, text);
  };
  return number(a) < number(b);
}

struct TimePoints {
  size_t key = 0;                          // the kKeyTags entry whose values tell them apart
  std::vector<std::vector<Slice>> points;  // in the order of its values
};

// The slices by the first time element whose values split them into `repeats` groups that each
// hold every position once.
std::optional<TimePoints> split_by_time(const std::vector<Slice>& slices, size_t repeats) {
  const glm::dvec3 normal = slice_normal(slices.front());
  for (size_t key = 0; key < kTimeKeys; ++key) {
    std::vector<std::string> values;
    for (const Slice& s : slices)
      if (std::find(values.begin(), values.end(), s.keys[key]) == values.end())
        values.push_back(s.keys[key]);
    if (values.size() != repeats) continue;
    std::sort(values.begin(), values.end(), key_before);
    TimePoints times{.key = key, .points = std::vector<std::vector<Slice>>(values.size())};
    for (const Slice& s : slices) {
      const auto value = std::find(values.begin(), values.end(), s.keys[key]);
      times.points[size_t(value - values.begin())].push_back(s);
    }
    if (std::all_of(times.points.begin(), times.points.end(),
                    [&](const auto& point) { return most_at_one_position(point, normal) == 1; }))
      return times;
  }
  return std::nullopt;
}

std::optional<TimePoints> time_points(const std::vector<Slice>& slices) {
  // Slices without a position are refused as a series later; time cannot order them.
  if (slices.size() < 2 ||
      !std::all_of(slices.begin(), slices.end(), [](const Slice& s) { return s.placed; }))
    return std::nullopt;
  const size_t repeats = most_at_one_position(slices, slice_normal(slices.front()));
  if (repeats < 2) return std::nullopt;
  return split_by_time(slices, repeats);
}

// Two slices at one position that no time element splits into volumes: what tells them apart, if
// anything, and what to do.
[[noreturn]] void fail_same_position(const fs::path& where, const Slice& a, const Slice& b) {
  const std::string same = concat(name_of(a), " and ", name_of(b), " are at the same position (",
                                  a.along_normal, " mm along the normal)");
  if (a.frames_in_file == 1 && !a.instance.empty() && a.instance == b.instance)
    fail(where, same + ": the same image twice (one SOPInstanceUID), a copied file; remove one");
  for (size_t key = 0; key < kKeyTags.size(); ++key) {
    if (a.keys[key] == b.keys[key]) continue;
    const char* name = kKeyTags[key].name;
    fail(where, concat(same, " and differ in ", name, " (", printable(a.keys[key]), ", ",
                       printable(b.keys[key]), "): the series holds several volumes",
                       key < kTimeKeys ? concat(" that its ", name,
                                                " values do not split into one slice a position")
                                       : std::string(),
                       "; split it into one folder a volume (dcm2niix does) and open one"));
  }
  fail(where, same +
                  ": a repeated slice (no TemporalPositionIdentifier, AcquisitionNumber, "
                  "TriggerTime or EchoNumbers tells them apart); remove one, or split the series "
                  "into one folder a volume");
}

// ---- spacing

// Half the last digit each coordinate of the positions is printed to (the finest any slice
// prints): how far rounding may have moved a position along each axis.
glm::dvec3 half_digits(const std::vector<Slice>& slices) {
  glm::dvec3 digit = slices.front().position_digit;
  for (const Slice& s : slices) digit = glm::min(digit, s.position_digit);
  return 0.5 * digit;
}

// The coarsest digit among the coordinates that move a position along `direction`.
double printed_digit(glm::dvec3 half, glm::dvec3 direction) {
  double digit = 0.0;
  for (int axis = 0; axis < 3; ++axis)
    if (std::fabs(direction[axis]) > 0.01) digit = std::max(digit, 2.0 * half[axis]);
  return digit;
}

std::string mm(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g mm", value);
  return text;
}

struct Deviation {
  double mm = 0.0;
  size_t slice = 0;
};

// The slice furthest from where even spacing from the first to the last puts it.
Deviation largest_deviation(const std::vector<Slice>& slices, double mean) {
  Deviation worst;
  const double first = slices.front().along_normal;
  for (size_t k = 0; k < slices.size(); ++k) {
    const double off = std::fabs(slices[k].along_normal - (first + double(k) * mean));
    if (off > worst.mm) worst = {off, k};
  }
  return worst;
}

// Steps within 1% of their mean (at least 1 µm) are even. Beyond that, positions printed to few
// digits (0.1 mm, as some scanners write them) are off by up to half a digit in each coordinate,
// `rounding` along the normal, so a slice may lie up to twice that from even spacing (both ends of
// the line through the first and last are rounded too); never more than a tenth of the spacing,
// as a missing slice moves some slice a quarter of it or more.
double check_even(const fs::path& where, const std::vector<Slice>& slices, double mean,
                  glm::dvec3 half, glm::dvec3 normal, std::vector<std::string>& warnings) {
  double smallest = mean, largest = mean;
  size_t uneven = slices.size();
  for (size_t k = 0; k + 1 < slices.size(); ++k) {
    const double step = slices[k + 1].along_normal - slices[k].along_normal;
    smallest = std::min(smallest, step);
    largest = std::max(largest, step);
    if (uneven == slices.size() && std::fabs(step - mean) > std::max(1e-3, 0.01 * mean)) uneven = k;
  }
  if (uneven == slices.size()) return mean;
  const double bound = std::min(2.0 * glm::dot(half, glm::abs(normal)), 0.1 * mean);
  const Deviation worst = largest_deviation(slices, mean);
  const std::string rounding =
      concat("rounding of the positions (printed to ", mm(printed_digit(half, normal)),
             ") explains up to ", mm(bound));
  if (worst.mm <= bound) {
    warnings.push_back(concat(where.string(), ": ImagePositionPatient: slice steps of ",
                              mm(smallest), " to ", mm(largest),
                              "; the largest deviation from "
                              "even spacing is ",
                              mm(worst.mm), " (", name_of(slices[worst.slice]), "), within what ",
                              rounding, ": read as evenly spaced ", mean, " mm apart"));
    return mean;
  }
  const double step = slices[uneven + 1].along_normal - slices[uneven].along_normal;
  fail(where, concat("slice spacing is not uniform: ", step, " mm between ",
                     name_of(slices[uneven]), " and ", name_of(slices[uneven + 1]), ", ", mean,
                     " mm on average; ", name_of(slices[worst.slice]), " lies ", mm(worst.mm),
                     " from even spacing, more than ", rounding,
                     " (a missing slice, or slices at uneven distances)"));
}

// Sorts along the normal and returns the even distance between slices.
double sort_and_space(const fs::path& where, std::vector<Slice>& slices, glm::dvec3 normal,
                      glm::dvec3 half, std::vector<std::string>& warnings) {
  for (Slice& s : slices) s.along_normal = glm::dot(s.position, normal);
  std::stable_sort(slices.begin(), slices.end(),
                   [](const Slice& a, const Slice& b) { return a.along_normal < b.along_normal; });
  if (slices.size() == 1) return slices[0].thickness > 0.0 ? slices[0].thickness : 1.0;
  for (size_t k = 0; k + 1 < slices.size(); ++k)
    if (slices[k + 1].along_normal - slices[k].along_normal < kSamePositionMm)
      fail_same_position(where, slices[k], slices[k + 1]);
  const double mean = (slices.back().along_normal - slices.front().along_normal) /
                      static_cast<double>(slices.size() - 1);
  return check_even(where, slices, mean, half, normal, warnings);
}

// ---- shear

// Sideways drift below this, or below what rounding of the printed positions explains, leaves the
// grid orthogonal.
constexpr double kDriftMm = 0.01;

std::string degrees_text(double degrees) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", degrees < 0.1 ? 3 : 1, degrees);
  return text;
}

// The voxels are not resampled: a sheared stack gets a sheared grid, so that every slice stays
// where its ImagePositionPatient puts it.
StackAxis stack_axis(const fs::path& where, const std::vector<Slice>& slices, glm::dvec3 normal,
                     double step, glm::dvec3 half, std::vector<std::string>& warnings) {
  if (slices.size() < 2) return {normal, step};
  const glm::dvec3 first = slices.front().position;
  const auto sideways = [&](glm::dvec3 d) { return d - glm::dot(d, normal) * normal; };
  const double rounding = std::max(kDriftMm, 2.0 * glm::length(half));
  double drift = 0.0;
  for (const Slice& s : slices) drift = std::max(drift, glm::length(sideways(s.position - first)));
  if (drift < rounding) return {normal, step};

  const glm::dvec3 along = (slices.back().position - first) / double(slices.size() - 1);
  for (size_t k = 0; k < slices.size(); ++k) {
    const double off = glm::length(sideways(slices[k].position - (first + double(k) * along)));
    if (off > std::max(rounding, 0.01 * glm::length(along)))
      fail(where, concat("ImagePositionPatient: the slices do not lie on one line: ",
                         name_of(slices[k]), " is ", off, " mm sideways from the line through ",
                         name_of(slices.front()), " and ", name_of(slices.back()),
                         " (strata reads evenly spaced slices, sheared at most uniformly)"));
  }
  const glm::dvec3 direction = glm::normalize(along);
  const double tilt = glm::degrees(std::acos(std::clamp(glm::dot(direction, normal), -1.0, 1.0)));
  const std::string sheared = concat("ImagePositionPatient: the slices are sheared by ",
                                     degrees_text(tilt), "° (gantry tilt): each moves ",
                                     glm::length(sideways(along)), " mm sideways from the last");
  if (tilt > 45.0)
    fail(where, sheared + "; more than 45° is not a stack of slices strata can show");
  warnings.push_back(concat(where.string(), ": ", sheared,
                            "; shown on a sheared grid, each slice at its own position "
                            "(not resampled)"));
  return {direction, glm::length(along)};
}

}  // namespace

std::vector<Slice> one_time_point(const fs::path& where, std::vector<Slice> slices,
                                  const VolumeReadOptions& options,
                                  std::vector<std::string>& warnings) {
  std::optional<TimePoints> times = time_points(slices);
  if (!times) {
    choose_frame(where, 1, options, warnings);
    return slices;
  }
  const size_t count = times->points.size();
  const int64_t frame = options.frame.value_or(0);
  if (frame < 0 || uint64_t(frame) >= count)
    fail(where, concat("frame ", frame, " is out of range: the series holds ", count,
                       " time points, 0 to ", count - 1));
  const char* name = kKeyTags[times->key].name;
  std::vector<Slice>& chosen = times->points[size_t(frame)];
  warnings.push_back(concat(where.string(), ": the series holds ", count,
                            " time points (its slices repeat their positions, ", name,
                            " tells them apart); showing time point ", frame, " (", name, " ",
                            printable(chosen.front().keys[times->key]),
                            "; choose with --frame 0 to ", count - 1, ")"));
  return std::move(chosen);
}

size_t count_time_points(const std::vector<Slice>& slices) {
  const std::optional<TimePoints> times = time_points(slices);
  return times ? times->points.size() : 1;
}

StackAxis order_stack(const fs::path& where, std::vector<Slice>& slices,
                      std::vector<std::string>& warnings) {
  const glm::dvec3 normal = slice_normal(slices.front());
  const glm::dvec3 half = half_digits(slices);
  const double step = sort_and_space(where, slices, normal, half, warnings);
  return stack_axis(where, slices, normal, step, half, warnings);
}

}  // namespace strata::dicom
