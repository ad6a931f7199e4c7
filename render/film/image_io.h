// Image files: OpenEXR (linear float RGB, for references and measurements) and PNG (sRGB, for eyes).
// Every failure is an InputError naming the path.
#pragma once
#include <string>
#include "render/film/image.h"

namespace vpl {

// Non-finite pixels are written as 0 (and counted in the return value): NaN never reaches a file.
size_t writeExr(const std::string& path, const Image& image);
Image readExr(const std::string& path);

size_t writePng(const std::string& path, const Image& image, float exposureStops = 0.0f);
// 8-bit sRGB values as stored (not linearised), in [0, 1].
Image readPng(const std::string& path);

}  // namespace vpl
