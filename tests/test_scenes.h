// Small scenes the tests build in code.
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "engine/scene/scene.h"
#include "shared/labels.h"

namespace strata::test {

// A 20 mm box (corners only) around (10, 20, 30), seen obliquely from the front left and above.
inline Scene box_scene() {
  Scene scene;
  Mesh box;
  for (int corner = 0; corner < 8; ++corner) {
    box.positions.push_back(glm::vec3(10, 20, 30) + 10.0f * glm::vec3((corner & 1) ? 1 : -1,
                                                                      (corner & 2) ? 1 : -1,
                                                                      (corner & 4) ? 1 : -1));
  }
  scene.meshes.push_back(box);
  scene.camera = {glm::lookAt(glm::vec3(-60, -60, 80), glm::vec3(10, 20, 30), glm::vec3(0, 0, 1)),
                  30.0f, 1.0f, 500.0f};
  return scene;
}

// A square of 2 `half` around `centre` at height z, facing +z.
inline Mesh quad(float z, glm::vec4 color, float half = 10.0f, glm::vec2 centre = glm::vec2(0.0f)) {
  Mesh m;
  m.name = "quad";
  m.positions = {{centre.x - half, centre.y - half, z},
                 {centre.x + half, centre.y - half, z},
                 {centre.x + half, centre.y + half, z},
                 {centre.x - half, centre.y + half, z}};
  m.normals.assign(4, glm::vec3(0.0f, 0.0f, 1.0f));
  m.indices = {0, 1, 2, 0, 2, 3};
  m.color = color;
  return m;
}

// An enabled label of `size` at `anchor` on `layer` (its previous position the anchor).
inline gpu::LabelGpu label_at(glm::vec2 anchor, glm::vec2 size, uint32_t layer = 0,
                              uint32_t flags = LABEL_ENABLED) {
  gpu::LabelGpu l{};
  l.anchor = anchor;
  l.size = size;
  l.previous = anchor;
  l.layer = layer;
  l.flags = flags;
  return l;
}

}  // namespace strata::test
