// One glTF image on its way to a texture: the encoded bytes (PNG or JPEG, as glTF allows; stb_image
// v2.30 from third_party/stb/, see gltf_image.cpp) decoded to 8-bit RGBA under a pixel limit, then
// the pixels turned into a Texture. The glTF loader's image callback and fuzz/fuzz_texture.cpp both go through these two functions.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>
#include "render/material/material.h"

namespace vpl::gltf {

struct DecodedImage {
  int width = 0, height = 0;
  std::vector<unsigned char> rgba;  // width * height * 4 bytes, row 0 at the top
};

// Refuses (InputError "image INDEX ...", without the file name) bytes that are not a PNG or JPEG, an image
// whose header claims more than maxPixels pixels (checked before any pixel is decoded) and one
// that does not decode.
DecodedImage decodeImage(const unsigned char* bytes, size_t size, uint64_t maxPixels, int index);

// Decoded pixels (channels 1-4, 8 bits each) to linear RGBA texels, through the sRGB curve when
// srgb. Nothing when the fields do not describe the pixels (the loader says "could not be decoded").
std::optional<Texture> makeTexture(int width, int height, int channels, int bits,
                                   const std::vector<unsigned char>& pixels, bool srgb);

}  // namespace vpl::gltf
