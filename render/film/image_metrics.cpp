#include "render/film/image_metrics.h"

#include <string>
#include "render/core/error.h"

namespace vpl {

namespace {
void requireSameSize(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height)
    throw InputError("image is " + std::to_string(a.width) + "x" + std::to_string(a.height) + " but the reference is " +
                     std::to_string(b.width) + "x" + std::to_string(b.height));
}
double lum(const glm::dvec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }
}  // namespace

double relMse(const Image& image, const Image& reference) {
  requireSameSize(image, reference);
  double sum = 0.0;
  for (size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double x = image.pixels[i][c], r = reference.pixels[i][c];
      sum += (x - r) * (x - r) / (r * r + 0.01);
    }
  return image.pixels.empty() ? 0.0 : sum / (3.0 * double(image.pixels.size()));
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
