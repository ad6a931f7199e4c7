// Learned next-event estimation: which part of which emitter each region of the scene sees.
//
// Where light enters through openings (skylights, a door ajar), most of an emitter is hidden from
// most points, and a light sample drawn by power and solid angle ends on the roof: its shadow ray is
// paid for nothing; a sky seen through windows sends most samples into walls. Here the scene's box
// is cut into regions, and the lights into cells: every emitting triangle's unit square (the domain
// of sampleUniformTriangle, whose map preserves area) into a grid, the sky's directions into the
// cells of an equal-area map (kSkyResolution^2 of them), and each punctual light is one. Every region
// starts with EmitterSet's own sampling (by power, then by solid angle or area) and records, per
// cell, what its unoccluded samples brought back (each sample's irradiance estimate: over its
// density, so the sums estimate each cell's whole share). Once kMinAttempts of its shadow rays are
// traced, a region decides for good: if fewer than kArrivalShare of them arrived (most light samples
// end on something else) it picks cell c with
//     P_r(c) = s base(c) + (1 - s) learned_r(c),
// base(c) its light's power share over the light's cell count, learned_r(c) the region's share of
// what was recorded from c, s = kBaseShare (no cell's density falls below that share of the power
// choice's), and a point uniform over the cell's area (a direction uniform over its solid angle for
// the sky); otherwise it keeps EmitterSet's sampling and
// records nothing more. So regions that see their lights (a Cornell box) keep solid-angle sampling,
// lose nothing to a noisy table and, after the first passes, pay only a region lookup.
//
// The tables and switches change only between passes and every strategy that asks the density (an
// emitter hit's MIS weight, a light path's first vertex in the joins' weights) sees the same, so the
// estimate stays unbiased whatever was learned; the records are integer sums, so the next pass's
// tables do not depend on the thread count.
//
// Up to kMaxCells emitting triangles each get a grid of cells. Beyond that (a tessellated lamp, a
// lamp in every room) a cell is a group of nearby triangles instead (their centroids split at the
// median of the longest axis, recursively, into kMaxCells groups), whose points a learned region
// samples uniformly by area: a triangle by its share of the group's area, then its point.
// Only for scenes of at most kMaxPunctual punctual lights and with more than one cell to choose from
// (otherwise inactive: the caller keeps EmitterSet's own sampling).
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>
#include <glm/glm.hpp>
#include "render/core/color.h"
#include "render/scene/emitters.h"
#include "render/scene/render_scene.h"

namespace vpl {

class EmitterGuide {
 public:
  // Measured on the skylit hall (brdf, 32 spp, seed 1, relMSE; 0.0496 without learning): the base
  // share 0.1 0.0383, 0.2 0.0329, 0.3 0.0321, 0.5 0.0341; 32 cells 0.0340, 512 0.0374; 256 regions
  // 0.0317, 4096 0.0342. At 128 spp the cells and regions changed the relMSE by 2 % at most.
  static constexpr float kBaseShare = 0.3f;
  static constexpr float kArrivalShare = 0.5f;
  static constexpr uint64_t kMinAttempts = 256;
  static constexpr int kMaxCells = 128;        // per region: cells over all triangles
  static constexpr int kMaxPunctual = 64;
  static constexpr int kSkyResolution = 16;
  static constexpr int kTargetRegions = 1024;  // the box is cut into about this many, near-cubic

  EmitterGuide() = default;
  // Inactive unless `enabled` and the scene's lights suit it (see above).
  EmitterGuide(const RenderScene& scene, bool enabled);

  bool active() const { return scene_ != nullptr; }
  // Between passes only: what the last pass's samples recorded joins the tables.
  void learnFromLastPass();

