#include <doctest/doctest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "engine/core/error.h"
#include "engine/scene/io/mesh_loader.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;

fs::path write_file(const std::string& name, const std::string& text) {
  return strata::test::write_file(fs::path(STRATA_TEST_OUTPUT) / "mesh_loader_tests" / name, text);
}

using strata::test::error_of;

struct Bounds {
  glm::vec3 lo{1e30f}, hi{-1e30f};
};

Bounds bounds_of(const std::vector<strata::Mesh>& meshes) {
  Bounds b;
  for (const strata::Mesh& mesh : meshes) {
    for (const glm::vec3& p : mesh.positions) {
      b.lo = glm::min(b.lo, p);
      b.hi = glm::max(b.hi, p);
    }
  }
  return b;
}

void check_vec(const glm::vec3& v, float x, float y, float z) {
  CHECK(v.x == doctest::Approx(x));
  CHECK(v.y == doctest::Approx(y));
  CHECK(v.z == doctest::Approx(z));
}

void check_unit_normals(const strata::Mesh& mesh) {
  REQUIRE(mesh.normals.size() == mesh.positions.size());
  for (const glm::vec3& n : mesh.normals) CHECK(glm::length(n) == doctest::Approx(1.0));
}

glm::vec3 corner(const strata::Mesh& mesh, size_t t, int i) {
  return mesh.positions[mesh.indices[t + size_t(i)]];
}

// For a closed convex mesh: normals and triangle windings (counter-clockwise seen from outside)
// point away from the centre.
void check_facing_out(const strata::Mesh& mesh) {
  check_unit_normals(mesh);
  glm::vec3 centre(0.0f);
  for (const glm::vec3& p : mesh.positions) centre += p / float(mesh.positions.size());
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    CHECK(glm::dot(mesh.normals[v], mesh.positions[v] - centre) > 0.0f);
  }
  for (size_t t = 0; t < mesh.indices.size(); t += 3) {
    const glm::vec3 a = corner(mesh, t, 0), b = corner(mesh, t, 1), c = corner(mesh, t, 2);
    CHECK(glm::dot(glm::cross(b - a, c - a), (a + b + c) / 3.0f - centre) > 0.0f);
  }
}

// For a flat mesh: every triangle winds counter-clockwise around its corners' normals.
void check_winding_follows_normals(const strata::Mesh& mesh) {
  check_unit_normals(mesh);
  for (size_t t = 0; t < mesh.indices.size(); t += 3) {
    const glm::vec3 a = corner(mesh, t, 0), b = corner(mesh, t, 1), c = corner(mesh, t, 2);
    const glm::vec3 normals = mesh.normals[mesh.indices[t]] + mesh.normals[mesh.indices[t + 1]] +
                              mesh.normals[mesh.indices[t + 2]];
    CHECK(glm::dot(glm::cross(b - a, c - a), normals) > 0.0f);
  }
}

const char* const tetrahedron_obj =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
    "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

std::string base64(const std::vector<unsigned char>& bytes) {
  static const char* const digits =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string text;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const unsigned n = unsigned(bytes[i]) << 16 |
                       (i + 1 < bytes.size() ? unsigned(bytes[i + 1]) << 8 : 0u) |
                       (i + 2 < bytes.size() ? unsigned(bytes[i + 2]) : 0u);
    text += digits[n >> 18 & 63];
    text += digits[n >> 12 & 63];
    text += i + 1 < bytes.size() ? digits[n >> 6 & 63] : '=';
    text += i + 2 < bytes.size() ? digits[n & 63] : '=';
  }
  return text;
}

// The tetrahedron as glTF 2.0 with its buffer embedded as base64, under a node that scales by 2
// and moves by (10, 0, 0), with a half-transparent red material.
std::string tetrahedron_gltf() {
  const float positions[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const uint16_t indices[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  std::vector<unsigned char> buffer(sizeof positions + sizeof indices);
  std::memcpy(buffer.data(), positions, sizeof positions);
  std::memcpy(buffer.data() + sizeof positions, indices, sizeof indices);
  return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0, "translation": [10, 0, 0], "scale": [2, 2, 2]}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
  "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 0.5]}, "alphaMode": "BLEND"}],
  "buffers": [{"byteLength": 72, "uri": "data:application/octet-stream;base64,)" +
         base64(buffer) + R"("}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48, "target": 34962},
                  {"buffer": 0, "byteOffset": 48, "byteLength": 24, "target": 34963}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 1]},
                {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}]})";
}

