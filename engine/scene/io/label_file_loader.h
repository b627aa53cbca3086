// Labels from other tools' files: 3D Slicer's markups JSON (.mrk.json), Slicer's older fiducial
// list (.fcsv) and strata's plain CSV (.csv). docs/scene-format.md, "Labels from other tools",
// describes what each format must hold and what is skipped.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "engine/scene/scene.h"

namespace strata {

// Labels from another tool's file, by extension: 3D Slicer markups (.mrk.json), Slicer's older
// fiducial list (.fcsv) and plain CSV (.csv). Anchors are returned in strata's world space, DICOM's
// LPS (x towards the patient's left, y posterior, z superior): RAS points get x and y negated.
// Ids are first_id, first_id + 1, ... in file order. Errors: one strata::Error "<file>: <field or
// line>: <reason>".
// An id past 2147483647 is an error naming the label's line or entry.
std::vector<Label> load_label_file(const std::filesystem::path& path, int64_t first_id = 0);

// Why a label file's `in_file` labels cannot join a scene that holds `in_scene` already: more than
// kMaxLabels together. Errors and `strata info --scene` put the label file's name before it.
std::optional<std::string> label_limit_problem(size_t in_file, size_t in_scene);

// The same, with the coordinate systems the file's points were written in ("LPS", "RAS"; in the
// order first met: a markups file may hold lists in both).
struct LabelFile {
  std::vector<Label> labels;
  std::vector<std::string> coordinate_systems;
};
LabelFile read_label_file(const std::filesystem::path& path, int64_t first_id = 0);

}  // namespace strata
