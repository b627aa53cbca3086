// Triangle meshes through Assimp: OBJ, PLY, STL, OFF, glTF/GLB, COLLADA and whatever else the
// installed Assimp reads. Every failure is one strata::Error "<file>: <reason>".
#pragma once

#include <filesystem>
#include <vector>

#include "engine/scene/io/isolated_read.h"
#include "engine/scene/scene.h"

namespace strata {

// One Mesh per placement of an aiMesh in the node tree, with the node's accumulated transform
// baked into positions and normals (Mesh::transform stays identity for the caller to set).
// Polygons are triangulated, identical vertices joined, smooth normals generated where the file
// has none; points and lines are dropped. The colour is the material's diffuse colour and
// opacity when the file gives a material, else Mesh's default.
// Assimp reads in a child process under `limits` (isolated_read.h): its crash, endless loop or
// runaway allocation is an Error naming the file. A GLB's chunk lengths and a PLY's header end
// are checked first, here.
std::vector<Mesh> load_meshes(const std::filesystem::path& path, const ParserLimits& limits);
std::vector<Mesh> load_meshes(const std::filesystem::path& path);
// The same read in this process, unprotected: for comparing with the isolated read.
std::vector<Mesh> load_meshes_in_process(const std::filesystem::path& path);

}  // namespace strata
