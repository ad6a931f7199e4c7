// VPL connections: the light vertices a camera path connects to (bidirectional path tracing with a
// light vertex cache, Davidovič et al. 2014). Each pass traces fresh light paths from the emitters,
// as instant radiosity does for its VPLs, and keeps every vertex they reach. A camera vertex joins
// a few of them (ConnectionSettings::joinsPerVertex; see "Which vertex" below); multiple importance sampling (the balance of all ways to make a
// path: BSDF sampling, next-event estimation, connection at each vertex; power heuristic) weights
// each connection, so the VPLs carry the light that reaches the camera's room through a door while
// the short connections, which instant radiosity clamps, are left to the other strategies: no bias.
// The MIS weights follow the recursive form of Georgiev's "Implementing Vertex Connection and
// Merging" (2012), without merging and without light tracing to the camera.
//
// Which vertex: Davidovič et al. pick uniformly. Where the light reaches the camera's room only
// through a slit, nearly every such join is occluded (door_ajar: 4 % of joins arrive). So the
// scene's box is cut into cells, and a join picks a cell in proportion to what joins to that cell's
// vertices brought back in the earlier passes of the film (each an estimate of the cell's whole
// contribution: the join's value over its pick probability), mixed with the uniform choice
// (kUniformShare, so that no vertex's probability falls below that share of uniform's), then a
// vertex of the cell uniformly. The join divides by the probability it was actually picked with.
// The MIS weights count a join to a vertex of cell k as m_k joins of uniform choice, m_k being the
// cell's expected pick rate over uniform's from the earlier passes (misFactor): fixed during a
// pass and known on both sides, it is the same for every way of making a path, so the weights
// still sum to 1 (and the estimate stays unbiased) even where this pass's actual rate differs.
//
// Parameters:
//   paths     per pass (ConnectionSettings::paths): more paths, less correlation between pixels of
//             one pass, more tracing per pass and a cache that falls out of the CPU's
//   maxLength most segments of a light subpath (the path tracer's maxDepth - 1)
#pragma once
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>
#include <glm/glm.hpp>
#include "render/integrator/sampling_mode.h"
#include "render/material/bsdf.h"
#include "render/scene/render_scene.h"

namespace vpl {

class EmitterGuide;

// The heuristic applied to every density ratio of the weights (power 2, as the tracer's own MIS).
inline float connectionMis(float ratio) { return ratio * ratio; }

struct ConnectionSettings {
  // Light paths per pass; 0: no connections; -1 (auto): in the guided modes a 32nd of the pixels,
  // at least 1024, at most 8192; none in brdf. Fewer paths than that measured faster at the same
  // error: the joins' random reads stay in cache (door_ajar 320x240 mis 10 s: 19200 paths 57 spp,
  // relMSE 0.185; 4096 81 spp, 0.137; 1024 83 spp, 0.134).
  int paths = -1;
  // Joins pick vertices by what their cells brought back (true) or uniformly (false).
  bool learnChoice = true;
  // Joins per camera vertex, systematic over the cells' choice: one number u picks (j + u) / n, each
  // join weighs 1/n, and the MIS weights count n joins. Equal time, mis, 10 s, 4 seeds, relMSE of 2
  // joins over 1 (3, 4): door_ajar 0.79 (0.74, 0.75), two_rooms 0.84 (0.86, 0.83), interior 0.81
  // (0.82, 0.83), Cornell box 0.94 (0.97, 1.03), cornell_glossy 1.03 (1.11, 1.20), 2 seeds for the last two.
  int joinsPerVertex = 2;
  static constexpr int kMaxJoinDepth = 2;
  static constexpr int kJoinDepthAuto = -2;
  // The deepest camera vertex that joins (0: the camera ray's hit), or -1: every vertex, or -2
  // (kJoinDepthAuto, the default): the render measures -1 and 1 (JoinDepthTrial::kCandidates) on the
  // same passes and keeps the one that pays (at 64 spp, relMSE x time 0.91-0.98 of every vertex's
  // where it keeps 1, and every vertex's own image elsewhere). A join's
  // weight leaves out the joins that a limit forbids on either side, so the estimate stays unbiased
  // (LightVertex keeps the terms of the joins that a limit of kMaxJoinDepth or less may allow apart).
  int joinDepth = kJoinDepthAuto;
  // Russian roulette on a join's shadow ray: a join whose contribution, were nothing in the way, is
  // below this share of what its camera sample has brought back so far traces its ray only with
  // probability contribution / (share x that value), at least kMinShadowSurvival, and weighs one
  // over it. The probability is known before its number is drawn, so the estimate stays unbiased;
  // the added variance is at most share^2 times the sample's value squared per join. 0: every join
  // traces its ray.
  float shadowRoulette = 0.0f;
  static constexpr float kMinShadowSurvival = 0.05f;

