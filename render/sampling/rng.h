// PCG32 random numbers. Every sample owns a stream derived from (seed, pixel, sample index), so an
// image is the same for any thread count or tile order (pbrt-v4's rule).
#pragma once
#include <cstdint>
#include <glm/glm.hpp>

namespace vpl {

// SplitMix64 finaliser: a good 64-bit mix for deriving stream seeds.
inline uint64_t mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

class Rng {
 public:
  explicit Rng(uint64_t seed = 0, uint64_t stream = 0) {
    inc_ = (stream << 1u) | 1u;
    state_ = 0;
    next();
    state_ += seed;
    next();
  }
  // The stream of one pixel sample: deterministic in (seed, pixel, sampleIndex) only.
  static Rng forSample(uint64_t seed, uint64_t pixel, uint64_t sampleIndex) {
    return Rng(mix64(seed ^ mix64(pixel)), mix64(sampleIndex ^ (seed << 17)));
  }

  uint32_t next() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    const uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    const uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
  }
  // Uniform in [0, 1): 24 random bits, so the result never rounds up to 1.
  float uniform() { return float(next() >> 8) * 0x1p-24f; }
  glm::vec2 uniform2() { float a = uniform(); return {a, uniform()}; }
  // Uniform integer in [0, n) without modulo bias worth caring about for n << 2^32.
  uint32_t below(uint32_t n) { return uint32_t((uint64_t(next()) * n) >> 32); }

 private:
  uint64_t state_, inc_;
};

}  // namespace vpl
