// glTF materials and textures to vpl::Material / vpl::Texture (sRGB decoding where the spec says).
#pragma once
#include <map>
#include <string>
#include <utility>
#include <vector>
#include <tiny_gltf.h>
#include "render/scene/scene_data.h"

namespace vpl::gltf {

class MaterialConverter {
 public:
  MaterialConverter(const tinygltf::Model& model, const std::string& file, SceneData& scene)
      : model_(model), file_(file), scene_(scene) {}

  // Index in scene.materials of glTF material `index` (-1: the spec's default material).
  uint32_t material(int index);

 private:
  int texture(const tinygltf::TextureInfo& info, bool srgb, int& texCoord);
  int texture(int textureIndex, int texCoordIn, bool srgb, int& texCoord);

  const tinygltf::Model& model_;
  const std::string& file_;
  SceneData& scene_;
  std::map<int, uint32_t> materials_;
  std::map<std::pair<int, bool>, int> textures_;  // (image, sRGB) -> scene texture
  bool noticedSpecularTextures_ = false;
};

}  // namespace vpl::gltf
