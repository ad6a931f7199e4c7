// PCG32 random numbers: the independent random fallback of the sampler (pixel_sampler.h) for decisions
// past its tabulated dimensions, and the stream of consumers that need an unbounded count of numbers
// (Metropolis mutations, light paths, clustering). Streams are derived from hashed keys, so results
// are the same for any thread count or tile order (pbrt-v4's rule).
#pragma once
#include <cstdint>
#include <glm/glm.hpp>

namespace vpl {

// SplitMix64 finaliser: a good 64-bit mix for deriving stream seeds.
// In place, T a uint64_t or a vector of them (render/sampling/lane_sobol.h hashes eight lanes' keys at
// once; by reference, so that no vector crosses a call between code built for different CPUs).
template <class T>
inline void mix64InPlace(T& x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  x ^= x >> 31;
}
inline uint64_t mix64(uint64_t x) {
  mix64InPlace(x);
  return x;
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
  // A stream whose state and increment both come from a strong hash of `key`. Streams that share a
  // state and differ only in the increment are correlated (Vigna's critique of PCG), so derived
  // streams (per sample, per light path, per slice) should be made by this, not Rng(seed, index).
  static Rng hashed(uint64_t key) {
    Rng r;
    r.inc_ = (mix64(key ^ 0x243f6a8885a308d3ull) << 1u) | 1u;
    r.state_ = mix64(key);
    r.next();
    return r;
  }
  // The stream of one pixel sample: deterministic in (seed, pixel, sampleIndex) only.
  static Rng forSample(uint64_t seed, uint64_t pixel, uint64_t sampleIndex) {
    return hashed(mix64(mix64(seed) ^ pixel) ^ mix64(sampleIndex ^ 0x5851f42d4c957f2dull));
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
