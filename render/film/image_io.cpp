#include "render/film/image_io.h"

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStdIO.h>
#include <stb_image.h>
#include <stb_image_write.h>
#include "render/core/error.h"
#include "render/film/atomic_file.h"
#include "render/film/tonemap.h"

namespace vpl {

namespace {

// Copies the image with non-finite values replaced by 0; returns how many were replaced.
size_t sanitized(const Image& in, std::vector<float>& rgb) {
  rgb.resize(in.pixels.size() * 3);
  size_t bad = 0;
  for (size_t i = 0; i < in.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const float v = in.pixels[i][c];
      const bool ok = std::isfinite(v);
      bad += !ok;
      rgb[3 * i + c] = ok ? v : 0.0f;
    }
  return bad;
}

}  // namespace

size_t writeExr(const std::string& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0) throw InputError(path + ": cannot write an empty image");
  std::vector<float> rgb;
  const size_t bad = sanitized(image, rgb);
  // Encoded in memory, then written in one piece: a failed write never truncates an earlier file.
  Imf::StdOSStream encoded;
  try {
    Imf::Header header(image.width, image.height);
    for (const char* name : {"R", "G", "B"}) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    Imf::OutputFile file(encoded, header);  // its destructor writes the line offsets: scope ends before str()
    Imf::FrameBuffer fb;
    const size_t xStride = 3 * sizeof(float), yStride = xStride * size_t(image.width);
    char* base = reinterpret_cast<char*>(rgb.data());
    fb.insert("R", Imf::Slice(Imf::FLOAT, base, xStride, yStride));
    fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xStride, yStride));
    fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xStride, yStride));
    file.setFrameBuffer(fb);
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot write OpenEXR (" + e.what() + ")");
  }
  writeFileAtomically(path, encoded.str());
  return bad;
}

Image readExr(const std::string& path) {
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    if (w <= 0 || h <= 0 || int64_t(w) * h > (int64_t(1) << 28)) throw InputError(path + ": unreasonable EXR size");
    for (const char* name : {"R", "G", "B"})
      if (!file.header().channels().findChannel(name)) throw InputError(path + ": EXR has no " + name + " channel");
    std::vector<float> rgb(size_t(w) * h * 3);
    Imf::FrameBuffer fb;
    const size_t xStride = 3 * sizeof(float), yStride = xStride * size_t(w);
    // Slices are addressed relative to the data window's origin.
    char* base = reinterpret_cast<char*>(rgb.data()) - (dw.min.x * xStride + dw.min.y * yStride);
    fb.insert("R", Imf::Slice(Imf::FLOAT, base, xStride, yStride));
    fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), xStride, yStride));
    fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), xStride, yStride));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    Image image(w, h);
    for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = {rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]};
    return image;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot read OpenEXR (" + e.what() + ")");
  }
}

size_t writePng(const std::string& path, const Image& image, float exposureStops) {
  if (image.width <= 0 || image.height <= 0) throw InputError(path + ": cannot write an empty image");
  std::vector<uint8_t> bytes(image.pixels.size() * 3);
  size_t bad = 0;
  for (size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const float v = image.pixels[i][c];
      bad += !std::isfinite(v);
      bytes[3 * i + c] = toDisplayByte(std::isfinite(v) ? v : 0.0f, exposureStops);
    }
  writePngBytes(path, image.width, image.height, bytes);
  return bad;
}

void writePngBytes(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb) {
  if (width <= 0 || height <= 0 || rgb.size() != size_t(width) * size_t(height) * 3)
    throw InputError(path + ": cannot write an empty or mis-sized image");
  std::string encoded;
  const auto append = [](void* out, void* bytes, int n) { static_cast<std::string*>(out)->append(static_cast<char*>(bytes), size_t(n)); };
  if (!stbi_write_png_to_func(append, &encoded, width, height, 3, rgb.data(), width * 3))
    throw InputError(path + ": cannot encode PNG");
  writeFileAtomically(path, encoded);
}

Image readPng(const std::string& path) {
  int w = 0, h = 0, n = 0;
  uint8_t* data = stbi_load(path.c_str(), &w, &h, &n, 3);
  if (!data) throw InputError(path + ": cannot read PNG (" + (stbi_failure_reason() ? stbi_failure_reason() : "?") + ")");
  Image image(w, h);
  for (size_t i = 0; i < image.pixels.size(); ++i)
    image.pixels[i] = glm::vec3(data[3 * i], data[3 * i + 1], data[3 * i + 2]) / 255.0f;
  stbi_image_free(data);
  return image;
}

}  // namespace vpl
