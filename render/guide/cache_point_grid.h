// Which cache point serves a path vertex: the nearest one whose lookup sphere holds the vertex and
// whose normal agrees with the vertex's. A hashed uniform grid of the spheres answers it with one
// bucket scan (the path tracer asks at every vertex, so a kd-tree's k-nearest search cost a fifth of
// the guided modes' time). Spheres far larger than the cell go to a short list checked every time.
#pragma once
#include <cstdint>
#include <vector>
#include <glm/glm.hpp>

namespace vpl {

struct LookupSphere {
  glm::vec3 centre{0.0f};
  glm::vec3 normal{0, 0, 1};
  float radius = 0.0f;
};

class CachePointGrid {
 public:
  CachePointGrid() = default;
  CachePointGrid(std::vector<LookupSphere> spheres, float cosNormal);

  // Index of the nearest sphere containing p whose normal n agrees (dot >= cosNormal), or -1; ties
  // go to the lower index.
  int find(const glm::vec3& p, const glm::vec3& n) const;
  int findLinear(const glm::vec3& p, const glm::vec3& n) const;  // brute force, for tests

  size_t memoryBytes() const;

 private:
  bool better(const LookupSphere& s, uint32_t index, const glm::vec3& p, const glm::vec3& n, float& bestDist2,
              int& best) const;
  uint32_t bucketOf(int64_t x, int64_t y, int64_t z) const;

  std::vector<LookupSphere> spheres_;
  float cosNormal_ = 1.0f;
  float cell_ = 1.0f;
  uint32_t bucketMask_ = 0;
  struct Item {  // a copy of the sphere beside its index: a bucket scan reads one contiguous run
    LookupSphere sphere;
    uint32_t index;
  };
  std::vector<uint32_t> bucketStart_;  // CSR: entries_[bucketStart_[b] .. bucketStart_[b + 1])
  std::vector<Item> entries_;
  std::vector<uint32_t> large_;                  // spheres covering too many cells to insert
};

}  // namespace vpl
