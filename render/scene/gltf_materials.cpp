#include "render/scene/gltf_materials.h"

#include <algorithm>
#include <cmath>
#include "render/core/error.h"
#include "render/scene/gltf_image.h"

namespace vpl::gltf {

namespace {

float finiteOr(double v, float fallback) { return std::isfinite(v) ? float(v) : fallback; }

glm::vec3 vec3Of(const std::vector<double>& v, glm::vec3 fallback) {
  if (v.size() < 3) return fallback;
  return {finiteOr(v[0], fallback.x), finiteOr(v[1], fallback.y), finiteOr(v[2], fallback.z)};
}

double extensionNumber(const tinygltf::ExtensionMap& ext, const char* name, const char* key, double fallback) {
  const auto it = ext.find(name);
  if (it == ext.end() || !it->second.Has(key)) return fallback;
  const tinygltf::Value& v = it->second.Get(key);
  return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

}  // namespace

int MaterialConverter::texture(const tinygltf::TextureInfo& info, bool srgb, int& texCoord) {
  return texture(info.index, info.texCoord, srgb, texCoord);
}

int MaterialConverter::texture(int textureIndex, int texCoordIn, bool srgb, int& texCoord) {
  if (textureIndex < 0) return -1;
  if (size_t(textureIndex) >= model_.textures.size())
    throw InputError(file_ + ": texture " + std::to_string(textureIndex) + " does not exist");
  texCoord = texCoordIn;
  if (texCoord < 0 || texCoord > 1) {
    scene_.notices.push_back("texture coordinate set " + std::to_string(texCoord) + " is not supported; using 0");
    texCoord = 0;
  }
  const int image = model_.textures[size_t(textureIndex)].source;
  if (image < 0) return -1;  // a texture without a source (e.g. only an unsupported extension's)
  if (size_t(image) >= model_.images.size()) throw InputError(file_ + ": image " + std::to_string(image) + " does not exist");
  const auto key = std::make_pair(image, srgb);
  if (auto it = textures_.find(key); it != textures_.end()) return it->second;

  const tinygltf::Image& img = model_.images[size_t(image)];
  std::optional<Texture> t = makeTexture(img.width, img.height, img.component, img.bits, img.image, srgb);
  if (!t) throw InputError(file_ + ": image " + std::to_string(image) + " could not be decoded");
  const int index = int(scene_.textures.size());
  scene_.textures.push_back(std::move(*t));
  textures_[key] = index;
  return index;
}

uint32_t MaterialConverter::material(int index) {
  if (auto it = materials_.find(index); it != materials_.end()) return it->second;
  Material m;  // the glTF default material when index < 0
  if (index >= 0) {
    if (size_t(index) >= model_.materials.size())
      throw InputError(file_ + ": material " + std::to_string(index) + " does not exist");
    const tinygltf::Material& g = model_.materials[size_t(index)];
    const auto& pbr = g.pbrMetallicRoughness;
    m.name = g.name;
    m.baseColor = glm::clamp(vec3Of(pbr.baseColorFactor, glm::vec3(1.0f)), 0.0f, 1.0f);
    m.baseAlpha = pbr.baseColorFactor.size() >= 4 ? std::clamp(finiteOr(pbr.baseColorFactor[3], 1.0f), 0.0f, 1.0f) : 1.0f;
    m.metallic = std::clamp(finiteOr(pbr.metallicFactor, 1.0f), 0.0f, 1.0f);
    m.roughness = std::clamp(finiteOr(pbr.roughnessFactor, 1.0f), 0.0f, 1.0f);
    m.baseColorTexture = texture(pbr.baseColorTexture, true, m.texcoordBaseColor);
    m.metallicRoughnessTexture = texture(pbr.metallicRoughnessTexture, false, m.texcoordMetallicRoughness);

    const float strength = finiteOr(extensionNumber(g.extensions, "KHR_materials_emissive_strength", "emissiveStrength", 1.0), 1.0f);
    m.emission = glm::max(vec3Of(g.emissiveFactor, glm::vec3(0.0f)), glm::vec3(0.0f)) * std::max(strength, 0.0f);
    m.emissiveTexture = texture(g.emissiveTexture.index, g.emissiveTexture.texCoord, true, m.texcoordEmissive);
    if (m.emissiveTexture >= 0 && m.emission == glm::vec3(0.0f)) m.emissiveTexture = -1;  // factor 0 switches it off

    m.ior = finiteOr(extensionNumber(g.extensions, "KHR_materials_ior", "ior", 1.5), 1.5f);
    if (m.ior < 1.0f && m.ior != 0.0f) m.ior = 1.0f;
    if (m.ior == 0.0f) m.ior = 1e30f;  // the extension's "ior 0": full reflection at normal incidence
    m.specularFactor = std::clamp(finiteOr(extensionNumber(g.extensions, "KHR_materials_specular", "specularFactor", 1.0), 1.0f), 0.0f, 1.0f);
    if (auto it = g.extensions.find("KHR_materials_specular"); it != g.extensions.end()) {
      if (it->second.Has("specularColorFactor")) {
        const tinygltf::Value& c = it->second.Get("specularColorFactor");
        if (c.IsArray() && c.ArrayLen() == 3)
          for (int k = 0; k < 3; ++k) m.specularColor[k] = std::max(0.0f, finiteOr(c.Get(k).GetNumberAsDouble(), 1.0f));
      }
      if ((it->second.Has("specularTexture") || it->second.Has("specularColorTexture")) && !noticedSpecularTextures_) {
        scene_.notices.push_back("KHR_materials_specular textures are ignored (factors are used)");
        noticedSpecularTextures_ = true;
      }
    }
    if (g.alphaMode == "MASK") {
      m.alphaMode = AlphaMode::Mask;
      m.alphaCutoff = std::clamp(finiteOr(g.alphaCutoff, 0.5f), 0.0f, 1.0f);
    } else if (g.alphaMode == "BLEND") {
      m.alphaMode = AlphaMode::Blend;  // rendered opaque
    }
    m.doubleSided = g.doubleSided;
  }
  const uint32_t out = uint32_t(scene_.materials.size());
  scene_.materials.push_back(m);
  materials_[index] = out;
  return out;
}

}  // namespace vpl::gltf
