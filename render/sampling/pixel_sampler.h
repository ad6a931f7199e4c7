// The numbers of one pixel sample, each random decision on its own dimension (DESIGN.md §2 step 8).
//
// A sample is (seed, pixel, index), the index counting the pixel's samples from 0 and never
// restarting, so the image depends on nothing else (not threads, not tile order). Each decision
// has a fixed slot: one 2D (or 1D) stream of sobol.h, shuffled and Owen-scrambled by a hash of
// (seed, pixel, slot). The first 2^m samples of any slot in a pixel are stratified (a (0,m,2)-net),
// different slots and pixels are independent of each other. Two 1D decisions of a vertex share one
// 2D slot, jointly stratified; the second is computed only when asked (most vertices ask for one).
// A light path of the light vertex cache uses the same slots, its index in the pass as the sample
// index (render/vpl/light_walk.h: vertex 0 its start, vertex k its k-th scattering).
//
// Slot layout: the camera jitter, the preview's cluster choice, then per path vertex (its depth:
// 0 is the camera ray's hit) a block of VertexDimension. Past kTabulatedVertices, and for consumers
// of an unbounded count of numbers (Metropolis mutations), numbers come from a hash of
// (seed, pixel, index, slot): independent random, no worse than before.
//
// One slot is not padded: vertex 1's BSDF direction shares vertex 0's shuffle and takes the third and
// fourth Sobol' dimensions, so the first two bounces' directions are one 4D Sobol' point (a (t,m,4)-net,
// t <= 3 for m <= 12), stratified jointly, where padding pairs them at random (Latin-hypercube-like:
// each 2D slot stratified, their product not). Vertex 1's own pair is then a (t,m,2)-net of t <= 2,
// not 0. Per sample, brdf's relMSE on the Cornell box fell 7 % at 64 spp and 12 % at 256 spp (4 seeds
// each); vertex 1's light point or vertex 2's direction joined as well added a point or less, and the
// same two dimensions with a shuffle of their own nothing (docs/measurements/stratification.md).
#pragma once
#include <cstdint>
#include <optional>
#include <glm/glm.hpp>
#include "render/sampling/rng.h"
#include "render/sampling/sobol.h"

namespace vpl {

// The slots of one path vertex, all 2D.
enum class VertexDimension : uint32_t {
  LightPoint,           // the point on the chosen emitter (next-event estimation); x also picks the emitter (EmitterSet::sampleStratified)
  BsdfDirection,        // the BSDF's direction; x also picks its lobe (Bsdf::sample(wo, u))
  LightChoiceRoulette,  // x: which emitter, where EmitterSet::foldsChoice() is false; y: Russian roulette
  StrategyGuideCell,    // x: the light vertices a vertex joins, or a free strategy where none are (mis takes its strategy from BsdfDirection's x); y: the guide's cell or its defensive share
  GuidePoint,           // the point within the guide's cell
  Count
};

class PixelSampler {
 public:
  static constexpr int kTabulatedVertices = 8;

  // `stratified` false: every slot draws from the hashed fallback, independent random numbers as the
  // paper's sampler had, so what the stratification buys stays measurable (`--sampler random`).
  PixelSampler(uint64_t seed, uint64_t pixel, uint64_t sampleIndex, bool stratified = true)
      : pixelKey_(mix64(mix64(seed ^ 0x736f626f6c000000ull) ^ pixel) ^ mix64(sampleIndex >> 32)),
        sampleKey_(mix64(pixelKey_ ^ sampleIndex)),
        reversedIndex_(sobol::reverseBits(uint32_t(sampleIndex))),
        hashedOnly_(!stratified) {}
  // Independent random numbers, all from `rng` in the order asked: for callers that bring their own
  // stream (benches, and as the baseline the stratified samples are measured against).
  explicit PixelSampler(Rng& rng) : independent_(&rng) {}

  // The camera's slot: a stratified sampler's cameraJitter() is the point get2D gives there (the path
  // lanes draw it for eight pixels at once, render/sampling/lane_sobol.h).
  static constexpr uint32_t kCameraSlot = 0, kPreviewClusterSlot = 1, kFirstVertexSlot = 2;
  glm::vec2 cameraJitter() { return slot2D(kCameraSlot); }
  // The preview's two choices per pass: x, the offset of its systematic cluster picks; y, the slice
  // whose clusters it uses (its own or a neighbour, so that slices blend across their borders).
  glm::vec2 previewChoices() { return slot2D(kPreviewClusterSlot); }

