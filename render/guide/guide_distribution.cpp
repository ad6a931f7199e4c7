#include "render/guide/guide_distribution.h"

#include <cmath>
#include <nanoflann.hpp>
#include "render/sampling/equal_area_map.h"
#include "render/sampling/warps.h"

namespace vpl {

namespace {

// The centres of the map's cells in a nanoflann kd-tree: one for the whole program, read-only.
class CellCentres {
 public:
  CellCentres() : centres_(GuideDistribution::kCells), tree_(3, *this, nanoflann::KDTreeSingleIndexAdaptorParams(8)) {
    for (int c = 0; c < GuideDistribution::kCells; ++c) {
      const int r = GuideDistribution::kResolution;
      centres_[size_t(c)] = equalAreaSquareToSphere({(float(c % r) + 0.5f) / float(r), (float(c / r) + 0.5f) / float(r)});
    }
    tree_.buildIndex();
  }
  static const CellCentres& get() {
    static const CellCentres instance;
    return instance;
  }
  const glm::vec3& centre(int cell) const { return centres_[size_t(cell)]; }

  // Appends the cells within squared chord `chord2` of d.
  void within(const glm::vec3& d, float chord2, std::vector<uint32_t>& out) const {
    Collect result{chord2, out};
    const float query[3] = {d.x, d.y, d.z};
    tree_.findNeighbors(result, query, nanoflann::SearchParams(32, 0.0f, false));
  }

