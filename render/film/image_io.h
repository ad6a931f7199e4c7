// Image files: OpenEXR (linear float RGB, for references and measurements) and PNG (sRGB, for eyes).
// Every failure is an InputError naming the path; writes are atomic (render/film/atomic_file.h).
#pragma once
#include <cstdint>
#include <string>
#include <vector>
#include "render/film/image.h"

namespace vpl {

// Non-finite pixels are written as 0 (and counted in the return value): NaN never reaches a file.
size_t writeExr(const std::string& path, const Image& image);
Image readExr(const std::string& path);

size_t writePng(const std::string& path, const Image& image, float exposureStops = 0.0f);
// 8-bit sRGB bytes as they are (a screenshot): width x height RGB triples, top row first.
void writePngBytes(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb);
// 8-bit sRGB values as stored (not linearised), in [0, 1].
Image readPng(const std::string& path);

}  // namespace vpl
