// Triangle meshes through Assimp: OBJ, PLY, STL, OFF, glTF/GLB, COLLADA and whatever else the
// installed Assimp reads. Every failure is one strata::Error "<file>: <reason>".
#pragma once

#include <filesystem>
#include <vector>

#include "engine/scene/scene.h"

namespace strata {

// One Mesh per placement of an aiMesh in the node tree, with the node's accumulated transform
// baked into positions and normals (Mesh::transform stays identity for the caller to set).
// Polygons are triangulated, identical vertices joined, smooth normals generated where the file
// has none; points and lines are dropped. The colour is the material's diffuse colour and
// opacity when the file gives a material, else Mesh's default.
std::vector<Mesh> load_meshes(const std::filesystem::path& path);

}  // namespace strata
