// All cache points of a camera view with their guide distributions, and the lookup of the cache
// point that serves a path vertex (by position and normal). Immutable once built: render threads
// only read it.
#pragma once
#include <cstdint>
#include <vector>
#include <glm/glm.hpp>
#include "render/guide/cache_point_grid.h"
#include "render/guide/guide_distribution.h"
#include "render/guide/guide_settings.h"

namespace vpl {

struct CachePoint {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0, 0, 1};
  float radius = 0.0f;  // lookup radius, world units
  GuideDistribution distribution;
};

class GuideField {
 public:
  GuideField() = default;
  GuideField(std::vector<CachePoint> points, const GuideSettings& settings);

  // The nearest cache point within its lookup radius of p whose normal agrees with n; or -1.
  int lookup(const glm::vec3& p, const glm::vec3& n) const { return grid_.find(p, n); }
  int lookupLinear(const glm::vec3& p, const glm::vec3& n) const;  // brute force, for tests
  // The cache point of a pixel's slice if it passes the same radius and normal tests at (p, n), else -1.
  int pixelCachePoint(uint64_t pixel, const glm::vec3& p, const glm::vec3& n) const;
  void setPixelCachePoints(std::vector<int32_t> perPixel) { pixelCachePoints_ = std::move(perPixel); }

  const CachePoint& point(int i) const { return points_[size_t(i)]; }
  size_t size() const { return points_.size(); }
  const GuideSettings& settings() const { return settings_; }
  size_t memoryBytes() const;

 private:
  std::vector<CachePoint> points_;
  GuideSettings settings_;
  std::vector<int32_t> pixelCachePoints_;
  CachePointGrid grid_;
};

}  // namespace vpl
