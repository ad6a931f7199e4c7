#include "render/scene/gltf_image.h"

#include <algorithm>
#include <climits>
#include <cstring>
#include "render/core/error.h"
#include "render/film/tonemap.h"

// stb_image v2.30 (third_party/stb/, upstream nothings/stb 013ac3b, 2024-05-31), compiled into this
// file alone with the PNG and JPEG decoders only, the two formats glTF allows. Debian's libstb
// (2.27, 2022-09) is not used here: fuzz_texture found it writing past a JPEG Huffman table built
// from a DHT segment with more than 256 codes (fuzz/regressions_textures/jpeg_dht_counts_over_256.jpg)
// and shifting by 33 when a JPEG's entropy-coded data runs out
// (fuzz/regressions_textures/jpeg_code_bits_negative_shift.jpg); 2.28 fixed both.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
#define STBI_NO_STDIO
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wsign-compare"
#include "third_party/stb/stb_image.h"
#pragma GCC diagnostic pop

namespace vpl::gltf {

namespace {

bool isPng(const unsigned char* b, size_t n) { return n >= 8 && std::memcmp(b, "\x89PNG\r\n\x1a\n", 8) == 0; }

// stb_image (2.27 and 2.30) copies a zero-length IDAT chunk that comes before any image data into
// a null pointer (memcpy(NULL, p, 0), undefined behaviour that UBSan stops at; found by
// fuzz_texture, fuzz/regressions_textures/png_empty_idat_before_data.png). An empty IDAT adds no
// data, so stb gets a copy without them when there are any. Chunks are framed as stb reads them: length, type, data,
// CRC; from the first chunk that runs past the end, the rest is copied as it is.
std::optional<std::vector<unsigned char>> pngWithoutEmptyIdat(const unsigned char* b, size_t n) {
  auto be32 = [&](size_t i) { return size_t(b[i]) << 24 | size_t(b[i + 1]) << 16 | size_t(b[i + 2]) << 8 | b[i + 3]; };
  std::optional<std::vector<unsigned char>> copy;
  size_t i = 8, copied = 0;  // b[copied, i) is still to be copied when a chunk is dropped
  while (i + 8 <= n) {
    const size_t length = be32(i);
    if (length == 0 && std::memcmp(b + i + 4, "IDAT", 4) == 0) {
      if (!copy) copy.emplace();
      copy->insert(copy->end(), b + copied, b + i);
      i = copied = std::min(n, i + 12);
      continue;
    }
    if (length > n - i - 8 || n - i - 8 - length < 4) break;
    i += 12 + length;
  }
  if (copy) copy->insert(copy->end(), b + copied, b + n);
  return copy;
}

}  // namespace

DecodedImage decodeImage(const unsigned char* bytes, size_t size, uint64_t maxPixels, int index) {
  const std::string name = "image " + std::to_string(index);
  if (size > size_t(INT_MAX)) throw InputError(name + " is larger than stb_image can read");
  std::optional<std::vector<unsigned char>> cleaned;
  if (isPng(bytes, size) && (cleaned = pngWithoutEmptyIdat(bytes, size))) {
    bytes = cleaned->data();
    size = cleaned->size();
  }
  int w = 0, h = 0, comp = 0;
  if (!stbi_info_from_memory(bytes, int(size), &w, &h, &comp))
    throw InputError(name + " is not a decodable PNG/JPEG (" +
                     (stbi_failure_reason() ? stbi_failure_reason() : "unknown") + ")");
  if (w <= 0 || h <= 0 || uint64_t(w) * uint64_t(h) > maxPixels)
    throw InputError(name + " claims " + std::to_string(w) + "x" + std::to_string(h) + " pixels, more than the limit");
  unsigned char* data = stbi_load_from_memory(bytes, int(size), &w, &h, &comp, 4);
  if (!data) throw InputError(name + " could not be decoded");
  DecodedImage image;
  image.width = w;
  image.height = h;
  image.rgba.assign(data, data + size_t(w) * size_t(h) * 4);
  stbi_image_free(data);
  return image;
}

std::optional<Texture> makeTexture(int width, int height, int channels, int bits,
                                   const std::vector<unsigned char>& pixels, bool srgb) {
  if (width <= 0 || height <= 0 || channels < 1 || channels > 4 || bits != 8 ||
      pixels.size() < size_t(width) * size_t(height) * size_t(channels))
    return std::nullopt;
  Texture t;
  t.width = width;
  t.height = height;
  t.texels.resize(size_t(width) * size_t(height));
  // 8-bit decode through a 256-entry table: colour textures are sRGB-encoded, data textures linear.
  float lut[256];
  for (int i = 0; i < 256; ++i) lut[i] = srgb ? srgbToLinear(i / 255.0f) : i / 255.0f;
  for (size_t p = 0; p < t.texels.size(); ++p) {
    const unsigned char* px = &pixels[p * size_t(channels)];
    glm::vec4 v(1.0f);
    if (channels >= 3) v = glm::vec4(lut[px[0]], lut[px[1]], lut[px[2]], channels == 4 ? px[3] / 255.0f : 1.0f);
    else v = glm::vec4(lut[px[0]], lut[px[0]], lut[px[0]], channels == 2 ? px[1] / 255.0f : 1.0f);
    t.texels[p] = v;
  }
  return t;
}

}  // namespace vpl::gltf