  // nanoflann's dataset interface.
  size_t kdtree_get_point_count() const { return centres_.size(); }
  float kdtree_get_pt(size_t i, size_t dim) const { return centres_[i][int(dim)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const { return false; }

 private:
  // A result set that keeps every index within the radius, unsorted.
  struct Collect {
    float radius2;
    std::vector<uint32_t>& out;
    void init() {}
    size_t size() const { return out.size(); }
    bool full() const { return true; }
    float worstDist() const { return radius2; }
    bool addPoint(float dist2, uint32_t index) {
      if (dist2 <= radius2) out.push_back(index);
      return true;
    }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, CellCentres>, CellCentres, 3, uint32_t>;
  std::vector<glm::vec3> centres_;
  Tree tree_;
};

// A cone around a unit vector is a ball of this squared chord: |w - d|^2 = 2 (1 - cos theta). From
// the angle, 4 sin^2(theta/2) keeps its precision for narrow cones, where 1 - cos cancels.
float chord2FromCos(float cosCone) { return 2.0f * (1.0f - cosCone); }
float chord2FromAngle(float angle) {
  const float s = std::sin(0.5f * std::min(angle, 3.14159265f));
  return 4.0f * s * s;
}

}  // namespace

int GuideDistribution::cellOf(const glm::vec3& w) { return equalAreaCell(w, kResolution); }
glm::vec3 GuideDistribution::cellCentre(int cell) { return CellCentres::get().centre(cell); }

void GuideDistribution::coneCells(const glm::vec3& d, float cosCone, std::vector<uint32_t>& cells) {
  CellCentres::get().within(d, chord2FromCos(cosCone), cells);
}

void GuideDistribution::coneCellsLinear(const glm::vec3& d, float cosCone, std::vector<uint32_t>& cells) {
  const float chord2 = chord2FromCos(cosCone);
  for (int c = 0; c < kCells; ++c) {
    const glm::vec3 e = cellCentre(c) - d;
    if (glm::dot(e, e) <= chord2) cells.push_back(uint32_t(c));
  }
}

GuideDistribution::GuideDistribution(const std::vector<GuideRepresentative>& representatives, float coneAngle,
                                     float defensive)
    : defensive_(defensive), representativeCount_(representatives.size()) {
  const float chord2Default = chord2FromAngle(coneAngle);
  std::vector<float> mass(kCells, 0.0f);
  std::vector<uint32_t> cells;
  for (const GuideRepresentative& r : representatives) {
    const float len = glm::length(r.direction);
    if (!(r.weight > 0.0f) || !std::isfinite(r.weight) || !(len > 0.0f) || !std::isfinite(len)) continue;
    const glm::vec3 d = r.direction / len;
    cells.clear();
    CellCentres::get().within(d, r.coneAngle > coneAngle ? chord2FromAngle(r.coneAngle) : chord2Default, cells);
    if (cells.empty()) cells.push_back(uint32_t(cellOf(d)));  // a cone narrower than a cell
    const float share = r.weight / float(cells.size());
    for (uint32_t c : cells) mass[c] += share;
    total_ += r.weight;
  }
  choice_ = Distribution1D(mass);
  if (choice_.empty()) total_ = 0.0;
  cellDensity_ = float((1.0 - defensive_) / kCellSolidAngle);
}

GuideDistribution::GuideDistribution(std::span<const float> cellWeights, float defensive)
    : choice_(cellWeights), total_(choice_.total()), defensive_(defensive) {
  cellDensity_ = float((1.0 - defensive_) / kCellSolidAngle);
}

float GuideDistribution::pdf(const glm::vec3& w) const {
  if (choice_.empty()) return uniformSpherePdf();
  return cellDensity_ * choice_.pmf(size_t(cellOf(w))) + defensive_ * uniformSpherePdf();
}

glm::vec3 GuideDistribution::sample(float uCell, glm::vec2 uPoint) const {
  if (choice_.empty() || uCell < defensive_) return sampleUniformSphere(uPoint);
  // Reuse uCell: it picks the cell after the defensive branch.
  const float uPick = std::min((uCell - defensive_) / (1.0f - defensive_), 0x1.fffffep-1f);
  return pointInCell(int(choice_.sample(uPick)), uPoint);
}

glm::vec3 GuideDistribution::sample(glm::vec2 u) const {
  if (choice_.empty()) return sampleUniformSphere(u);
  if (u.x < defensive_) return sampleUniformSphere({std::min(u.x / defensive_, 0x1.fffffep-1f), u.y});
  const float ux = std::min((u.x - defensive_) / (1.0f - defensive_), 0x1.fffffep-1f);
  // Row by its share (u.y), then the cell within the row (u.x), both from the one flattened CDF: a
  // 2D inversion, so nearby numbers land in nearby cells and a stratified u stays stratified.
  constexpr size_t n = kResolution;
  const double y = std::clamp(double(u.y), 0.0, 1.0);
  size_t lo = 0, hi = n;  // the row r with cdf(r n) <= y < cdf((r + 1) n)
  while (hi - lo > 1) {
    const size_t mid = (lo + hi) / 2;
    (choice_.cdf(mid * n) <= y ? lo : hi) = mid;
  }
  size_t row = lo;
  while (!(choice_.cdf((row + 1) * n) > choice_.cdf(row * n)) && row > 0) --row;  // rounding at the top
  const double rowStart = choice_.cdf(row * n), rowMass = choice_.cdf((row + 1) * n) - rowStart;
  const float uInRow = float(std::clamp((y - rowStart) / rowMass, 0.0, double(0x1.fffffep-1f)));
  float uInCell = 0.0f;
  const int cell = int(choice_.sampleRange(ux, row * n, (row + 1) * n, &uInCell));
  return pointInCell(cell, {uInCell, uInRow});
}

glm::vec3 GuideDistribution::pointInCell(int cell, glm::vec2 u) {
  constexpr float kInside = 0x1.fffffep-1f;
  const glm::vec2 p((float(cell % kResolution) + u.x * kInside) / float(kResolution),
                    (float(cell / kResolution) + u.y * kInside) / float(kResolution));
  return equalAreaSquareToSphere(p);
}

size_t GuideDistribution::memoryBytes() const {
  return sizeof(*this) + choice_.size() * (sizeof(double) + sizeof(float));
}

}  // namespace vpl
