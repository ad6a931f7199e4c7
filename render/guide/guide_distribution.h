// The directional distribution of one cache point (Hua & Low 2015): representatives are the
// directions to its VPL clusters with weights (their estimated contribution, W/sr-like luminance).
// The target f(w) is the summed weight of the representatives within a cone of half-angle thetaC
// around w, divided by the cone's solid angle: the mean incoming radiance in that cone. Its sphere
// integral is exactly Z = sum of weights, so the sampling density is known in closed form:
//   pdf(w) = (1 - eps) f(w) / Z + eps / (4 pi)        (uniform when Z = 0).
// Exact sampling: a representative by weight, then a uniform direction in its cone.
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <vector>
#include <glm/glm.hpp>
#include "render/sampling/distribution_1d.h"
#include "render/sampling/rng.h"

namespace vpl {

struct GuideRepresentative {
  glm::vec3 direction{0, 0, 1};  // unit, world space, from the cache point towards the cluster
  float weight = 0.0f;           // >= 0
};

class GuideDistribution {
 public:
  // Below this many representatives the cone query scans linearly (faster than the kd-tree there).
  static constexpr size_t kLinearScanLimit = 48;

  GuideDistribution();
  GuideDistribution(std::vector<GuideRepresentative> representatives, float coneAngle, float defensive);
  GuideDistribution(GuideDistribution&&) noexcept;
  GuideDistribution& operator=(GuideDistribution&&) noexcept;
  ~GuideDistribution();

  // f(w): mean weight per steradian in the cone around w.
  float target(const glm::vec3& w) const;
  // Density of sample() per solid angle (includes the defensive term).
  float pdf(const glm::vec3& w) const;
  glm::vec3 sample(Rng& rng) const;

  double totalWeight() const { return total_; }
  size_t size() const { return reps_.size(); }
  float cosCone() const { return cosCone_; }
  float defensive() const { return defensive_; }
  const std::vector<GuideRepresentative>& representatives() const { return reps_; }

  // Sum of weights of the representatives within the cone around w: kd-tree or linear scan.
  double coneSum(const glm::vec3& w) const;
  double coneSumLinear(const glm::vec3& w) const;

  size_t memoryBytes() const;

 private:
  struct Index;  // nanoflann kd-tree over the unit vectors (only for many representatives)
  std::vector<GuideRepresentative> reps_;
  Distribution1D choice_;
  std::unique_ptr<Index> index_;
  double total_ = 0.0;
  float cosCone_ = 1.0f, chord2_ = 0.0f, coneSolidAngle_ = 0.0f, defensive_ = 0.01f;
};

}  // namespace vpl
