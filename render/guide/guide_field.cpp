#include "render/guide/guide_field.h"

#include <algorithm>
#include <nanoflann.hpp>

namespace vpl {

struct GuideField::Index {
  struct Points {
    const std::vector<CachePoint>* points;
    size_t kdtree_get_point_count() const { return points->size(); }
    float kdtree_get_pt(size_t i, size_t dim) const { return (*points)[i].position[int(dim)]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const { return false; }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Points>, Points, 3, uint32_t>;
  Points points;
  Tree tree;
  explicit Index(const std::vector<CachePoint>& p) : points{&p}, tree(3, points, nanoflann::KDTreeSingleIndexAdaptorParams(8)) {
    tree.buildIndex();
  }
};


GuideField::GuideField() = default;
GuideField::GuideField(GuideField&& o) noexcept { *this = std::move(o); }

GuideField& GuideField::operator=(GuideField&& o) noexcept {
  points_ = std::move(o.points_);
  settings_ = o.settings_;
  maxRadius_ = o.maxRadius_;
  index_ = std::move(o.index_);
  pixelCachePoints_ = std::move(o.pixelCachePoints_);
  if (index_) index_->points.points = &points_;  // the adaptor refers to the vector object itself
  return *this;
}
GuideField::~GuideField() = default;

GuideField::GuideField(std::vector<CachePoint> points, const GuideSettings& settings)
    : points_(std::move(points)), settings_(settings) {
  for (const CachePoint& c : points_) maxRadius_ = std::max(maxRadius_, c.radius * settings.lookupRadiusScale);
  if (!points_.empty()) index_ = std::make_unique<Index>(points_);
}

int GuideField::lookup(const glm::vec3& p, const glm::vec3& n) const {
  if (!index_) return -1;
  // The few nearest cache points by position, then the radius and normal tests: a bounded search,
  // where a radius search would visit every point within the largest slice's radius.
  constexpr size_t kCandidates = kLookupCandidates;
  uint32_t index[kCandidates];
  float dist2[kCandidates];
  const float query[3] = {p.x, p.y, p.z};
  const size_t found = index_->tree.knnSearch(query, kCandidates, index, dist2);
  for (size_t k = 0; k < found; ++k) {  // nearest first
    const CachePoint& c = points_[index[k]];
    const float r = c.radius * settings_.lookupRadiusScale;
    if (dist2[k] <= r * r && glm::dot(c.normal, n) >= settings_.lookupCosNormal) return int(index[k]);
  }
  return -1;
}

int GuideField::pixelCachePoint(uint64_t pixel, const glm::vec3& p, const glm::vec3& n) const {
  if (pixel >= pixelCachePoints_.size() || pixelCachePoints_[pixel] < 0) return -1;
  const CachePoint& c = points_[size_t(pixelCachePoints_[pixel])];
  const glm::vec3 d = c.position - p;
  const float r = c.radius * settings_.lookupRadiusScale;
  return glm::dot(d, d) <= r * r && glm::dot(c.normal, n) >= settings_.lookupCosNormal ? pixelCachePoints_[pixel] : -1;
}

int GuideField::lookupLinear(const glm::vec3& p, const glm::vec3& n) const {
  // The same rule by brute force.
  std::vector<std::pair<float, size_t>> byDistance;
  for (size_t i = 0; i < points_.size(); ++i) {
    const glm::vec3 d = points_[i].position - p;
    byDistance.push_back({glm::dot(d, d), i});
  }
  std::sort(byDistance.begin(), byDistance.end());
  byDistance.resize(std::min<size_t>(kLookupCandidates, byDistance.size()));
  int best = -1;
  float bestDist2 = INFINITY;
  for (const auto& [unused, i] : byDistance) {
    const CachePoint& c = points_[i];
    const glm::vec3 d = c.position - p;
    const float dist2 = glm::dot(d, d), r = c.radius * settings_.lookupRadiusScale;
    if (dist2 <= r * r && dist2 < bestDist2 && glm::dot(c.normal, n) >= settings_.lookupCosNormal) {
      best = int(i);
      bestDist2 = dist2;
    }
  }
  return best;
}

size_t GuideField::memoryBytes() const {
  size_t bytes = sizeof(*this) + points_.capacity() * sizeof(CachePoint) + points_.size() * 24;
  for (const CachePoint& c : points_) bytes += c.distribution.memoryBytes() - sizeof(GuideDistribution);
  return bytes;
}

}  // namespace vpl
