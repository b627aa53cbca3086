// Labels written back out as 3D Slicer markups, so that points placed in strata open in Slicer 5
// and load_label_file (label_file_loader.h) reads the same anchors and texts again.
// docs/scene-format.md, "Labels from other tools", says what is written.
#pragma once

#include <filesystem>
#include <span>
#include <string>

#include "engine/scene/scene.h"

namespace strata {

// The coordinate system the file's numbers are in. strata's world is LPS; RAS negates x and y.
enum class LabelAxes { lps, ras };

// A Slicer markups JSON file: one "Fiducial" markup (point list), a control point per label with
// its text as label, "mm" units and the schema URL Slicer 5 writes.
// Errors: a strata::Error "labels[<index>] (id <id>): <reason>" for a label whose anchor or
// text a markups file cannot hold (an anchor past value_limits', text that is not UTF-8).
std::string markups_json_text(std::span<const Label> labels, LabelAxes axes);

// Slicer's fiducial list (.fcsv, the header Slicer 4.11 writes): a row per label, the text quoted
// as Slicer quotes it when it holds a comma or a quote. Errors as markups_json_text, and a text
// with a line break, which Slicer reads as the end of the row, or a NUL character, which makes
// the file unreadable.
std::string fcsv_text(std::span<const Label> labels, LabelAxes axes);

// By extension, .mrk.json or .fcsv, written whole or not at all (AtomicFile). Errors: one
// strata::Error "<file>: <reason>", also for another extension.
void write_label_file(const std::filesystem::path& path, std::span<const Label> labels,
                      LabelAxes axes = LabelAxes::lps);

}  // namespace strata
