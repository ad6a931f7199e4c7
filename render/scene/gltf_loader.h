// glTF 2.0 loading (.gltf and .glb) into SceneData: the node hierarchy flattened to world-space
// triangle meshes, metallic-roughness materials with their textures, KHR punctual lights and the
// first perspective camera. Every problem with the file is an InputError naming it.
#pragma once
#include <cstdint>
#include <filesystem>
#include "render/scene/scene_data.h"

namespace vpl {

struct LoadLimits {
  uint64_t maxBufferBytes = 2ull << 30;   // per buffer or external file
  uint64_t maxImagePixels = 64ull << 20;  // per decoded image
  uint64_t maxTriangles = 100'000'000;    // whole scene
  uint64_t maxNodeVisits = 1'000'000;     // node instances after flattening (shared children multiply)
};

SceneData loadGltf(const std::filesystem::path& file, const LoadLimits& limits = {});

}  // namespace vpl
