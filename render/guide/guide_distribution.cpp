#include "render/guide/guide_distribution.h"

#include <array>
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
                                     float defensive, bool bilinear)
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
  setTable(mass, bilinear);
  if (choice_.empty()) total_ = 0.0;
}

GuideDistribution::GuideDistribution(std::span<const float> cellWeights, float defensive, bool bilinear)
    : defensive_(defensive) {
  std::vector<float> mass(cellWeights.begin(), cellWeights.end());
  setTable(mass, bilinear);
  total_ = choice_.total();
}

void GuideDistribution::setTable(std::vector<float>& mass, bool bilinear) {
  if (bilinear) interpolateFromCorners(mass);
  choice_ = Distribution1D(mass);
  cellDensity_ = float((1.0 - defensive_) / kCellSolidAngle);
  if (choice_.empty()) corners_.clear();
  for (float& v : corners_) v = float(v / choice_.total());
}

namespace {
// A point of [0, 1] with density proportional to (1 - x) a + x b (a, b >= 0).
float sampleLinear(float u, float a, float b) {
  if (!(a + b > 0.0f) || a == b) return u;
  const float x = u * (a + b) / (a + std::sqrt((1.0f - u) * a * a + u * b * b));
  return std::min(x, 0x1.fffffep-1f);
}
}  // namespace

void GuideDistribution::interpolateFromCorners(std::vector<float>& cellWeights) {
  constexpr int r = kResolution, n = kResolution + 1;
  corners_.assign(size_t(n * n), 0.0f);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      float sum = 0.0f;
      int count = 0;
      for (int dj = -1; dj <= 0; ++dj)
        for (int di = -1; di <= 0; ++di) {
          const int x = i + di, y = j + dj;
          if (x < 0 || y < 0 || x >= r || y >= r) continue;
          const float w = cellWeights[size_t(y * r + x)];
          sum += std::isfinite(w) && w > 0.0f ? w : 0.0f;
          ++count;
        }
      corners_[size_t(j * n + i)] = sum / float(count);
    }
  for (int y = 0; y < r; ++y)
    for (int x = 0; x < r; ++x) {
      const float* below = cornersBelow(x, y);
      cellWeights[size_t(y * r + x)] = 0.25f * (below[0] + below[1] + below[n] + below[n + 1]);
    }
}

float GuideDistribution::interpolatedShare(const glm::vec3& w) const {
  constexpr int r = kResolution, n = kResolution + 1;
  const glm::vec2 p = equalAreaSphereToSquare(w) * float(r);
  const int ix = std::min(int(p.x), r - 1), iy = std::min(int(p.y), r - 1);
  const float fx = std::clamp(p.x - float(ix), 0.0f, 1.0f), fy = std::clamp(p.y - float(iy), 0.0f, 1.0f);
  const float* row0 = cornersBelow(ix, iy);
  const float* row1 = row0 + n;
  return (1.0f - fy) * ((1.0f - fx) * row0[0] + fx * row0[1]) + fy * ((1.0f - fx) * row1[0] + fx * row1[1]);
}

glm::vec2 GuideDistribution::warpInCell(int cell, glm::vec2 u) const {
  if (corners_.empty()) return u;
  constexpr int n = kResolution + 1;
  const float* row0 = cornersBelow(cell % kResolution, cell / kResolution);
  const float* row1 = row0 + n;
  const float x = sampleLinear(u.x, row0[0] + row1[0], row0[1] + row1[1]);
  const float y = sampleLinear(u.y, (1.0f - x) * row0[0] + x * row0[1], (1.0f - x) * row1[0] + x * row1[1]);
  return {x, y};
}

float GuideDistribution::pdf(const glm::vec3& w) const {
  if (choice_.empty()) return uniformSpherePdf();
  const float share = corners_.empty() ? choice_.pmf(size_t(cellOf(w))) : interpolatedShare(w);
  return cellDensity_ * share + defensive_ * uniformSpherePdf();
}

glm::vec3 GuideDistribution::sample(float uCell, glm::vec2 uPoint) const {
  if (choice_.empty() || uCell < defensive_) return sampleUniformSphere(uPoint);
  // Reuse uCell: it picks the cell after the defensive branch.
  const float uPick = std::min((uCell - defensive_) / (1.0f - defensive_), 0x1.fffffep-1f);
  const int cell = int(choice_.sample(uPick));
  return pointInCell(cell, warpInCell(cell, uPoint));
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
  if (!corners_.empty())
    if (const auto p = sampleAlongRow(int(row), uInRow, ux)) return equalAreaSquareToSphere(*p);
  float uInCell = 0.0f;
  const int cell = int(choice_.sampleRange(ux, row * n, (row + 1) * n, &uInCell));
  return pointInCell(cell, warpInCell(cell, {uInCell, uInRow}));
}

std::optional<glm::vec2> GuideDistribution::sampleAlongRow(int row, float uInRow, float ux) const {
  constexpr int r = kResolution, n = kResolution + 1;
  const float* below = cornersBelow(0, row);
  const float* above = below + n;
  float lineBelow = 0.0f, lineAbove = 0.0f;  // twice the density integrated along each line
  for (int i = 0; i < r; ++i) {
    lineBelow += below[i] + below[i + 1];
    lineAbove += above[i] + above[i + 1];
  }
  const float t = sampleLinear(uInRow, lineBelow, lineAbove);
  std::array<float, n> along;  // the density along height t, at the corners' columns
  for (int i = 0; i < n; ++i) along[size_t(i)] = (1.0f - t) * below[i] + t * above[i];
  float total = 0.0f;
  for (int i = 0; i < r; ++i) total += along[size_t(i)] + along[size_t(i) + 1];
  if (!(total > 0.0f)) return std::nullopt;
  // The cell whose share of the line holds ux; the last one with any, if rounding runs past the end.
  const float target = ux * total;
  int cell = -1;
  float before = 0.0f, beforeCell = 0.0f;
  for (int i = 0; i < r; ++i) {
    const float mass = along[size_t(i)] + along[size_t(i) + 1];
    if (!(mass > 0.0f)) continue;
    cell = i;
    beforeCell = before;
    if (before + mass > target) break;
    before += mass;
  }
  if (cell < 0) return std::nullopt;
  const float a = along[size_t(cell)], b = along[size_t(cell) + 1];
  const float uInCell = std::clamp((target - beforeCell) / (a + b), 0.0f, 0x1.fffffep-1f);
  constexpr float kInside = 0x1.fffffep-1f;
  const float x = sampleLinear(uInCell, a, b);
  return glm::vec2((float(cell) + x * kInside) / float(r), (float(row) + t * kInside) / float(r));
}

glm::vec3 GuideDistribution::pointInCell(int cell, glm::vec2 u) {
  constexpr float kInside = 0x1.fffffep-1f;
  const glm::vec2 p((float(cell % kResolution) + u.x * kInside) / float(kResolution),
                    (float(cell / kResolution) + u.y * kInside) / float(kResolution));
  return equalAreaSquareToSphere(p);
}

size_t GuideDistribution::memoryBytes() const {
  return sizeof(*this) + choice_.size() * (sizeof(double) + sizeof(float)) + corners_.size() * sizeof(float);
}

}  // namespace vpl
