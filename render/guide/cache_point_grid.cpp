#include "render/guide/cache_point_grid.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace vpl {

namespace {

// A sphere covering more cells than this is checked at every lookup instead of being inserted.
constexpr int64_t kMaxCellsPerSphere = 512;
// Cell coordinates beyond this are treated as outside the grid (no float-to-int overflow).
constexpr float kMaxCoordinate = 1e9f;

bool cellRange(const glm::vec3& lo, const glm::vec3& hi, float cell, glm::i64vec3& a, glm::i64vec3& b) {
  const glm::vec3 fa = glm::floor(lo / cell), fb = glm::floor(hi / cell);
  for (int k = 0; k < 3; ++k)
    if (!(std::abs(fa[k]) < kMaxCoordinate) || !(std::abs(fb[k]) < kMaxCoordinate)) return false;
  a = glm::i64vec3(fa);
  b = glm::i64vec3(fb);
  return true;
}

}  // namespace

CachePointGrid::CachePointGrid(std::vector<LookupSphere> spheres, float cosNormal)
    : spheres_(std::move(spheres)), cosNormal_(cosNormal) {
  if (spheres_.empty()) return;
  // Cells twice the median radius: a typical sphere touches at most 2 x 2 x 2 of them.
  std::vector<float> radii;
  for (const LookupSphere& s : spheres_)
    if (s.radius > 0.0f && std::isfinite(s.radius)) radii.push_back(s.radius);
  if (radii.empty()) return;
  std::nth_element(radii.begin(), radii.begin() + radii.size() / 2, radii.end());
  cell_ = 2.0f * radii[radii.size() / 2];

  struct Entry {
    uint32_t bucket, sphere;
  };
  std::vector<Entry> inserted;
  std::vector<std::pair<glm::i64vec3, uint32_t>> cells;
  for (uint32_t i = 0; i < spheres_.size(); ++i) {
    const LookupSphere& s = spheres_[i];
    if (!(s.radius > 0.0f) || !std::isfinite(s.radius)) continue;
    glm::i64vec3 a, b;
    if (!cellRange(s.centre - s.radius, s.centre + s.radius, cell_, a, b)) continue;
    const glm::i64vec3 extent = b - a + int64_t(1);
    if (extent.x * extent.y * extent.z > kMaxCellsPerSphere) {
      large_.push_back(i);
      continue;
    }
    for (int64_t z = a.z; z <= b.z; ++z)
      for (int64_t y = a.y; y <= b.y; ++y)
        for (int64_t x = a.x; x <= b.x; ++x) cells.push_back({{x, y, z}, i});
  }
  bucketMask_ = uint32_t(std::bit_ceil(std::max<size_t>(16, 2 * cells.size()))) - 1;
  bucketStart_.assign(size_t(bucketMask_) + 2, 0);
  inserted.reserve(cells.size());
  for (const auto& [c, i] : cells) {
    const uint32_t bucket = bucketOf(c.x, c.y, c.z);
    inserted.push_back({bucket, i});
    ++bucketStart_[bucket + 1];
  }
  for (size_t b = 1; b < bucketStart_.size(); ++b) bucketStart_[b] += bucketStart_[b - 1];
  entries_.resize(inserted.size());
  std::vector<uint32_t> fill(bucketStart_.begin(), bucketStart_.end() - 1);
  for (const Entry& e : inserted) entries_[fill[e.bucket]++] = {spheres_[e.sphere], e.sphere};
}

uint32_t CachePointGrid::bucketOf(int64_t x, int64_t y, int64_t z) const {
  // Teschner et al.'s spatial hash primes.
  const uint64_t h = uint64_t(x) * 73856093ull ^ uint64_t(y) * 19349663ull ^ uint64_t(z) * 83492791ull;
  return uint32_t(h ^ (h >> 29)) & bucketMask_;
}

bool CachePointGrid::better(const LookupSphere& s, uint32_t candidate, const glm::vec3& p, const glm::vec3& n,
                            float& bestDist2, int& best) const {
  const glm::vec3 d = s.centre - p;
  const float dist2 = glm::dot(d, d);
  if (dist2 > s.radius * s.radius || glm::dot(s.normal, n) < cosNormal_) return false;
  if (dist2 < bestDist2 || (dist2 == bestDist2 && int(candidate) < best)) {
    bestDist2 = dist2;
    best = int(candidate);
    return true;
  }
  return false;
}

int CachePointGrid::find(const glm::vec3& p, const glm::vec3& n) const {
  int best = -1;
  float bestDist2 = INFINITY;
  if (!bucketStart_.empty()) {
    glm::i64vec3 c, unused;
    if (cellRange(p, p, cell_, c, unused)) {
      const uint32_t b = bucketOf(c.x, c.y, c.z);
      for (uint32_t k = bucketStart_[b]; k < bucketStart_[b + 1]; ++k)
        better(entries_[k].sphere, entries_[k].index, p, n, bestDist2, best);
    }
  }
  for (uint32_t i : large_) better(spheres_[i], i, p, n, bestDist2, best);
  return best;
}

int CachePointGrid::findLinear(const glm::vec3& p, const glm::vec3& n) const {
  int best = -1;
  float bestDist2 = INFINITY;
  for (uint32_t i = 0; i < spheres_.size(); ++i)
    if (spheres_[i].radius > 0.0f && std::isfinite(spheres_[i].radius)) better(spheres_[i], i, p, n, bestDist2, best);
  return best;
}

size_t CachePointGrid::memoryBytes() const {
  return sizeof(*this) + spheres_.capacity() * sizeof(LookupSphere) +
         entries_.capacity() * sizeof(Item) + (bucketStart_.capacity() + large_.capacity()) * sizeof(uint32_t);
}

}  // namespace vpl