// A unit quad in z = 0 as one COLLADA polygon, placed by a node matrix (row-major in COLLADA).
std::string quad_collada(const std::string& matrix) {
  return R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Y_UP</up_axis></asset>
  <library_geometries>
    <geometry id="quad" name="quad"><mesh>
      <source id="quad-positions">
        <float_array id="quad-positions-array" count="12">0 0 0 1 0 0 1 1 0 0 1 0</float_array>
        <technique_common><accessor source="#quad-positions-array" count="4" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common>
      </source>
      <vertices id="quad-vertices"><input semantic="POSITION" source="#quad-positions"/></vertices>
      <polylist count="1"><input semantic="VERTEX" source="#quad-vertices" offset="0"/>
        <vcount>4</vcount><p>0 1 2 3</p></polylist>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="scene"><node id="quad-node" name="quad-node">
      <matrix>)" +
         matrix + R"(</matrix><instance_geometry url="#quad"/>
    </node></visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
)";
}

}  // namespace

TEST_SUITE("loaders") {
  TEST_CASE("obj_tetrahedron_loads_with_smooth_normals_and_joined_vertices") {
    const auto meshes = strata::load_meshes(write_file("tetrahedron.obj", tetrahedron_obj));
    REQUIRE(meshes.size() == 1);
    CHECK(meshes[0].triangle_count() == 4);
    CHECK(meshes[0].positions.size() == 4);  // smooth normals keep the corners shared
    check_vec(bounds_of(meshes).lo, 0, 0, 0);
    check_vec(bounds_of(meshes).hi, 1, 1, 1);
    check_facing_out(meshes[0]);
    CHECK(meshes[0].transform == glm::mat4(1.0f));
    CHECK(meshes[0].color == glm::vec4(0.8f, 0.8f, 0.8f, 1.0f));  // no material: the default
    CHECK(meshes[0].source.filename() == "tetrahedron.obj");
  }

  TEST_CASE("obj_material_gives_the_diffuse_colour_and_opacity") {
    write_file("blue.mtl", "newmtl blue\nKd 0 0.5 1\nd 0.25\n");
    const auto meshes = strata::load_meshes(
        write_file("blue.obj", std::string("mtllib blue.mtl\nusemtl blue\n") + tetrahedron_obj));
    REQUIRE(meshes.size() == 1);
    CHECK(meshes[0].color.r == doctest::Approx(0.0));
    CHECK(meshes[0].color.g == doctest::Approx(0.5));
    CHECK(meshes[0].color.b == doctest::Approx(1.0));
    CHECK(meshes[0].color.a == doctest::Approx(0.25));
  }

  TEST_CASE("ascii_ply_tetrahedron_loads") {
    const auto meshes = strata::load_meshes(write_file("tetrahedron.ply",
                                                       "ply\nformat ascii 1.0\n"
                                                       "element vertex 4\n"
                                                       "property float x\nproperty float y\n"
                                                       "property float z\n"
                                                       "element face 4\n"
                                                       "property list uchar int vertex_indices\n"
                                                       "end_header\n"
                                                       "0 0 0\n2 0 0\n0 2 0\n0 0 2\n"
                                                       "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"));
    REQUIRE(meshes.size() == 1);
    CHECK(meshes[0].triangle_count() == 4);
    check_vec(bounds_of(meshes).hi, 2, 2, 2);
    check_facing_out(meshes[0]);
  }

  TEST_CASE("ascii_stl_tetrahedron_loads_with_its_facet_normals") {
    const auto meshes = strata::load_meshes(write_file(
        "tetrahedron.stl",
        "solid tetrahedron\n"
        "facet normal 0 0 -1\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 0\nendloop\n"
        "endfacet\n"
        "facet normal 0 -1 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 1\nendloop\n"
        "endfacet\n"
        "facet normal -1 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\nvertex 0 1 0\nendloop\n"
        "endfacet\n"
        "facet normal 0.57735 0.57735 0.57735\nouter loop\nvertex 1 0 0\nvertex 0 1 0\n"
        "vertex 0 0 1\nendloop\nendfacet\n"
        "endsolid tetrahedron\n"));
    REQUIRE(meshes.size() == 1);
    CHECK(meshes[0].triangle_count() == 4);
    check_vec(bounds_of(meshes).lo, 0, 0, 0);
    check_vec(bounds_of(meshes).hi, 1, 1, 1);
    check_facing_out(meshes[0]);
  }

  TEST_CASE("off_quad_is_triangulated") {
    const auto meshes = strata::load_meshes(
        write_file("quad.off", "OFF\n4 1 0\n0 0 0\n2 0 0\n2 3 0\n0 3 0\n4 0 1 2 3\n"));
    REQUIRE(meshes.size() == 1);
    CHECK(meshes[0].triangle_count() == 2);
    check_vec(bounds_of(meshes).hi, 2, 3, 0);
    check_winding_follows_normals(meshes[0]);
    for (const glm::vec3& n : meshes[0].normals) check_vec(n, 0, 0, 1);
  }

  TEST_CASE("gltf_with_embedded_buffer_loads_with_its_node_transform_baked") {
    const auto meshes = strata::load_meshes(write_file("tetrahedron.gltf", tetrahedron_gltf()));
    REQUIRE(meshes.size() == 1);
    CHECK(meshes[0].triangle_count() == 4);
    check_vec(bounds_of(meshes).lo, 10, 0, 0);
    check_vec(bounds_of(meshes).hi, 12, 2, 2);
    check_facing_out(meshes[0]);
    CHECK(meshes[0].transform == glm::mat4(1.0f));
    CHECK(meshes[0].color.r == doctest::Approx(1.0));
    CHECK(meshes[0].color.g == doctest::Approx(0.0));
    CHECK(meshes[0].color.a == doctest::Approx(0.5));
  }

  TEST_CASE("collada_quad_loads_with_its_node_matrix_baked") {
    const auto meshes = strata::load_meshes(
        write_file("quad.dae", quad_collada("1 0 0 5  0 1 0 0  0 0 1 0  0 0 0 1")));
    REQUIRE(meshes.size() == 1);
    CHECK(meshes[0].triangle_count() == 2);
    check_vec(bounds_of(meshes).lo, 5, 0, 0);
    check_vec(bounds_of(meshes).hi, 6, 1, 0);
    check_winding_follows_normals(meshes[0]);
  }

  TEST_CASE("mirroring_node_transform_keeps_triangles_facing_their_normals") {
    const auto meshes = strata::load_meshes(
        write_file("mirrored.dae", quad_collada("-1 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1")));
    REQUIRE(meshes.size() == 1);
    check_vec(bounds_of(meshes).lo, -1, 0, 0);
    check_winding_follows_normals(meshes[0]);  // the winding is flipped with the mirror
  }

  TEST_CASE("bad_mesh_files_give_one_error_naming_the_file_and_reason") {
    const fs::path missing = fs::path(STRATA_TEST_OUTPUT) / "mesh_loader_tests/missing.obj";
    CHECK(error_of([&] { strata::load_meshes(missing); }) == missing.string() + ": no such file");
    const fs::path empty = write_file("empty.stl", "");
    CHECK(error_of([&] { strata::load_meshes(empty); }) == empty.string() + ": empty file");
    const fs::path garbage = write_file("garbage.ply", "this is not a mesh\n\x01\x02\x03");
    const std::string message = error_of([&] { strata::load_meshes(garbage); });
    CHECK(message.rfind(garbage.string() + ": ", 0) == 0);
    CHECK(message.size() > garbage.string().size() + 10);
    const fs::path no_faces = write_file("points.obj", "v 0 0 0\nv 1 0 0\n");
    CHECK(error_of([&] { strata::load_meshes(no_faces); }).rfind(no_faces.string() + ": ", 0) == 0);
    const fs::path folder = fs::path(STRATA_TEST_OUTPUT) / "mesh_loader_tests";
    CHECK(error_of([&] { strata::load_meshes(folder); }) == folder.string() + ": not a file");
  }
}
