// glTF metallic-roughness material as loaded, plus its textures. Colours are linear RGB.
#pragma once
#include <cstdint>
#include <string>
#include <vector>
#include <glm/glm.hpp>

namespace vpl {

// A decoded texture: linear RGBA floats (sRGB-encoded images are decoded at load time).
struct Texture {
  int width = 0, height = 0;
  std::vector<glm::vec4> texels;  // row-major, row 0 is the top of the image (glTF uv origin)
  // Bilinear lookup with repeat wrapping.
  glm::vec4 sample(glm::vec2 uv) const;
};

enum class AlphaMode { Opaque, Mask, Blend };

struct Material {
  std::string name;
  glm::vec3 baseColor{1.0f};      // baseColorFactor.rgb
  float baseAlpha = 1.0f;         // baseColorFactor.a
  float metallic = 1.0f;          // glTF defaults
  float roughness = 1.0f;         // perceptual roughness; GGX alpha = roughness^2
  glm::vec3 emission{0.0f};       // emissiveFactor x KHR_materials_emissive_strength (radiance, W/(m^2 sr))
  float ior = 1.5f;               // KHR_materials_ior
  float specularFactor = 1.0f;    // KHR_materials_specular
  glm::vec3 specularColor{1.0f};  // KHR_materials_specular
  int baseColorTexture = -1;          // index into SceneData::textures, sRGB-decoded
  int metallicRoughnessTexture = -1;  // linear; G = roughness, B = metallic
  int emissiveTexture = -1;           // sRGB-decoded
  int texcoordBaseColor = 0, texcoordMetallicRoughness = 0, texcoordEmissive = 0;
  AlphaMode alphaMode = AlphaMode::Opaque;
  float alphaCutoff = 0.5f;
  bool doubleSided = false;

  bool isEmissive() const { return emissiveTexture >= 0 || glm::max(emission.x, glm::max(emission.y, emission.z)) > 0.0f; }
  bool hasTextures() const { return baseColorTexture >= 0 || metallicRoughnessTexture >= 0 || emissiveTexture >= 0; }
};

}  // namespace vpl