  // Next-event estimation from p (a point of the scene), from the numbers EmitterSet::sampleStratified
  // takes. In a learned region u.x picks the cell and, rescaled, with u.y the point within it. The
  // sample's guideSlot names its region and cell for attempted() and arrived().
  template <class SpareNumber>
  std::optional<LightSample> sample(const glm::vec3& p, glm::vec2 u, SpareNumber&& spareNumber) const {
    const uint32_t region = regionOf(p);
    if (state_[region] == State::Learned) return sampleLearned(p, region, u);
    auto s = scene_->emitters().sampleStratified(p, u, spareNumber);
    if (s && s->emitter >= 0 && state_[region] == State::Undecided) s->guideSlot = slotOf(region, *s, p);
    return s;
  }
  // The solid-angle density at p with which sample() picks the emitting point of a hit ...
  float pdf(const glm::vec3& p, const SurfaceHit& hit) const;
  // ... and the sky's direction wi.
  float pdfSky(const glm::vec3& p, const glm::vec3& wi) const;
  // The same for a light path's start e (EmitterSet::nextEventPdfTimesCos's meaning: times the
  // cosine at the light).
  float nextEventPdfTimesCos(const glm::vec3& p, const EmissionSample& e) const;
  // What a sample that arrived records: the luminance of its radiance times the receiver's cosine
  // over its density.
  static float arrivalValue(const glm::vec3& radiance, float cosReceiver, float pdf) {
    return luminance(radiance) * cosReceiver / pdf;
  }
  // A sample's shadow ray is traced ...
  void attempted(uint32_t slot) const {
    if (slot == UINT32_MAX) return;
    const uint32_t region = slot / uint32_t(cells_);
    if (state_[region] == State::Undecided) lane().attempts[region].fetch_add(1, std::memory_order_relaxed);
  }
  // ... and arrived, bringing back `value` (arrivalValue()). Any thread, any order.
  void arrived(uint32_t slot, float value) const {
    if (slot == UINT32_MAX) return;
    Lane& l = lane();
    const uint32_t region = slot / uint32_t(cells_);
    if (state_[region] == State::Undecided) l.arrivals[region].fetch_add(1, std::memory_order_relaxed);
    if (!l.touched[region].load(std::memory_order_relaxed)) l.touched[region].store(1, std::memory_order_relaxed);
    if (value > 0.0f)
      l.sumsOf(region, size_t(cells_))[slot % uint32_t(cells_)].fetch_add(uint64_t(std::min(value, kLargestRecord) * kFixedPoint),
                                                                          std::memory_order_relaxed);
  }
  // A region's state: Undecided samples as EmitterSet and records its light samples, Default samples as
  // EmitterSet (it decided against learning), Learned from its table.
  enum class State : uint8_t { Undecided, Default, Learned };
  // The regions' states, by index: the lanes' vector form of sampleStratified serves where sample() is
  // EmitterSet's and records nothing (path_lanes.cpp).
  const State* states() const { return state_.data(); }
  // The region of point (x, y, z), for floats (F, I = int32_t) or vectors of them (I: their integers;
  // toInt(t, i) truncates): regionOf's arithmetic, which the lanes share. (Results by reference: a
  // vector returned by value would change the ABI between code with and without AVX.)
  template <class F, class I, class ToInt>
  void regionIndex(const F& x, const F& y, const F& z, ToInt toInt, I& region) const {
    const F* v[3] = {&x, &y, &z};
    I c[3];
    for (int a = 0; a < 3; ++a) {
      F t = (*v[a] - low_[a]) * perUnit_[a];
      t = t > 0.0f ? t : F{};
      t = t < float(kTargetRegions) ? t : F{} + float(kTargetRegions);
      toInt(t, c[a]);
      c[a] = c[a] < regionsPerAxis_[a] - 1 ? c[a] : I{} + (regionsPerAxis_[a] - 1);  // c >= 0: t was
    }
    region = (c[2] * regionsPerAxis_.y + c[1]) * regionsPerAxis_.x + c[0];
  }
  // sample()'s pick in learned region `region` from the numbers u, where u.x falls in a cell of an
  // emitting triangle: the triangle, the point's square (sampleUniformTriangle's domain), the
  // probability that makes EmitterSet::sampleTriangleByArea's density, and the sample's guideSlot. False
  // where the cell is a punctual light's or the sky's, or has no mass. (The lanes draw the point.)
  struct TrianglePick {
    uint32_t triangle = 0, slot = UINT32_MAX;
    glm::vec2 square{0.0f};
    float choice = 0.0f;
  };
  bool pickLearnedTriangle(uint32_t region, glm::vec2 u, TrianglePick& out) const;
  // The share of regions that sample from what they learned.
  float learnedRegionShare() const;
  int regions() const { return int(state_.size()); }
  int cells() const { return cells_; }

