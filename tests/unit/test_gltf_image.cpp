// A glTF image's bytes to a texture (gltf_image.h): the inputs fuzz_texture once failed on, the
// empty-IDAT rewrite, the formats refused, and the pixel limit checked before decoding.
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>
#include <stb_image_write.h>
#include "render/core/error.h"
#include "render/scene/gltf_image.h"
#include "tests/unit/support.h"

namespace vpl::gltf {
namespace {

namespace fs = std::filesystem;

std::vector<unsigned char> readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<unsigned char> pngOf(int w, int h) {
  std::vector<unsigned char> rgba(size_t(w) * size_t(h) * 4);
  for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = static_cast<unsigned char>(i * 37 % 251);
  std::vector<unsigned char> out;
  stbi_write_png_to_func(
      [](void* ctx, void* data, int size) {
        auto* bytes = static_cast<unsigned char*>(data);
        static_cast<std::vector<unsigned char>*>(ctx)->insert(static_cast<std::vector<unsigned char>*>(ctx)->end(), bytes, bytes + size);
      },
      &out, w, h, 4, rgba.data(), w * 4);
  return out;
}

// Inputs that once crashed or tripped a sanitizer in fuzz/fuzz_texture (fuzz/regressions_textures/,
// see fuzz/README.md): each is refused with one line or decoded within the limit. Under sanitizers
// (tests/e2e/fuzz_loader.sh replays them in fuzz_texture) the old decoder stops on each.
TEST(GltfImage, FuzzRegressionsAreRefusedOrDecodedWithinTheLimit) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(test::sourceDir() + "/fuzz/regressions_textures")) {
    ++count;
    const std::vector<unsigned char> bytes = readFile(entry.path());
    try {
      const DecodedImage image = decodeImage(bytes.data(), bytes.size(), 256 * 256, 0);
      EXPECT_LE(uint64_t(image.width) * uint64_t(image.height), 256u * 256u) << entry.path();
      EXPECT_EQ(image.rgba.size(), size_t(image.width) * size_t(image.height) * 4) << entry.path();
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(count, 0);
}

// A zero-length IDAT chunk before the image data is valid PNG; it is left out before stb_image
// reads the file (which would copy it into a null pointer), and the pixels are the same.
TEST(GltfImage, EmptyIdatChunksDecodeLikeTheFileWithoutThem) {
  const std::vector<unsigned char> png = pngOf(5, 3);
  const DecodedImage plain = decodeImage(png.data(), png.size(), 1000, 0);
  // After the signature (8) and IHDR (4 + 4 + 13 + 4): an empty IDAT, its CRC included.
  const size_t at = 8 + 25;
  ASSERT_EQ(std::memcmp(png.data() + at + 4, "IDAT", 4), 0);
  const unsigned char empty[12] = {0, 0, 0, 0, 'I', 'D', 'A', 'T', 0x35, 0xAF, 0x06, 0x1E};
  std::vector<unsigned char> withEmpty(png.begin(), png.begin() + at);
  for (int i = 0; i < 2; ++i) withEmpty.insert(withEmpty.end(), empty, empty + 12);
  withEmpty.insert(withEmpty.end(), png.begin() + at, png.end());
  const DecodedImage image = decodeImage(withEmpty.data(), withEmpty.size(), 1000, 0);
  EXPECT_EQ(image.width, 5);
  EXPECT_EQ(image.height, 3);
  EXPECT_EQ(image.rgba, plain.rgba);
}

TEST(GltfImage, OnlyPngAndJpegAreRead) {
  // A 1x1 24-bit BMP and a binary PGM: formats stb_image can read but glTF does not allow.
  const unsigned char bmp[] = {'B', 'M', 58, 0, 0, 0, 0, 0, 0, 0, 54, 0, 0, 0, 40, 0, 0, 0, 1, 0, 0, 0, 1, 0,
                               0, 0, 1, 0, 24, 0, 0, 0, 0, 0, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
                               0, 0, 0, 0, 0, 0, 0, 0, 255, 0};
  const std::string pgm = "P5\n1 1\n255\n\x80";
  EXPECT_THROW(decodeImage(bmp, sizeof(bmp), 1000, 0), InputError);
  EXPECT_THROW(decodeImage(reinterpret_cast<const unsigned char*>(pgm.data()), pgm.size(), 1000, 0), InputError);
}

TEST(GltfImage, ThePixelLimitIsCheckedBeforeDecoding) {
  const std::vector<unsigned char> png = pngOf(20, 10);
  EXPECT_EQ(decodeImage(png.data(), png.size(), 200, 3).rgba.size(), 800u);
  try {
    decodeImage(png.data(), png.size(), 199, 3);
    FAIL() << "decoded more pixels than the limit";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "image 3 claims 20x10 pixels, more than the limit");
  }
}

TEST(GltfImage, MakeTextureChecksItsFieldsAndDecodesSrgb) {
  const std::vector<unsigned char> pixels = {0, 128, 255, 128};
  EXPECT_FALSE(makeTexture(2, 2, 1, 16, pixels, true));  // 16-bit
  EXPECT_FALSE(makeTexture(3, 2, 1, 8, pixels, true));   // fewer bytes than pixels
  EXPECT_FALSE(makeTexture(1, 1, 5, 8, pixels, true));   // five channels
  const auto linear = makeTexture(1, 1, 4, 8, pixels, false);
  const auto srgb = makeTexture(1, 1, 4, 8, pixels, true);
  ASSERT_TRUE(linear && srgb);
  EXPECT_NEAR(linear->texels[0].y, 128 / 255.0f, 1e-6f);
  EXPECT_NEAR(srgb->texels[0].y, 0.2158605f, 1e-5f);  // sRGB 128 in linear light
  EXPECT_NEAR(srgb->texels[0].w, 128 / 255.0f, 1e-6f);  // alpha stays linear
}

}  // namespace
}  // namespace vpl::gltf
