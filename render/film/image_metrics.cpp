#include "render/film/image_metrics.h"

#include <string>
#include <algorithm>
#include <cmath>
#include <iterator>
#include "render/core/error.h"
#include "render/film/tonemap.h"

namespace vpl {

namespace {
void requireSameSize(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height)
    throw InputError("image is " + std::to_string(a.width) + "x" + std::to_string(a.height) + " but the reference is " +
                     std::to_string(b.width) + "x" + std::to_string(b.height));
}
double lum(const glm::dvec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

double pixelRelMse(const glm::vec3& image, const glm::vec3& reference) {
  double sum = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double x = image[c], r = reference[c];
    sum += (x - r) * (x - r) / (r * r + 0.01);
  }
  return sum / 3.0;
}
}  // namespace

double relMse(const Image& image, const Image& reference) {
  requireSameSize(image, reference);
  double sum = 0.0;
  for (size_t i = 0; i < image.pixels.size(); ++i) sum += pixelRelMse(image.pixels[i], reference.pixels[i]);
  return image.pixels.empty() ? 0.0 : sum / double(image.pixels.size());
}

Image relMseMap(const Image& image, const Image& reference) {
  requireSameSize(image, reference);
  Image map(image.width, image.height);
  for (size_t i = 0; i < image.pixels.size(); ++i) map.pixels[i] = glm::vec3(float(pixelRelMse(image.pixels[i], reference.pixels[i])));
  return map;
}

Image falseColourLog(const Image& errors, float logMin, float logMax) {
  // Piecewise-linear ramp; its stops are spread evenly over [logMin, logMax].
  static constexpr glm::vec3 kRamp[] = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {1, 1, 0}, {1, 1, 1}};
  constexpr int kStops = int(std::size(kRamp));
  Image out(errors.width, errors.height);
  for (size_t i = 0; i < errors.pixels.size(); ++i) {
    const float e = errors.pixels[i].x;
    const float t = e > 0.0f ? std::clamp((std::log10(e) - logMin) / (logMax - logMin), 0.0f, 1.0f) : 0.0f;
    const float x = t * float(kStops - 1);
    const int k = std::min(int(x), kStops - 2);
    // Linear values: the PNG writer applies the sRGB curve, so store what the ramp means on screen.
    const glm::vec3 srgb = glm::mix(kRamp[k], kRamp[k + 1], x - float(k));
    out.pixels[i] = {srgbToLinear(srgb.x), srgbToLinear(srgb.y), srgbToLinear(srgb.z)};
  }
  return out;
}

glm::dvec3 meanRgb(const Image& image) {
  glm::dvec3 sum(0.0);
  for (const glm::vec3& p : image.pixels) sum += glm::dvec3(p);
  return image.pixels.empty() ? sum : sum / double(image.pixels.size());
}

double relativeBias(const Image& image, const Image& reference) {
  requireSameSize(image, reference);
  const double r = lum(meanRgb(reference));
  return r > 0.0 ? (lum(meanRgb(image)) - r) / r : 0.0;
}

}  // namespace vpl
