// libFuzzer target for the whole scene-loading path: bytes -> file -> loadGltf -> RenderScene.
// The loader reads from a path, so each input is written into a private temporary folder, as
// scene.glb when it starts with the GLB magic and as scene.gltf otherwise. The folder also holds
// a small external buffer (b.bin) and image (i.png) that inputs may refer to by URI. InputError is
// the expected outcome of bad input; anything else (crash, other exception, sanitizer report,
// timeout, out of memory) is a finding.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <stb_image_write.h>
#include "render/core/error.h"
#include "render/scene/gltf_loader.h"
#include "render/scene/render_scene.h"

namespace fs = std::filesystem;

namespace {

fs::path folder;

// Small limits: a fuzz input may claim anything, and must not get gigabytes for it.
vpl::LoadLimits fuzzLimits() {
  vpl::LoadLimits limits;
  limits.maxBufferBytes = 1u << 20;
  limits.maxImagePixels = 256 * 256;
  limits.maxTriangles = 100'000;
  limits.maxNodeVisits = 10'000;
  return limits;
}

void writeFile(const fs::path& path, const void* data, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), std::streamsize(size));
}

void removeFolder() {
  std::error_code ec;
  fs::remove_all(folder, ec);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  std::string pattern = (fs::temp_directory_path() / "vplview_fuzz_XXXXXX").string();
  if (!mkdtemp(pattern.data())) {
    std::perror("fuzz_gltf_loader: mkdtemp");
    std::abort();
  }
  folder = pattern;
  std::atexit(removeFolder);
  // One triangle (3 x VEC3 float) and a 2x2 RGBA PNG, for inputs that use external URIs.
  const float triangle[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  writeFile(folder / "b.bin", triangle, sizeof(triangle));
  const unsigned char texels[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 128};
  stbi_write_png((folder / "i.png").c_str(), 2, 2, 4, texels, 8);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const fs::path file = folder / (glb ? "scene.glb" : "scene.gltf");
  writeFile(file, data, size);
  try {
    vpl::RenderScene scene(vpl::loadGltf(file, fuzzLimits()));
  } catch (const vpl::InputError&) {
    // Refused with a message: the expected outcome for most inputs.
  }
  std::error_code ec;
  fs::remove(file, ec);
  return 0;
}