  int pathsFor(int pixels, SamplingMode mode) const;
  std::string validate() const;
};

struct LightVertex {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f};  // geometric, on the side the light arrived from
  glm::vec3 wIn{0.0f};     // unit, back towards the previous vertex of the light path
  // The light path's throughput to here over its density, with the arriving segment's cosine at
  // this vertex divided out: a connection multiplies it by both BSDFs and the cosine towards the
  // camera vertex over the squared distance.
  glm::vec3 alpha{0.0f};
  float dVC = 0.0f, dVCM = 0.0f;  // the MIS partial sums (Georgiev 2012) at this vertex
  // For a join depth limit: the part of dVC that is not joins (next-event estimation, emitter hits),
  // and the part that is the join two vertices back towards the light (made by a camera vertex two
  // deeper than the one that joins here). dVCM is a join for length >= 2, next-event estimation at 1.
  float dVCNotJoins = 0.0f, dVCJoinTwoBack = 0.0f;
  int length = 0;                 // segments from the light
  uint32_t cell = 0;              // the cache's cell of position
  Bsdf bsdf;
};

class LightVertexCache {
 public:
  static constexpr int kCellsPerAxis = 8;
  static constexpr float kUniformShare = 0.3f;

  static constexpr int kMaxJoinsPerVertex = 16;

  explicit LightVertexCache(const ConnectionSettings& s)
      : learnChoice_(s.learnChoice), joinsPerVertex_(std::clamp(s.joinsPerVertex, 1, kMaxJoinsPerVertex)),
        joinDepth_(clampJoinDepth(s.joinDepth)),
        shadowRoulette_(std::max(0.0f, s.shadowRoulette)), misFactor_(kCells, connectionMis(float(joinsPerVertex_))) {}

  // Traces `paths` light paths of pass `pass` and takes what the joins of the earlier passes
  // recorded into the cells' choice: the cache depends on nothing else (not threads). Path i of a
  // pass takes the i-th point of the pass's scrambled Sobol sequences (`stratified`: its start, the
  // emitter folded into the position's x, and its first scatterings; render/vpl/light_walk.h) or
  // numbers hashed from (seed, pass, path). Subpaths end after maxLength segments or by Russian
  // roulette. Empty for lights that connections do not support.
  // `emitterGuide`: the tracer's learned next-event estimation, if any (its density enters the weights).
  void build(const RenderScene& scene, uint64_t seed, uint64_t pass, int paths, int maxLength, bool stratified,
             const EmitterGuide* emitterGuide = nullptr);

  bool empty() const { return vertices_.empty(); }
  int joinsPerVertex() const { return joinsPerVertex_; }
  // Between passes only: the depth the next pass's camera vertices join to (-1: every vertex).
  void setJoinDepth(int depth) { joinDepth_ = clampJoinDepth(depth); }
  int joinDepth() const { return joinDepth_; }
  // Whether a camera vertex at `depth` joins (ConnectionSettings::joinDepth), under this cache's
  // depth or under `limit` (a depth the tracer weighs a counterfactual estimate for).
  bool joinsAt(int depth) const { return joinsAt(depth, joinDepth_); }
  static bool joinsAt(int depth, int limit) { return limit < 0 || depth <= limit; }
  // The light side's sum of a join from a camera vertex at `depth` to y, over the ways of making the
  // same path with the connection nearer the light that the depth limit allows; lightPdf: y's BSDF
  // density from the join's direction back along the light path; limit: the join depth weighed (the
  // pass's own, joinDepth(), or a counterfactual's; -1: every vertex).
  static float lightSideSum(const LightVertex& y, int depth, float lightPdf, int limit) {
    static_assert(ConnectionSettings::kMaxJoinDepth <= 2, "a light vertex keeps only the join two back apart");
    if (limit < 0) return y.dVCM + y.dVC * connectionMis(lightPdf);
    const float oneBack = y.length == 1 || joinsAt(depth + 1, limit) ? y.dVCM : 0.0f;
    return oneBack + (y.dVCNotJoins + (joinsAt(depth + 2, limit) ? y.dVCJoinTwoBack : 0.0f)) * connectionMis(lightPdf);
  }
  float shadowRoulette() const { return shadowRoulette_; }
  const std::vector<LightVertex>& vertices() const { return vertices_; }
  // The vertex for the number u in [0, 1); scale is one over its pick probability times the path
  // count (each camera vertex stands for one light path's worth of joins) and the joins per vertex.
  const LightVertex& pick(float u, float& scale) const {
    const size_t c = cellFor(u);
    const float low = c > 0 ? cellCdf_[c - 1] : 0.0f, width = cellCdf_[c] - low;
    const uint32_t n = cellCount_[c];
    const uint32_t i = std::min(n - 1, uint32_t(std::max(0.0f, (u - low) / width) * float(n)));
    scale = cellScale_[c];
    return vertices_[cellStart_[c] + i];
  }
  // What a join to y brought back (luminance, with every factor of the estimate): the next passes
  // pick y's cell by it. Any thread, any order: the sums are integers, so the next passes' choice
  // does not depend on the schedule.
  void record(const LightVertex& y, float contribution) const {
    if (!learnChoice_ || !(contribution > 0.0f)) return;
    const float clamped = std::min(contribution, kLargestRecord);  // a rare spike must not overflow the sum
    pending(recordLane(), y.cell).fetch_add(uint64_t(clamped * kFixedPoint), std::memory_order_relaxed);
  }
  // connectionMis of the MIS count of a join whose light end is at p (in cell y.cell): see above.
  float misFactor(const glm::vec3& p) const { return misFactor_[cellOf(p)]; }
  float misFactor(const LightVertex& y) const { return misFactor_[y.cell]; }
  uint64_t rays() const { return rays_; }
  // The share of picks that go to the cells' learned choice rather than the uniform one (0 before
  // anything is learned or without learning).
  float learnedShare() const { return learnedShare_; }