 private:
  static constexpr float kFixedPoint = 65536.0f;  // 2^16: records are summed as integers
  static constexpr float kLargestRecord = 1.0e6f;
  // This pass's records, in kLanes copies: the threads record into different lanes (by the order
  // in which they first record), so that two cores do not pass the same cache lines back and forth.
  static constexpr size_t kLanes = 2;  // the 2-core machines measured; more threads share them (atomics)
  // A region's per-cell sums are made when a sample first records there (most of a scene's box holds
  // no surface, and a render job of a few pixels must not pay for tables it never touches).
  struct Lane {
    std::vector<std::atomic<std::atomic<uint64_t>*>> sums;  // per region: its cells' sums, or null
    std::vector<std::atomic<uint64_t>> attempts, arrivals;  // per region
    std::vector<std::atomic<uint8_t>> touched;               // per region: any sum this pass
    std::atomic<uint64_t>* sumsOf(uint32_t region, size_t cells);
    ~Lane();
  };
  // What a region has learned over every pass so far (made when it first records).
  struct Table {
    std::vector<double> sums;  // per cell
    double total = 0.0;
    std::vector<float> cdf;    // per cell, cumulative, the last exactly 1 (learned regions)
    // Per k < kCuts: the first cell whose cdf passes k / kCuts, where the search for u in
    // [k / kCuts, (k + 1) / kCuts) starts: a step or two instead of a binary search's mispredicted
    // branches (which took 11 % of a brdf sample on lamp_rooms).
    std::vector<uint16_t> cuts;
  };
  static constexpr int kCuts = 256;

  uint32_t regionOf(const glm::vec3& p) const {
    int32_t region;
    regionIndex<float, int32_t>(p.x, p.y, p.z, [](float t, int32_t& i) { i = int32_t(t); }, region);
    return uint32_t(region);
  }
  bool grouped() const { return !groupOf_.empty(); }
  // Cell index of a point of triangle t at `square` ...
  uint32_t cellOf(size_t triangle, glm::vec2 square) const {
    if (grouped()) return groupOf_[triangle];
    const glm::ivec2 c = glm::min(glm::ivec2(square * float(grid_)), glm::ivec2(grid_ - 1));
    return uint32_t((int(triangle) * grid_ + c.y) * grid_ + c.x);
  }
  // ... and at x (its square is needed only for a grid).
  uint32_t cellAt(size_t triangle, const glm::vec3& x) const {
    return grouped() ? groupOf_[triangle] : cellOf(triangle, scene_->emitters().squareOf(triangle, x));
  }
  // Splits the emitting triangles into kMaxCells groups of nearby ones (groupOf_ and the rest).
  void groupTriangles(const EmitterSet& emitters);
  uint32_t slotOf(uint32_t region, const LightSample& s, const glm::vec3& p) const;
  // The probability that learned region r picks `cell`.
  float cellPmf(uint32_t region, uint32_t cell) const {
    const float* cdf = tables_[region]->cdf.data();
    return cdf[cell] - (cell > 0 ? cdf[cell - 1] : 0.0f);
  }
  // The probability of triangle t that gives its points in `cell` the density learned region r
  // samples them with (EmitterSet::sampleTriangleByArea's `choice`): the cell's, times its cells on a
  // grid, times the triangle's share of its group's area.
  float triangleChoice(uint32_t region, size_t triangle, uint32_t cell) const {
    return cellPmf(region, cell) * (grouped() ? areaShare_[triangle] : float(grid_ * grid_));
  }
  // A learned region's cell for the number u, its slot (region and cell), u rescaled within the cell,
  // and the cell's probability (width 0: a cell without mass, which sends nothing).
  struct CellPick {
    uint32_t cell, slot;
    float x, width;
  };
  CellPick pickCell(uint32_t region, float u) const;
  // The triangle and square of a point of emitting triangle cell c, with v the point's second number.
  bool cellPoint(const CellPick& c, float v, TrianglePick& out) const;
  std::optional<LightSample> sampleLearned(const glm::vec3& p, uint32_t region, glm::vec2 u) const;
  Lane& lane() const;

  const RenderScene* scene_ = nullptr;
  int grid_ = 1;   // cells per side of a triangle's square (1 where grouped)
  // Grouped: each triangle's group (its cell) and share of the group's area; per group, its triangles
  // (from groupFirst_[g] to groupFirst_[g + 1] in groupTriangles_) and their cumulative area shares.
  std::vector<uint32_t> groupOf_;
  std::vector<float> areaShare_;
  std::vector<uint32_t> groupFirst_, groupTriangles_;
  std::vector<float> groupCdf_;
  int cells_ = 0;  // triangles x grid^2 (or the groups), then one per punctual light, then the sky's
  int punctualFirst_ = 0, skyFirst_ = 0;  // the first cells of punctual lights and of the sky
  glm::ivec3 regionsPerAxis_{1};
  glm::vec3 low_{0.0f}, perUnit_{0.0f};
  std::vector<float> base_;       // per cell: the power choice
  std::vector<State> state_;      // per region: Learned samples from its table, the others as EmitterSet
  std::vector<std::unique_ptr<Table>> tables_;  // per region: null until it records
  std::vector<uint64_t> attempts_, arrivals_;  // per region: every pass so far
  mutable std::vector<Lane> lanes_;
};

}  // namespace vpl
