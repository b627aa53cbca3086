// A DICOM series' slices as one volume: the time point --frame chooses where the slices repeat
// their positions, then the slices in order along their normal, evenly spaced within the
// rounding of their printed positions, on an orthogonal or uniformly sheared grid.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "engine/scene/io/dicom_slice.h"
#include "engine/scene/io/volume_loader.h"

namespace strata::dicom {

// The slices of the time point options.frame chooses (default the first, with a warning naming
// how many there are), where the slices repeat every position and a time element
// (TemporalPositionIdentifier, AcquisitionNumber or TriggerTime) tells the repeats apart; else
// all of them, refusing a --frame past 0.
std::vector<Slice> one_time_point(const std::filesystem::path& where, std::vector<Slice> slices,
                                  const VolumeReadOptions& options,
                                  std::vector<std::string>& warnings);

// How many time points one_time_point finds (1 where the positions do not repeat).
size_t count_time_points(const std::vector<Slice>& slices);

// The k axis: the slice normal, or, when the slices also move sideways from one to the next
// (gantry tilt, a sheared stack), the line through their positions.
struct StackAxis {
  glm::dvec3 direction{0.0};
  double spacing = 0.0;
};

// Sorts the slices along their normal and checks that they are evenly spaced on one line, within
// what rounding their printed positions explains (a warning says when that was needed). Errors
// name `where` (the folder or file) and the slices.
StackAxis order_stack(const std::filesystem::path& where, std::vector<Slice>& slices,
                      std::vector<std::string>& warnings);

}  // namespace strata::dicom
