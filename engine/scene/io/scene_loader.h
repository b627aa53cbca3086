// Scene files: strata's JSON (docs/scene-format.md) and, for the thesis's own scenes, the
// voly-labeller program's Boost-serialization XML. Every failure is one strata::Error
// "<file>: <field>: <reason>"; things a scene can do without (a thesis scene's missing dataset)
// become Scene::warnings instead.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "engine/core/atomic_file.h"
#include "engine/scene/io/volume_loader.h"
#include "engine/scene/scene.h"
#include "engine/scene/segmentation.h"

namespace strata {

// What the command line adds to a scene (--preset, --labels, --frame).
struct SceneOpenOptions {
  std::string preset;               // every volume's transfer function: this preset
  std::filesystem::path labels;     // labels from this file (load_label_file) added
  std::optional<SegmentationEntry> segmentation;  // its regions added (add_segmentation)
  std::optional<int> frame;         // a 4-D volume opened directly: this frame
  std::string series;               // a DICOM folder opened directly: this series (number or UID)
  std::optional<glm::vec2> window;  // every volume: a grey ramp at (center, width), its values
  std::vector<glm::vec4> cut;       // every volume: these cut-away planes added (Volume::cut)
  std::optional<bool> fit;          // complete_scene's `fit`
  VolumeLimits limits;              // every volume read, checked from its header (volume_loader.h)
};

// A scene file, .json (strata) or .xml (thesis import), or a volume file or DICOM folder opened
// as a scene of its own; then completed (complete_scene) with the options.
Scene load_scene(const std::filesystem::path& path, const SceneOpenOptions& options = {});

// A scene holding the one volume, named after the file, with no transfer function or camera.
Scene scene_from_volume(const std::filesystem::path& path, const SceneOpenOptions& options = {});

// What a scene needs to render that its file may not give: each volume without a transfer
// function gets the preset that suits its data (transfer_function_presets.h) and a warning
// saying which; `preset`, when given, replaces every volume's. A scene without a camera gets the
// fitted one, and every scene the standard views as named positions (fitted_camera.h).
// `window` (center, width in the volume's values), when given, replaces every volume's
// transfer function with that grey ramp (window_transfer_function). A transfer function in the
// volume's values (units HU or raw) is made one of its value range here. `fit` (by default for a
// scene without a camera): the standard views, and the file's camera and positions turned no
// other way, fitted to what the volumes' cut-aways keep rather than to the whole content.
void complete_scene(Scene& scene, const std::string& preset = "",
                    std::optional<glm::vec2> window = {}, std::optional<bool> fit = {});

// The labels of a label file (load_label_file) added to the scene's, with the lowest ids no
// label has, but for those the scene has already (same_label): a warning names the file and
// counts them. Scene::added_labels counts those added.
void add_label_file(Scene& scene, const std::filesystem::path& path);

// The `count` lowest ids from 0 that none of `labels` has: new labels' ids. An Error where the
// ids up to 2147483647 run out.
std::vector<int> unused_label_ids(const std::vector<Label>& labels, size_t count);

// One more than the highest label id (0 for none): where added labels' ids start.
// (int64_t: one past a label with id 2147483647 is no int.)
int64_t next_label_id(const Scene& scene);

// strata scene JSON, version 1. Paths in it are relative to the scene file's folder. Unknown keys
// are errors (they are almost always typos), and so is a referenced file that does not load.
Scene load_scene_json(const std::filesystem::path& path, const VolumeLimits& limits = {});

// A voly-labeller scene (Boost serialization XML): camera, named camera positions, labels,
// volumes and meshes. Referenced files are looked up relative to the scene's folder and its
// ancestors (the thesis program resolved them from its working folder); one that is found
// nowhere is skipped with a warning. Implemented in voly_scene_import.cpp.
Scene import_voly_scene(const std::filesystem::path& path, const VolumeLimits& limits = {});

// Writes strata scene JSON, version 1, whole or not at all (atomic_file.h), with paths relative
// to the new file's folder. A scene read from strata JSON is written as it was read (every entry
// and key kept: atlas entries, transfer functions and labels by file, frames), with the scene's
// camera positions in place of the file's (those complete_scene fitted left out: it fits them
// again). Any other scene (a volume, a thesis .xml) is written from the model: volumes and meshes
// by file, transfer functions by file or inline, labels inline, the camera and its positions.
// Replace::no: an Error if `path` exists (a new file never replaces another).
void save_scene_json(const std::filesystem::path& path, const Scene& scene,
                     AtomicFile::Replace replace = AtomicFile::Replace::yes);

}  // namespace strata