  // A slot read in 1D is the first coordinate of its 2D point.
  float get1D(int vertex, VertexDimension d) {
    const uint32_t slot = slotOf(vertex, d);
    return stratified(vertex) || independent_ ? get1D(slot) : hashedUniform(slot, 0);
  }
  glm::vec2 get2D(int vertex, VertexDimension d) {
    const uint32_t slot = slotOf(vertex, d);
    return stratified(vertex) || independent_ ? get2D(slot) : hashed2D(slot);
  }
  // A slot shared by two decisions of which most vertices read only the first (light choice and
  // roulette, joins and guide cell): its second coordinate is computed when asked, the same number
  // get2D() gives.
  class Pair {
   public:
    float x() const { return x_; }
    float y() {
      if (y_ < 0.0f) {
        const uint32_t seed = uint32_t(mix64(slotHash_));
        y_ = sobol::toUnitFloat(joined_ ? sobol::scrambledSobolFourth(index_, seed)
                                        : sobol::scrambledSobolSecond(index_, seed));
      }
      return y_;
    }

   private:
    friend class PixelSampler;
    float x_ = 0.0f, y_ = -1.0f;  // y_ < 0: not computed yet
    uint32_t index_ = 0;          // the slot's shuffled sample index
    uint64_t slotHash_ = 0;
    bool joined_ = false;         // the joined slot: Sobol' dimensions 3 and 4
  };
  Pair getPair(int vertex, VertexDimension d) {
    if (stratified(vertex) && !independent_) return stratifiedPair(slotOf(vertex, d));
    const glm::vec2 u = get2D(vertex, d);
    Pair p;
    p.x_ = u.x;
    p.y_ = u.y;
    return p;
  }
  // The numbers of a branch that a split path grows (render/integrator/weight_window.h): the
  // branches of one vertex must not share numbers, and the stratified dimensions belong to the
  // sample's first path, so a branch draws all its vertices from the hashed fallback, keyed by `id`.
  PixelSampler branch(uint32_t id) const {
    PixelSampler b = *this;
    b.branch_ = true;
    b.sampleKey_ = mix64(sampleKey_ ^ (0x6272616e63680000ull + id));
    return b;
  }
  // For numbers drawn for many lanes at once (lane_sobol.h): whether `vertex` draws from the
  // stratified slots, and the keys they hash.
  bool stratifiedAt(int vertex) const { return stratified(vertex) && !independent_; }
  uint64_t pixelKey() const { return pixelKey_; }
  uint32_t reversedIndex() const { return reversedIndex_; }
  static uint32_t slotOf(int vertex, VertexDimension d) {
    return kFirstVertexSlot + uint32_t(vertex) * uint32_t(VertexDimension::Count) + uint32_t(d);
  }
  // The slot that is not padded (see above), and the slot whose shuffle it shares.
  static constexpr uint32_t kJoinedSlot =
      kFirstVertexSlot + 1 * uint32_t(VertexDimension::Count) + uint32_t(VertexDimension::BsdfDirection);
  static constexpr uint32_t kJoinedToSlot = kFirstVertexSlot + uint32_t(VertexDimension::BsdfDirection);
  // A stream of its own for a vertex's consumer of an unbounded count of numbers.
  Rng random(int vertex) {
    if (independent_) return Rng::hashed(independent_->next() | uint64_t(independent_->next()) << 32);
    return Rng::hashed(sampleKey_ ^ (0x72616e646f6d0000ull + uint64_t(vertex)));
  }

 private:
  // A vertex whose numbers come from the stratified slots, not the hashed fallback.
  bool stratified(int vertex) const { return vertex < kTabulatedVertices && !branch_ && !hashedOnly_; }

  // One hash of (pixel, slot) gives the slot's shuffle and its scrambles (the second coordinate's
  // through Pair::y(), when asked).
  Pair stratifiedPair(uint32_t slot) const {
    if (slot == kJoinedSlot) return joinedPair();
    Pair p;
    p.slotHash_ = mix64(pixelKey_ + slot);
    p.index_ = shuffledIndex(uint32_t(p.slotHash_));
    p.x_ = sobol::toUnitFloat(sobol::scrambledVanDerCorput(p.index_, uint32_t(p.slotHash_ >> 32)));
    return p;
  }
  // The joined slot: its own scrambles, the shuffle of the slot it joins (lane_sobol.h draws the same).
  Pair joinedPair() const {
    Pair p;
    p.slotHash_ = mix64(pixelKey_ + kJoinedSlot);
    p.joined_ = true;
    p.index_ = shuffledIndex(uint32_t(mix64(pixelKey_ + kJoinedToSlot)));
    p.x_ = sobol::toUnitFloat(sobol::scrambledSobolThird(p.index_, uint32_t(p.slotHash_ >> 32)));
    return p;
  }
  // A slot of its own outside the vertices' (which stratified() already sends to the fallback).
  glm::vec2 slot2D(uint32_t slot) const {
    return hashedOnly_ ? hashed2D(slot) : get2D(slot);
  }
  float get1D(uint32_t slot) const { return independent_ ? independent_->uniform() : stratifiedPair(slot).x(); }
  glm::vec2 get2D(uint32_t slot) const {
    if (independent_) return independent_->uniform2();
    Pair p = stratifiedPair(slot);
    return {p.x(), p.y()};
  }
  // sobol::shuffleIndex(index, seed), its first bit reversal done once per sample.
  uint32_t shuffledIndex(uint32_t seed) const { return sobol::reverseBits(sobol::nestedScrambleReversed(reversedIndex_, seed)); }
  float hashedUniform(uint32_t slot, uint32_t component) const {
    return float(mix64(sampleKey_ + 2u * uint64_t(slot) + component) >> 40) * 0x1p-24f;
  }
  glm::vec2 hashed2D(uint32_t slot) const { return {hashedUniform(slot, 0), hashedUniform(slot, 1)}; }