 private:
  static constexpr int kCells = kCellsPerAxis * kCellsPerAxis * kCellsPerAxis;
  static constexpr float kFixedPoint = 1048576.0f;  // 2^20: records are summed as integers
  static constexpr float kLargestRecord = 1024.0f;
  static constexpr size_t kGuidePerCell = 4;
  // A bound on a join's MIS count: the partial sums multiply counts along a path, and a sum that
  // overflows zeroes the weight. Any bound keeps the weights summing to 1.
  static constexpr float kLargestMisCount = 100.0f;

  static int clampJoinDepth(int d) { return d < 0 ? -1 : std::min(d, ConnectionSettings::kMaxJoinDepth); }
  uint32_t cellOf(const glm::vec3& p) const {
    const glm::ivec3 c = glm::clamp(glm::ivec3(glm::clamp((p - low_) * perUnit_, 0.0f, float(kCellsPerAxis))),
                                    glm::ivec3(0), glm::ivec3(kCellsPerAxis - 1));
    return uint32_t((c.z * kCellsPerAxis + c.y) * kCellsPerAxis + c.x);
  }
  // The first cell whose cumulative probability passes u (upper_bound, clamped to the last cell), in
  // constant time: the guide table gives a cell at or just before it (a binary search over the
  // cells was a quarter of the tracer's own time on the Cornell box). The two walks make it exact
  // whatever the rounding of u times the table's size.
  size_t cellFor(float u) const {
    const size_t last = cellCdf_.size() - 1;
    size_t c = cellGuide_[std::min(cellGuide_.size() - 1, size_t(std::max(0.0f, u) * float(cellGuide_.size())))];
    while (c > 0 && cellCdf_[c - 1] > u) --c;
    while (c < last && cellCdf_[c] <= u) ++c;
    return c;
  }
  // The share of picks that follow what was learned, given the learned sum over the cells considered.
  double learnedShareFor(double learnedTotal) const {
    return learnChoice_ && learnedTotal > 0.0 ? 1.0 - double(kUniformShare) : 0.0;
  }
  void learnFromLastPass();
  // Sorts the light paths' vertices (in path order, batch by batch) into vertices_ by cell.
  void sortIntoCells(std::vector<std::vector<LightVertex>>& batches);
  void chooseCells(int paths);

  bool learnChoice_;
  int joinsPerVertex_;
  int joinDepth_;
  float shadowRoulette_;
  std::vector<LightVertex> vertices_;  // grouped by cell
  // The non-empty cells: their first vertex, vertex count, pick probabilities (cumulative) and scale.
  std::vector<uint32_t> cellOf_, cellStart_, cellCount_;
  std::vector<float> cellCdf_, cellScale_;
  std::vector<uint32_t> cellGuide_;  // entry b: cellFor(b / size), kGuidePerCell entries a cell
  glm::vec3 low_{0.0f}, perUnit_{0.0f};  // the scene's box: cell coordinates
  std::vector<double> learned_ = std::vector<double>(kCells, 0.0);  // every pass so far, per cell
  std::vector<double> seen_ = std::vector<double>(kCells, 0.0);     // vertices, every pass so far, per cell
  std::vector<float> misFactor_;
  // This pass's sums, in kRecordLanes copies: the threads' records fall into different lanes (by
  // the order in which they first record), so two cores do not pass the hot cells' cache lines back
  // and forth. Lanes are still atomic: beyond kRecordLanes threads they are shared.
  static constexpr size_t kRecordLanes = 16;
  static size_t recordLane() {
    static std::atomic<size_t> next{0};
    static thread_local const size_t lane = next.fetch_add(1, std::memory_order_relaxed) % kRecordLanes;
    return lane;
  }
  mutable std::vector<std::atomic<uint64_t>> pending_ = std::vector<std::atomic<uint64_t>>(kRecordLanes * kCells);
  std::atomic<uint64_t>& pending(size_t lane, size_t cell) const { return pending_[lane * size_t(kCells) + cell]; }
  float learnedShare_ = 0.0f;
  uint64_t rays_ = 0;
};

}  // namespace vpl
