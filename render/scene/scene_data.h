// What the glTF loader produces: flattened world-space triangle meshes, materials, textures,
// punctual lights and the camera. Plain data; the renderer builds its accelerations from it.
#pragma once
#include <optional>
#include <string>
#include <vector>
#include <glm/glm.hpp>
#include "render/material/material.h"

namespace vpl {

// One glTF primitive instanced by one node, with the node's world transform applied.
struct MeshData {
  std::string name;
  std::vector<glm::vec3> positions;  // world space
  std::vector<glm::vec3> normals;    // world space, unit; empty when the file has none (use geometric normals)
  std::vector<glm::vec2> uvs0, uvs1; // TEXCOORD_0 / TEXCOORD_1; empty when absent
  std::vector<uint32_t> indices;     // 3 per triangle; winding fixed for negative-determinant transforms
  uint32_t material = 0;             // index into SceneData::materials
};

enum class LightType { Point, Spot, Directional };

// KHR_lights_punctual, in world space.
struct PunctualLight {
  LightType type = LightType::Point;
  glm::vec3 position{0.0f};
  glm::vec3 direction{0, 0, -1};  // direction the light travels (spot and directional)
  glm::vec3 intensity{1.0f};      // colour x intensity: candela (point, spot) or lux (directional)
  float cosInner = 1.0f, cosOuter = 0.0f;  // spot cone cosines
  float range = 0.0f;                       // 0 = infinite
};

struct CameraData {
  glm::vec3 eye{0, 0, 3}, target{0, 0, 0}, up{0, 1, 0};
  float yfov = 0.7f;                 // radians
  std::optional<float> aspectRatio;  // as the file gives it
};

struct SceneData {
  std::vector<MeshData> meshes;
  std::vector<Material> materials;  // always at least one (the glTF default material)
  std::vector<Texture> textures;
  std::vector<PunctualLight> lights;
  std::optional<CameraData> camera;  // the first perspective camera, if any
  glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};
  std::vector<std::string> notices;  // one-line remarks for the user (ignored extensions, ...)

  size_t triangleCount() const {
    size_t n = 0;
    for (const auto& m : meshes) n += m.indices.size() / 3;
    return n;
  }
};

}  // namespace vpl
