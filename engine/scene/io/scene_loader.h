// Scene files: strata's JSON (docs/scene-format.md) and, for the thesis's own scenes, the
// voly-labeller program's Boost-serialization XML. Every failure is one strata::Error
// "<file>: <field>: <reason>"; things a scene can do without (a thesis scene's missing dataset)
// become Scene::warnings instead.
#pragma once

#include <filesystem>

#include "engine/scene/scene.h"

namespace strata {

// .json (strata) or .xml (thesis import), by extension.
Scene load_scene(const std::filesystem::path& path);

// strata scene JSON, version 1. Paths in it are relative to the scene file's folder. Unknown keys
// are errors (they are almost always typos), and so is a referenced file that does not load.
Scene load_scene_json(const std::filesystem::path& path);

// A voly-labeller scene (Boost serialization XML): camera, named camera positions, labels,
// volumes and meshes. Referenced files are looked up relative to the scene's folder and its
// ancestors (the thesis program resolved them from its working folder); one that is found
// nowhere is skipped with a warning. Implemented in voly_scene_import.cpp.
Scene import_voly_scene(const std::filesystem::path& path);

// Writes strata scene JSON, version 1, with paths relative to the new file's folder and transfer
// functions inline. Volumes and meshes without a source file (atlas masks and surfaces) cannot
// be written as files and are left out; meshes are written once per source file.
void save_scene_json(const std::filesystem::path& path, const Scene& scene);

}  // namespace strata
