#include "render/guide/guide_field.h"

namespace vpl {

namespace {
std::vector<LookupSphere> lookupSpheres(const std::vector<CachePoint>& points, float radiusScale) {
  std::vector<LookupSphere> spheres(points.size());
  for (size_t i = 0; i < points.size(); ++i) spheres[i] = {points[i].position, points[i].normal, points[i].radius * radiusScale};
  return spheres;
}
}  // namespace

GuideField::GuideField(std::vector<CachePoint> points, const GuideSettings& settings)
    : points_(std::move(points)),
      settings_(settings),
      grid_(lookupSpheres(points_, settings.lookupRadiusScale), settings.lookupCosNormal) {}

int GuideField::pixelCachePoint(uint64_t pixel, const glm::vec3& p, const glm::vec3& n) const {
  if (pixel >= pixelCachePoints_.size() || pixelCachePoints_[pixel] < 0) return -1;
  const CachePoint& c = points_[size_t(pixelCachePoints_[pixel])];
  const glm::vec3 d = c.position - p;
  const float r = c.radius * settings_.lookupRadiusScale;
  return glm::dot(d, d) <= r * r && glm::dot(c.normal, n) >= settings_.lookupCosNormal ? pixelCachePoints_[pixel] : -1;
}

int GuideField::lookupLinear(const glm::vec3& p, const glm::vec3& n) const { return grid_.findLinear(p, n); }

size_t GuideField::memoryBytes() const {
  size_t bytes = sizeof(*this) + points_.capacity() * sizeof(CachePoint) + grid_.memoryBytes();
  for (const CachePoint& c : points_) bytes += c.distribution.memoryBytes() - sizeof(GuideDistribution);
  return bytes;
}

}  // namespace vpl
