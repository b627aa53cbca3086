#include "engine/scene/io/mesh_loader.h"

#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include "engine/core/error.h"

namespace strata {

namespace {

glm::mat4 to_glm(const aiMatrix4x4& m) {
  glm::mat4 result(1.0f);
  // aiMatrix4x4 is row-major (a1..a4 is the first row); glm indexes [column][row].
  for (unsigned row = 0; row < 4; ++row) {
    for (unsigned col = 0; col < 4; ++col) result[int(col)][int(row)] = m[row][col];
  }
  return result;
}

// Formats without materials (STL, PLY, OFF, OBJ without .mtl) get Assimp's invented grey
// "DefaultMaterial"; strata's own default reads better, so that one is ignored.
glm::vec4 material_color(const aiMaterial& material, glm::vec4 color) {
  aiString name;
  if (material.Get(AI_MATKEY_NAME, name) == AI_SUCCESS &&
      std::string(name.C_Str()) == AI_DEFAULT_MATERIAL_NAME) {
    return color;
  }
  aiColor4D diffuse;
  if (material.Get(AI_MATKEY_COLOR_DIFFUSE, diffuse) == AI_SUCCESS ||
      material.Get(AI_MATKEY_BASE_COLOR, diffuse) == AI_SUCCESS) {
    color = glm::vec4(diffuse.r, diffuse.g, diffuse.b, diffuse.a);
  }
  float opacity = 1.0f;
  if (material.Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS) color.a = opacity;
  return glm::clamp(color, glm::vec4(0.0f), glm::vec4(1.0f));
}

Mesh bake(const aiScene& scene, const aiMesh& source, const glm::mat4& transform) {
  Mesh mesh;
  mesh.name = source.mName.length > 0 ? source.mName.C_Str() : "";
  const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(transform)));
  mesh.positions.reserve(source.mNumVertices);
  mesh.normals.reserve(source.mNumVertices);
  for (unsigned v = 0; v < source.mNumVertices; ++v) {
    const aiVector3D& p = source.mVertices[v];
    mesh.positions.push_back(glm::vec3(transform * glm::vec4(p.x, p.y, p.z, 1.0f)));
    const glm::vec3 n = source.mNormals ? glm::vec3(source.mNormals[v].x, source.mNormals[v].y,
                                                    source.mNormals[v].z)
                                        : glm::vec3(0.0f);
    const glm::vec3 moved = normal_matrix * n;
    const float length = glm::length(moved);
    mesh.normals.push_back(length > 0.0f ? moved / length : moved);
  }
  // A mirroring transform turns counter-clockwise triangles clockwise; swapping two corners keeps
  // the front faces facing out.
  const bool mirrored = glm::determinant(glm::mat3(transform)) < 0.0f;
  mesh.indices.reserve(size_t{source.mNumFaces} * 3);
  for (unsigned f = 0; f < source.mNumFaces; ++f) {
    const aiFace& face = source.mFaces[f];
    if (face.mNumIndices != 3) continue;  // SortByPType removed points and lines; be safe
    mesh.indices.push_back(face.mIndices[0]);
    mesh.indices.push_back(face.mIndices[mirrored ? 2 : 1]);
    mesh.indices.push_back(face.mIndices[mirrored ? 1 : 2]);
  }
  if (source.mMaterialIndex < scene.mNumMaterials) {
    mesh.color = material_color(*scene.mMaterials[source.mMaterialIndex], mesh.color);
  }
  return mesh;
}

void collect(const aiScene& scene, const aiNode& node, const glm::mat4& parent,
             std::vector<Mesh>& meshes) {
  const glm::mat4 transform = parent * to_glm(node.mTransformation);
  for (unsigned i = 0; i < node.mNumMeshes; ++i) {
    const aiMesh& source = *scene.mMeshes[node.mMeshes[i]];
    if (!(source.mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    Mesh mesh = bake(scene, source, transform);
    if (mesh.name.empty()) mesh.name = node.mName.C_Str();
    if (!mesh.indices.empty()) meshes.push_back(std::move(mesh));
  }
  for (unsigned i = 0; i < node.mNumChildren; ++i) {
    collect(scene, *node.mChildren[i], transform, meshes);
  }
}

}  // namespace

std::vector<Mesh> load_meshes(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error(file + ": " + (std::filesystem::exists(path, ec) ? "not a file" : "no such file"));
  }
  if (std::filesystem::file_size(path, ec) == 0) throw Error(file + ": empty file");
  Assimp::Importer importer;
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(
      file, aiProcess_Triangulate | aiProcess_GenSmoothNormals | aiProcess_JoinIdenticalVertices |
                aiProcess_SortByPType | aiProcess_ValidateDataStructure);
  if (!scene) throw Error(file + ": " + importer.GetErrorString());
  std::vector<Mesh> meshes;
  if (scene->mRootNode) collect(*scene, *scene->mRootNode, glm::mat4(1.0f), meshes);
  if (meshes.empty()) throw Error(file + ": no triangles in the file");
  for (size_t i = 0; i < meshes.size(); ++i) {
    meshes[i].source = path;
    if (meshes[i].name.empty()) meshes[i].name = path.stem().string() + "#" + std::to_string(i);
  }
  return meshes;
}

}  // namespace strata
