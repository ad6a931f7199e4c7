// Small scenes built in code for tests whose answer is known analytically.
#pragma once
#include "render/scene/scene_data.h"

namespace vpl::test {

// An axis-aligned box [-h, h]^3 seen from inside: 12 triangles, one material.
inline MeshData insideBox(float h, uint32_t material) {
  MeshData m;
  m.name = "box";
  const glm::vec3 c[8] = {{-h, -h, -h}, {h, -h, -h}, {h, h, -h}, {-h, h, -h},
                          {-h, -h, h},  {h, -h, h},  {h, h, h},  {-h, h, h}};
  m.positions.assign(c, c + 8);
  // Wound so that the normals point into the box.
  const uint32_t faces[6][4] = {{0, 1, 2, 3}, {5, 4, 7, 6}, {4, 0, 3, 7}, {1, 5, 6, 2}, {4, 5, 1, 0}, {3, 2, 6, 7}};
  for (const auto& f : faces) {
    for (uint32_t i : {f[0], f[1], f[2], f[0], f[2], f[3]}) m.indices.push_back(i);
  }
  m.material = material;
  return m;
}

// A closed furnace: every wall is Lambertian with albedo rho and emits radiance le on both sides.
// Radiance everywhere inside is le / (1 - rho) (the Neumann series of a constant operator).
inline SceneData furnaceScene(float rho, float le, float halfSize = 1.0f) {
  SceneData s;
  Material wall;
  wall.baseColor = glm::vec3(rho);
  wall.metallic = 0.0f;
  wall.roughness = 1.0f;
  wall.specularFactor = 0.0f;  // pure Lambertian
  wall.emission = glm::vec3(le);
  wall.doubleSided = true;
  s.materials.push_back(wall);
  s.meshes.push_back(insideBox(halfSize, 0));
  s.boundsMin = glm::vec3(-halfSize);
  s.boundsMax = glm::vec3(halfSize);
  CameraData cam;
  cam.eye = glm::vec3(0.0f);
  cam.target = glm::vec3(0, 0, -1);
  cam.yfov = 1.2f;
  s.camera = cam;
  return s;
}

}  // namespace vpl::test