  uint64_t pixelKey_ = 0;   // hash of (seed, pixel, the index's high half): the slots' scrambles
  uint64_t sampleKey_ = 0;  // hash of that and the whole index: the random fallback
  uint32_t reversedIndex_ = 0;  // the index's low 32 bits, bit-reversed
  bool branch_ = false;         // a split path's branch: hashed numbers at every vertex
  bool hashedOnly_ = false;     // the random sampler: hashed numbers at every slot
  Rng* independent_ = nullptr;
};

// The numbers of one path vertex: handed to whoever decides something there. A slot shared by two
// decisions is drawn once, when the first of them asks.
class VertexSamples {
 public:
  VertexSamples(PixelSampler& sampler, int vertex) : sampler_(sampler), vertex_(vertex) {}

  int vertex() const { return vertex_; }
  glm::vec2 lightPoint() { return point(lightPoint_, VertexDimension::LightPoint); }
  glm::vec2 bsdfDirection() { return point(bsdfDirection_, VertexDimension::BsdfDirection); }
  float lightChoice() { return pair(lightChoiceRoulette_, VertexDimension::LightChoiceRoulette).x(); }
  float roulette() { return pair(lightChoiceRoulette_, VertexDimension::LightChoiceRoulette).y(); }
  float guideCell() { return pair(strategyGuideCell_, VertexDimension::StrategyGuideCell).y(); }
  glm::vec2 guidePoint() { return sampler_.get2D(vertex_, VertexDimension::GuidePoint); }
  // The light vertices a vertex joins (render/integrator/light_vertex_cache.h), stratified over the
  // pixel's samples: per sample at 32 spp (seeds 1, 2), relMSE 0.86 of a hashed number's on the Cornell
  // box, 0.94 on two_rooms, 0.99 on door_ajar.
  float connectionChoice() { return pair(strategyGuideCell_, VertexDimension::StrategyGuideCell).x(); }
  // The same number, for a continuation strategy of its own where no joins are made (bench/portal_bound).
  float strategy() { return connectionChoice(); }
  // The numbers every vertex reads, drawn before its ray is traced: their hash chains are long and
  // independent of the hit, so the core works them out in the shadow of the traversal. (Not the light
  // choice: EmitterSet::sampleStratified folds it into the light point and asks for it only where it
  // cannot; drawing it ahead cost 2.4 % of a brdf sample's time.)
  void drawAhead() {
    lightPoint();
    bsdfDirection();
  }
  // The same two numbers, drawn elsewhere from this vertex's slots (lane_sobol.h).
  void drawnAhead(glm::vec2 lightPoint, glm::vec2 bsdfDirection) {
    lightPoint_ = lightPoint;
    bsdfDirection_ = bsdfDirection;
  }
  // The vertex's own random stream (Metropolis chains), made on first use.
  Rng& random() {
    if (!random_) random_ = sampler_.random(vertex_);
    return *random_;
  }

 private:
  glm::vec2 point(std::optional<glm::vec2>& cached, VertexDimension d) {
    if (!cached) cached = sampler_.get2D(vertex_, d);
    return *cached;
  }
  PixelSampler::Pair& pair(std::optional<PixelSampler::Pair>& cached, VertexDimension d) {
    if (!cached) cached = sampler_.getPair(vertex_, d);
    return *cached;
  }

  PixelSampler& sampler_;
  int vertex_;
  std::optional<glm::vec2> lightPoint_, bsdfDirection_;
  std::optional<PixelSampler::Pair> lightChoiceRoulette_, strategyGuideCell_;
  std::optional<Rng> random_;
};

}  // namespace vpl
