// Splits gather points (primary hits) into slices with a 6D kd-tree over (position, normal scaled
// by normalScale): median split on the longest axis of the 6D box until a node holds at most
// maxSliceSize points (LightSlice §4, and Hua & Low's cache points). Flat arrays throughout.
//
// Parameters (SliceSettings):
//   maxSliceSize  int    256   largest slice, in gather points
//   normalScale   float  0     weight of the normal in the 6D distance; 0 = scene diagonal / 16
//   neighbours    int    32    nearest slices (6D distance of representatives, itself included)
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>
#include <glm/glm.hpp>

namespace vpl {

struct GatherPoint {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0, 0, 1};
};

struct SliceSettings {
  int maxSliceSize = 256;
  float normalScale = 0.0f;
  int neighbours = 32;
  std::string validate() const;
};

struct Slice {
  uint32_t begin = 0, end = 0;   // range in SliceTree::order
  uint32_t representative = 0;   // a member gather point: the one nearest the slice's 6D centroid
  float radius2 = 0.0f;          // mean squared 6D distance of the members from the representative
};

// Squared distance of two gather points in the 6D embedding (position, normal x normalScale).
inline float embeddedDistance2(const GatherPoint& a, const GatherPoint& b, float normalScale) {
  const glm::vec3 dp = a.position - b.position, dn = (a.normal - b.normal) * normalScale;
  return glm::dot(dp, dp) + glm::dot(dn, dn);
}

struct SliceTree {
  std::vector<uint32_t> order;       // gather point indices grouped by slice
  std::vector<Slice> slices;
  std::vector<uint32_t> sliceOf;     // per gather point
  std::vector<uint32_t> neighbours;  // slices.size() x neighbourCount, nearest first (itself first)
  int neighbourCount = 0;
  float normalScale = 1.0f;          // the scale actually used

  std::span<const uint32_t> neighboursOf(uint32_t slice) const {
    return {neighbours.data() + size_t(slice) * size_t(neighbourCount), size_t(neighbourCount)};
  }
};

SliceTree buildSliceTree(std::span<const GatherPoint> points, const SliceSettings& settings, float sceneDiagonal);

}  // namespace vpl
