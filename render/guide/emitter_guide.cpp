#include "render/guide/emitter_guide.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include "render/sampling/equal_area_map.h"
#include "render/sampling/warps.h"

namespace vpl {

EmitterGuide::EmitterGuide(const RenderScene& scene, bool enabled) {
  const EmitterSet& emitters = scene.emitters();
  const size_t triangles = emitters.triangleCount(), punctual = emitters.punctualCount();
  if (!enabled || emitters.empty() || punctual > size_t(kMaxPunctual)) return;
  if (triangles > size_t(kMaxCells)) {
    groupTriangles(emitters);
    for (size_t g = 0; g + 1 < groupFirst_.size(); ++g) {
      float power = 0.0f;
      for (uint32_t k = groupFirst_[g]; k < groupFirst_[g + 1]; ++k) power += emitters.emitterPmf(groupTriangles_[k]);
      base_.push_back(power);
    }
  } else {
    // The finest square grid that keeps every triangle's cells within kMaxCells in all.
    while (triangles > 0 && triangles * size_t(4 * grid_ * grid_) <= size_t(kMaxCells)) grid_ *= 2;
    for (size_t t = 0; t < triangles; ++t)
      for (int c = 0; c < grid_ * grid_; ++c) base_.push_back(emitters.emitterPmf(t) / float(grid_ * grid_));
  }
  punctualFirst_ = int(base_.size());
  for (size_t i = 0; i < punctual; ++i) base_.push_back(emitters.emitterPmf(triangles + i));
  skyFirst_ = int(base_.size());
  if (emitters.skyIndex() >= 0) {
    const int bins = kSkyResolution * kSkyResolution;
    for (int c = 0; c < bins; ++c) base_.push_back(emitters.emitterPmf(size_t(emitters.skyIndex())) / float(bins));
  }
  cells_ = int(base_.size());
  if (cells_ < 2) return;  // one light, one cell: nothing to choose
  // Near-cubic regions, about kTargetRegions of them; a flat box gets one layer along its thin axis.
  low_ = scene.data().boundsMin;
  const glm::vec3 extent = glm::max(scene.data().boundsMax - low_, glm::vec3(0.0f));
  const float largest = std::max(extent.x, std::max(extent.y, extent.z));
  if (!(largest > 0.0f) || !std::isfinite(largest)) return;
  const glm::vec3 safe = glm::max(extent, glm::vec3(largest * 1e-3f));
  const float side = std::cbrt(safe.x * safe.y * safe.z / float(kTargetRegions));
  regionsPerAxis_ = glm::clamp(glm::ivec3(glm::round(safe / side)), glm::ivec3(1), glm::ivec3(kTargetRegions));
  perUnit_ = glm::vec3(regionsPerAxis_) / safe;
  const size_t regionCount = size_t(regionsPerAxis_.x) * size_t(regionsPerAxis_.y) * size_t(regionsPerAxis_.z);
  state_.assign(regionCount, State::Undecided);
  tables_.resize(regionCount);
  attempts_.assign(regionCount, 0);
  arrivals_.assign(regionCount, 0);
  lanes_ = std::vector<Lane>(kLanes);
  for (Lane& l : lanes_) {
    l.sums = std::vector<std::atomic<std::atomic<uint64_t>*>>(regionCount);
    l.attempts = std::vector<std::atomic<uint64_t>>(regionCount);
    l.arrivals = std::vector<std::atomic<uint64_t>>(regionCount);
    l.touched = std::vector<std::atomic<uint8_t>>(regionCount);
  }
  scene_ = &scene;
}

void EmitterGuide::groupTriangles(const EmitterSet& emitters) {
  const size_t n = emitters.triangleCount();
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  // Depth first, the lower half first, so that the groups come out as consecutive runs of `order`.
  struct Range {
    size_t first, last;
    int groups;
  };
  std::vector<Range> pending{{0, n, kMaxCells}};
  groupFirst_.clear();
  while (!pending.empty()) {
    const Range r = pending.back();
    pending.pop_back();
    if (r.groups == 1) {
      groupFirst_.push_back(uint32_t(r.first));
      continue;
    }
    glm::vec3 low(INFINITY), high(-INFINITY);
    for (size_t k = r.first; k < r.last; ++k) {
      low = glm::min(low, emitters.triangleCentroid(order[k]));
      high = glm::max(high, emitters.triangleCentroid(order[k]));
    }
    const glm::vec3 extent = high - low;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    // Each side keeps as many triangles per group as the other (n > kMaxCells: at least one each).
    const int lowerGroups = r.groups / 2;
    const size_t middle = r.first + (r.last - r.first) * size_t(lowerGroups) / size_t(r.groups);
    std::nth_element(order.begin() + std::ptrdiff_t(r.first), order.begin() + std::ptrdiff_t(middle),
                     order.begin() + std::ptrdiff_t(r.last), [&](uint32_t a, uint32_t b) {
                       const float ca = emitters.triangleCentroid(a)[axis], cb = emitters.triangleCentroid(b)[axis];
                       return ca < cb || (ca == cb && a < b);
                     });
    pending.push_back({middle, r.last, r.groups - lowerGroups});
    pending.push_back({r.first, middle, lowerGroups});
  }
  groupFirst_.push_back(uint32_t(n));
  groupTriangles_ = std::move(order);
  groupOf_.assign(n, 0);
  areaShare_.assign(n, 0.0f);
  groupCdf_.assign(n, 0.0f);
  for (size_t g = 0; g + 1 < groupFirst_.size(); ++g) {
    double area = 0.0;
    for (uint32_t k = groupFirst_[g]; k < groupFirst_[g + 1]; ++k) area += double(emitters.triangleArea(groupTriangles_[k]));
    double cumulative = 0.0;
    for (uint32_t k = groupFirst_[g]; k < groupFirst_[g + 1]; ++k) {
      const uint32_t t = groupTriangles_[k];
      groupOf_[t] = uint32_t(g);
      areaShare_[t] = float(double(emitters.triangleArea(t)) / area);
      cumulative += double(emitters.triangleArea(t)) / area;
      groupCdf_[k] = float(cumulative);
    }
    groupCdf_[groupFirst_[g + 1] - 1] = 1.0f;
  }
}

std::atomic<uint64_t>* EmitterGuide::Lane::sumsOf(uint32_t region, size_t cells) {
  std::atomic<uint64_t>* block = sums[region].load(std::memory_order_acquire);
  if (block) return block;
  auto* made = new std::atomic<uint64_t>[cells]();
  // Two threads of one lane may race to make it: one block wins, the other is freed unused.
  if (sums[region].compare_exchange_strong(block, made, std::memory_order_acq_rel)) return made;
  delete[] made;
  return block;
}

EmitterGuide::Lane::~Lane() {
  for (auto& block : sums) delete[] block.load(std::memory_order_relaxed);
}

EmitterGuide::Lane& EmitterGuide::lane() const {
  static std::atomic<size_t> next{0};
  static thread_local const size_t index = next.fetch_add(1, std::memory_order_relaxed) % kLanes;
  return lanes_[index];
}


uint32_t EmitterGuide::slotOf(uint32_t region, const LightSample& s, const glm::vec3& p) const {
  const size_t e = size_t(s.emitter);
  uint32_t cell;
  const size_t triangles = scene_->emitters().triangleCount();
  if (e < triangles) cell = cellAt(e, p + s.wi * s.distance);
  else if (int(e) == scene_->emitters().skyIndex()) cell = uint32_t(skyFirst_ + equalAreaCell(s.wi, kSkyResolution));
  else cell = uint32_t(punctualFirst_) + uint32_t(e - triangles);
  return region * uint32_t(cells_) + cell;
}

float EmitterGuide::learnedRegionShare() const {
  if (state_.empty()) return 0.0f;
  return float(double(std::count(state_.begin(), state_.end(), State::Learned)) / double(state_.size()));
}

namespace {

// A lane's counter, emptied. A plain load first: a locked exchange on every region of every lane each
// pass cost more than the passes of a small render.
template <class T>
T take(std::atomic<T>& counter) {
  return counter.load(std::memory_order_relaxed) != 0 ? counter.exchange(0, std::memory_order_relaxed) : T(0);
}

}  // namespace

void EmitterGuide::learnFromLastPass() {
  if (!active()) return;
  for (size_t r = 0; r < state_.size(); ++r) {
    if (state_[r] == State::Default) continue;
    bool touched = false, attempted = false;
    for (Lane& l : lanes_) {
      const uint64_t a = take(l.attempts[r]);
      attempts_[r] += a;
      attempted |= a > 0;
      arrivals_[r] += take(l.arrivals[r]);
      touched |= take(l.touched[r]) != 0;
    }
    if (!touched && !attempted) continue;  // nothing new here (most of the box, every pass)
    // An undecided region's sums wait in the lanes until it decides: folding them every pass was most
    // of a small render's time.
    const bool deciding = state_[r] == State::Undecided && attempts_[r] >= kMinAttempts;
    if ((touched && state_[r] == State::Learned) || deciding) {
      if (!tables_[r]) tables_[r] = std::make_unique<Table>(Table{std::vector<double>(size_t(cells_), 0.0), 0.0, {}, {}});
      Table& t = *tables_[r];
      for (Lane& l : lanes_) {
        std::atomic<uint64_t>* block = l.sums[r].load(std::memory_order_acquire);
        if (!block) continue;
        for (int c = 0; c < cells_; ++c) {
          const double sum = double(take(block[c])) / double(kFixedPoint);
          t.sums[size_t(c)] += sum;
          t.total += sum;
        }
      }
    }
    // The switch, once: to learning where most light samples were wasted and something arrived.
    bool switched = false;
    if (deciding) {
      const bool wasted = double(arrivals_[r]) < double(kArrivalShare) * double(attempts_[r]);
      state_[r] = wasted && tables_[r]->total > 0.0 ? State::Learned : State::Default;
      switched = state_[r] == State::Learned;
    }
    if (state_[r] != State::Learned || !(touched || switched)) continue;
    Table& t = *tables_[r];
    t.cdf.resize(size_t(cells_));
    double cumulative = 0.0;
    for (int c = 0; c < cells_; ++c) {
      cumulative += double(kBaseShare) * double(base_[size_t(c)]) + (1.0 - double(kBaseShare)) * t.sums[size_t(c)] / t.total;
      t.cdf[size_t(c)] = float(cumulative);
    }
    t.cdf.back() = 1.0f;
    t.cuts.resize(kCuts);
    int cell = 0;
    for (int k = 0; k < kCuts; ++k) {
      while (cell + 1 < cells_ && t.cdf[size_t(cell)] <= float(k) / float(kCuts)) ++cell;
      t.cuts[size_t(k)] = uint16_t(cell);
    }
  }
}

EmitterGuide::CellPick EmitterGuide::pickCell(uint32_t region, float u) const {
  const Table& table = *tables_[region];
  const float* cdf = table.cdf.data();
  // The first cell whose cumulative probability passes u (the last if none does); u rescaled within
  // it serves the point.
  uint32_t cell = table.cuts[size_t(std::min(int(u * float(kCuts)), kCuts - 1))];
  while (cell + 1 < uint32_t(cells_) && cdf[cell] <= u) ++cell;
  const float low = cell > 0 ? cdf[cell - 1] : 0.0f, width = cdf[cell] - low;
  const uint32_t slot = region * uint32_t(cells_) + cell;
  if (!(width > 0.0f)) return {cell, slot, 0.0f, 0.0f};
  return {cell, slot, std::clamp((u - low) / width, 0.0f, std::nextafter(1.0f, 0.0f)), width};
}

bool EmitterGuide::cellPoint(const CellPick& c, float v, TrianglePick& out) const {
  if (grouped()) {
    // A triangle of the group by its share of the group's area (x rescaled once more), then its point.
    const uint32_t first = groupFirst_[c.cell], count = groupFirst_[c.cell + 1] - first;
    const float* shares = groupCdf_.data() + first;
    // The first triangle whose cumulative share passes x (the last if none does), from where it would
    // be if the areas were equal: a step or two on a tessellated lamp.
    uint32_t k = std::min(uint32_t(c.x * float(count)), count - 1);
    while (k > 0 && shares[k - 1] > c.x) --k;
    while (k + 1 < count && shares[k] <= c.x) ++k;
    const float before = k > 0 ? shares[k - 1] : 0.0f, share = shares[k] - before;
    if (!(share > 0.0f)) return false;
    out.triangle = groupTriangles_[first + k];
    out.square = glm::vec2(std::clamp((c.x - before) / share, 0.0f, std::nextafter(1.0f, 0.0f)), v);
    out.choice = c.width * areaShare_[out.triangle];
    return true;
  }
  out.triangle = c.cell / uint32_t(grid_ * grid_);
  const uint32_t inTriangle = c.cell % uint32_t(grid_ * grid_);
  out.square = (glm::vec2(float(inTriangle % uint32_t(grid_)), float(inTriangle / uint32_t(grid_))) + glm::vec2(c.x, v)) /
               float(grid_);
  out.choice = c.width * float(grid_ * grid_);
  return true;
}

bool EmitterGuide::pickLearnedTriangle(uint32_t region, glm::vec2 u, TrianglePick& out) const {
  const CellPick c = pickCell(region, u.x);
  if (!(c.width > 0.0f) || c.cell >= uint32_t(punctualFirst_)) return false;
  out.slot = c.slot;
  return cellPoint(c, u.y, out);
}

std::optional<LightSample> EmitterGuide::sampleLearned(const glm::vec3& p, uint32_t region, glm::vec2 u) const {
  const CellPick c = pickCell(region, u.x);
  if (!(c.width > 0.0f)) return std::nullopt;
  if (c.cell >= uint32_t(skyFirst_)) {
    // A direction uniform in the sky cell's solid angle (the map preserves area).
    const uint32_t bin = c.cell - uint32_t(skyFirst_);
    const glm::vec2 square = (glm::vec2(float(bin % uint32_t(kSkyResolution)), float(bin / uint32_t(kSkyResolution))) +
                              glm::vec2(c.x, u.y)) / float(kSkyResolution);
    LightSample s;
    s.wi = glm::normalize(equalAreaSquareToSphere(square));
    s.radiance = scene_->emitters().sky();
    s.pdf = c.width * float(kSkyResolution * kSkyResolution) / (4.0f * kPi);
    s.emitter = scene_->emitters().skyIndex();
    s.guideSlot = c.slot;
    return s;
  }
  if (c.cell >= uint32_t(punctualFirst_)) {
    const EmitterSet& emitters = scene_->emitters();
    auto s = emitters.samplePunctual(p, emitters.triangleCount() + (c.cell - uint32_t(punctualFirst_)), c.width);
    if (s) s->guideSlot = c.slot;
    return s;
  }
  TrianglePick t;
  if (!cellPoint(c, u.y, t)) return std::nullopt;
  auto s = scene_->emitters().sampleTriangleByArea(p, t.triangle, t.square, t.choice);
  if (s) s->guideSlot = c.slot;
  return s;
}

float EmitterGuide::pdfSky(const glm::vec3& p, const glm::vec3& wi) const {
  const uint32_t region = regionOf(p);
  if (state_[region] != State::Learned) return scene_->emitters().pdfSky(wi);
  const uint32_t cell = uint32_t(skyFirst_ + equalAreaCell(wi, kSkyResolution));
  return cellPmf(region, cell) * float(kSkyResolution * kSkyResolution) / (4.0f * kPi);
}

float EmitterGuide::pdf(const glm::vec3& p, const SurfaceHit& hit) const {
  const EmitterSet& emitters = scene_->emitters();
  const uint32_t region = regionOf(p);
  if (state_[region] != State::Learned) return emitters.pdfTriangle(p, hit);
  const int32_t t = emitters.emitterOf(hit);
  if (t < 0) return 0.0f;
  const float choice = triangleChoice(region, size_t(t), cellAt(size_t(t), hit.position));
  return emitters.solidAnglePdfOfArea(p, size_t(t), hit.position, hit.geometricNormal, hit.frontFace, choice);
}

float EmitterGuide::nextEventPdfTimesCos(const glm::vec3& p, const EmissionSample& e) const {
  const EmitterSet& emitters = scene_->emitters();
  const uint32_t region = regionOf(p);
  if (state_[region] != State::Learned) return emitters.nextEventPdfTimesCos(p, e);
  if (e.emitter >= emitters.triangleCount()) {
    // A punctual light: EmitterSet's figure is linear in the choice's probability. (The sky has no
    // light paths that joins weigh.)
    const uint32_t cell = uint32_t(punctualFirst_) + uint32_t(e.emitter - emitters.triangleCount());
    return emitters.nextEventPdfTimesCos(p, e) / emitters.emitterPmf(e.emitter) * cellPmf(region, cell);
  }
  const glm::vec3 d = p - e.position;
  const float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.0f)) return 0.0f;
  const bool front = glm::dot(e.normal, emitters.triangleNormal(e.emitter)) > 0.0f;
  const float solidAngle = emitters.solidAnglePdfOfArea(p, e.emitter, e.position, e.normal, front,
                                                        triangleChoice(region, e.emitter, cellOf(e.emitter, e.square)));
  return solidAngle * std::abs(glm::dot(e.normal, d)) / std::sqrt(dist2);
}

}  // namespace vpl
