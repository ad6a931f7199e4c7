#include "render/guide/guide_distribution.h"

#include <cmath>
#include <nanoflann.hpp>
#include "render/core/frame.h"
#include "render/sampling/warps.h"

namespace vpl {

// nanoflann needs a dataset adaptor; it lives beside the tree at a stable address.
struct GuideDistribution::Index {
  struct Points {
    const std::vector<GuideRepresentative>* reps;
    size_t kdtree_get_point_count() const { return reps->size(); }
    float kdtree_get_pt(size_t i, size_t dim) const { return (*reps)[i].direction[int(dim)]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const { return false; }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Points>, Points, 3, uint32_t>;

  Points points;
  Tree tree;
  explicit Index(const std::vector<GuideRepresentative>& reps)
      : points{&reps}, tree(3, points, nanoflann::KDTreeSingleIndexAdaptorParams(8)) {
    tree.buildIndex();
  }
};

namespace {

// A nanoflann result set that only sums the weights of the points it is given.
struct WeightSum {
  const std::vector<GuideRepresentative>& reps;
  float radius2;
  double sum = 0.0;
  size_t count = 0;
  void init() {}
  size_t size() const { return count; }
  bool full() const { return true; }
  float worstDist() const { return radius2; }
  bool addPoint(float dist2, uint32_t index) {
    if (dist2 <= radius2) {
      sum += reps[index].weight;
      ++count;
    }
    return true;
  }
};

}  // namespace

GuideDistribution::GuideDistribution(std::vector<GuideRepresentative> representatives, float coneAngle, float defensive)
    : reps_(std::move(representatives)), defensive_(defensive) {
  for (GuideRepresentative& r : reps_) {
    const float len = glm::length(r.direction);
    r.direction = len > 0.0f ? r.direction / len : glm::vec3(0, 0, 1);
    if (!(r.weight > 0.0f) || !std::isfinite(r.weight)) r.weight = 0.0f;
  }
  std::vector<float> weights(reps_.size());
  for (size_t i = 0; i < reps_.size(); ++i) weights[i] = reps_[i].weight;
  choice_ = Distribution1D(weights);
  total_ = choice_.total();
  cosCone_ = std::cos(coneAngle);
  // |w - d|^2 = 2 (1 - cos): the cone is a ball of this squared chord around each representative.
  // 1 - cos = 2 sin^2(theta/2) avoids cancellation for small cones.
  const float oneMinusCos = 2.0f * std::sin(0.5f * coneAngle) * std::sin(0.5f * coneAngle);
  chord2_ = 2.0f * oneMinusCos;
  coneSolidAngle_ = 2.0f * kPi * oneMinusCos;
  if (reps_.size() > kLinearScanLimit) index_ = std::make_unique<Index>(reps_);
}

GuideDistribution::GuideDistribution(GuideDistribution&& o) noexcept { *this = std::move(o); }

GuideDistribution& GuideDistribution::operator=(GuideDistribution&& o) noexcept {
  reps_ = std::move(o.reps_);
  choice_ = std::move(o.choice_);
  index_ = std::move(o.index_);
  if (index_) index_->points.reps = &reps_;  // the vector's buffer moved with it; repoint the adaptor
  total_ = o.total_;
  cosCone_ = o.cosCone_;
  chord2_ = o.chord2_;
  coneSolidAngle_ = o.coneSolidAngle_;
  defensive_ = o.defensive_;
  return *this;
}

GuideDistribution::GuideDistribution() = default;
GuideDistribution::~GuideDistribution() = default;

double GuideDistribution::coneSumLinear(const glm::vec3& w) const {
  double sum = 0.0;
  for (const GuideRepresentative& r : reps_) {
    const glm::vec3 d = r.direction - w;
    if (glm::dot(d, d) <= chord2_) sum += r.weight;
  }
  return sum;
}

double GuideDistribution::coneSum(const glm::vec3& w) const {
  if (!index_) return coneSumLinear(w);
  WeightSum result{reps_, chord2_};
  const float query[3] = {w.x, w.y, w.z};
  index_->tree.findNeighbors(result, query, nanoflann::SearchParams(32, 0.0f, false));
  return result.sum;
}

float GuideDistribution::target(const glm::vec3& w) const {
  return total_ > 0.0 ? float(coneSum(w) / coneSolidAngle_) : 0.0f;
}

float GuideDistribution::pdf(const glm::vec3& w) const {
  if (!(total_ > 0.0)) return uniformSpherePdf();
  return float((1.0 - defensive_) * coneSum(w) / (coneSolidAngle_ * total_)) + defensive_ * uniformSpherePdf();
}

glm::vec3 GuideDistribution::sample(Rng& rng) const {
  const float u = rng.uniform();
  const glm::vec2 u2 = rng.uniform2();
  if (!(total_ > 0.0) || u < defensive_) return sampleUniformSphere(u2);
  // Reuse u: it picks the representative after the defensive branch.
  const float uPick = std::min((u - defensive_) / (1.0f - defensive_), 0x1.fffffep-1f);
  const GuideRepresentative& r = reps_[choice_.sample(uPick)];
  return glm::normalize(Frame::fromNormal(r.direction).toWorld(sampleUniformCone(u2, cosCone_)));
}

size_t GuideDistribution::memoryBytes() const {
  // Representatives + CDF + pmf; the kd-tree adds about one index and a few nodes per point.
  return sizeof(*this) + reps_.capacity() * sizeof(GuideRepresentative) + reps_.size() * (sizeof(double) + sizeof(float)) +
         (index_ ? reps_.size() * (sizeof(uint32_t) + 24) : 0);
}

}  // namespace vpl
