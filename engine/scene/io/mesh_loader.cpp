#include "engine/scene/io/mesh_loader.h"

#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <fstream>
#include <string_view>

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

uint32_t little_endian_u32(const unsigned char* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// Binary glTF: Assimp allocates what a chunk header claims before it reads it (a 4 GB claim in a
// 2 KB file: 30 s and 4 GB of memory, then "No suitable reader found"). Every chunk must fit.
void check_glb(const std::string& file, std::ifstream& in, uint64_t size) {
  unsigned char header[12];
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(header), sizeof header))
    throw Error(file + ": GLB header: 12 bytes needed, the file has " + std::to_string(size));
  const uint32_t version = little_endian_u32(header + 4), length = little_endian_u32(header + 8);
  if (length > size)
    throw Error(file + ": GLB header: length " + std::to_string(length) + " bytes, the file has " +
                std::to_string(size));
  if (version != 2) return;  // glTF 1's binary container has one content length, checked above
  uint64_t offset = sizeof header;
  for (int chunk = 0; offset + 8 <= length; ++chunk) {
    unsigned char chunk_header[8];
    in.seekg(std::streamoff(offset));
    if (!in.read(reinterpret_cast<char*>(chunk_header), sizeof chunk_header)) break;
    const uint32_t bytes = little_endian_u32(chunk_header);
    const uint32_t type = little_endian_u32(chunk_header + 4);
    const std::string name = type == 0x4E4F534Au ? " (JSON)" : type == 0x004E4942u ? " (BIN)" : "";
    const uint64_t after = length - offset - 8;
    if (bytes > after)
      throw Error(file + ": GLB chunk " + std::to_string(chunk) + name + ": length " +
                  std::to_string(bytes) + " bytes, the file has " + std::to_string(after) +
                  " after the chunk header");
    offset += 8 + uint64_t{bytes};
  }
}

// PLY: a header without its "end_header" line (a file cut inside it) sends Assimp's reader into
// an endless loop. The line is searched for through the whole file, in pieces.
void check_ply(const std::string& file, std::ifstream& in) {
  static constexpr std::string_view line = "\nend_header";
  in.seekg(0);
  std::string window;
  std::vector<char> piece(1 << 16);
  while (in.read(piece.data(), std::streamsize(piece.size())) || in.gcount() > 0) {
    window.append(piece.data(), size_t(in.gcount()));
    for (size_t at = window.find(line); at != std::string::npos; at = window.find(line, at + 1)) {
      size_t end = at + line.size();
      while (end < window.size() &&
             (window[end] == ' ' || window[end] == '\t' || window[end] == '\r'))
        ++end;
      if (end < window.size() && window[end] == '\n') return;
      if (end == window.size()) break;  // the rest of the line is in the next piece
    }
    // Keep a tail long enough for a line that straddles two pieces.
    if (window.size() > 4096) window.erase(0, window.size() - 4096);
    if (!in) break;
  }
  throw Error(file + ": PLY header: no 'end_header' line (the file is cut short or damaged)");
}

// Structural checks of what Assimp would take badly, where a check is complete and cheap: the
// errors name the field instead of a parser going down.
void check_structure(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[5] = {};
  in.read(magic, 4);
  in.clear();
  std::error_code ec;
  const uint64_t size = std::filesystem::file_size(path, ec);
  if (std::string_view(magic, 4) == "glTF") check_glb(path.string(), in, size);
  if (std::string_view(magic, 4) == "ply\n" || std::string_view(magic, 4) == "ply\r")
    check_ply(path.string(), in);
}

void check_file(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error(file + ": " + (std::filesystem::exists(path, ec) ? "not a file" : "no such file"));
  }
  if (std::filesystem::file_size(path, ec) == 0) throw Error(file + ": empty file");
  check_structure(path);
}

std::vector<Mesh> read_with_assimp(const std::filesystem::path& path) {
  const std::string file = path.string();
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

}  // namespace

std::vector<Mesh> load_meshes(const std::filesystem::path& path, const ParserLimits& limits) {
  check_file(path);
  return read_meshes_isolated(path, "the mesh reader (Assimp)", limits,
                              [&] { return read_with_assimp(path); });
}

std::vector<Mesh> load_meshes(const std::filesystem::path& path) {
  return load_meshes(path, {});
}

std::vector<Mesh> load_meshes_in_process(const std::filesystem::path& path) {
  check_file(path);
  return read_with_assimp(path);
}

}  // namespace strata
