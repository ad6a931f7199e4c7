// libFuzzer target for the texture path: image bytes (as a glTF image's data URI, bufferView or
// file holds them) -> gltf::decodeImage under the fuzz pixel limit -> gltf::makeTexture, sRGB and
// linear -> a few bilinear lookups. These are the functions the loader's image callback and its
// material converter call. InputError is the expected answer to bad bytes; a crash, another
// exception, a sanitizer report, a timeout, too much memory, or a decoded image that breaks the
// limit or the texel range (checked below, abort) is a finding.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include "render/core/error.h"
#include "render/scene/gltf_image.h"

namespace {

constexpr uint64_t kMaxPixels = 256 * 256;  // as fuzz_gltf_loader's limit

void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_texture: %s\n", what);
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  vpl::gltf::DecodedImage image;
  try {
    image = vpl::gltf::decodeImage(data, size, kMaxPixels, 0);
  } catch (const vpl::InputError&) {
    return 0;  // refused with a message: the expected outcome for most inputs
  }
  check(image.width > 0 && image.height > 0, "decoded an empty image");
  check(uint64_t(image.width) * uint64_t(image.height) <= kMaxPixels, "decoded more pixels than the limit");
  check(image.rgba.size() == size_t(image.width) * size_t(image.height) * 4, "pixel count does not match the size");
  for (const bool srgb : {true, false}) {
    const auto texture = vpl::gltf::makeTexture(image.width, image.height, 4, 8, image.rgba, srgb);
    check(texture.has_value(), "a decoded image was not turned into a texture");
    // Texel centres, edges, outside [0,1] (repeat wrapping) and non-finite coordinates.
    const float uvs[][2] = {{0.5f, 0.5f}, {0, 0}, {1, 1}, {-0.25f, 1.75f}, {1e9f, -1e9f}, {NAN, 0.5f}, {INFINITY, 0}};
    for (const auto& uv : uvs) {
      const glm::vec4 v = texture->sample({uv[0], uv[1]});
      for (int c = 0; c < 4; ++c)
        check(std::isfinite(v[c]) && v[c] >= -1e-6f && v[c] <= 1 + 1e-6f, "a texel outside [0,1]");
    }
  }
  return 0;
}
