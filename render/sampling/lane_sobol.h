// PixelSampler's stratified numbers (pixel_sampler.h, sobol.h) for several lanes at once, each lane its
// own sampler and slot: the same hashes, scrambles and bit reversals in vector arithmetic, so a lane's
// point is the one PixelSampler::get2D gives, bit for bit. Only the second Sobol' dimension's table is
// read lane by lane. Used by the path lanes (render/integrator/path_lanes.h) and bench/simd_lanes.
//
// U is a vector of uint32_t, U64 of uint64_t, F of float (GCC vector extensions), N lanes each. Every
// vector goes by reference: an AVX2 caller inlines these, and no vector crosses a call between code
// built for different CPUs.
#pragma once
#include <cstdint>
#include "render/sampling/pixel_sampler.h"
#include "render/sampling/rng.h"
#include "render/sampling/sobol.h"

namespace vpl::lane_sobol {

// sobol::reverseBits by shifts (vectors have no byte table), in place.
template <class U>
inline void reverseBits(U& x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  x = (x >> 16) | (x << 16);
}

// sobol::toUnitFloat.
template <class U, class F>
inline void toUnitFloat(const U& v, F& out) { out = __builtin_convertvector(v >> 8, F) * 0x1p-24f; }

// Both coordinates of each lane's slot: pixelKey and reversedIndex are the lane's
// PixelSampler::pixelKey() and reversedIndex(), slot its PixelSampler::slotOf(vertex, dimension).
// The joined slot (PixelSampler::kJoinedSlot) takes the shuffle of the slot it joins and the third and
// fourth Sobol' dimensions, as PixelSampler::stratifiedPair gives it. Always inlined: GCC otherwise kept this
// out of line, built for the default target rather than the lanes' AVX2 (brdf 7 % slower).
template <class U, class U64, class F>
[[gnu::always_inline]] inline void point(const U64& pixelKey, const U& reversedIndex, const U& slot, F& x, F& y) {
  constexpr int kN = int(sizeof(U) / sizeof(uint32_t));
  U64 slotHash = pixelKey + __builtin_convertvector(slot, U64);
  mix64InPlace(slotHash);
  const U low = __builtin_convertvector(slotHash, U), high = __builtin_convertvector(slotHash >> 32, U);
  const U joined = U(slot == PixelSampler::kJoinedSlot);  // all ones where joined
  uint32_t anyJoined = 0;
  for (int k = 0; k < kN; ++k) anyJoined |= joined[k];
  U shuffle = low;
  if (anyJoined) {
    U64 joinedTo = pixelKey + uint64_t(PixelSampler::kJoinedToSlot);
    mix64InPlace(joinedTo);
    shuffle = (__builtin_convertvector(joinedTo, U) & joined) | (low & ~joined);
  }
  U index = reversedIndex;  // the shuffled index (PixelSampler::shuffledIndex)
  sobol::nestedScrambleReversedInPlace(index, shuffle);
  reverseBits(index);
  U first = index;  // the van der Corput point reversed is the index itself
  if (anyJoined)
    for (int k = 0; k < kN; ++k)
      if (joined[k]) first[k] = sobol::reversedSobol(sobol::kThirdByByte, index[k]);
  sobol::nestedScrambleReversedInPlace(first, high);
  reverseBits(first);
  toUnitFloat(first, x);
  U second;
  for (int k = 0; k < kN; ++k)
    second[k] = sobol::reversedSobol(joined[k] ? sobol::kFourthByByte : sobol::kSecondByByte, index[k]);
  U64 secondHash = slotHash;
  mix64InPlace(secondHash);
  const U secondKey = __builtin_convertvector(secondHash, U);
  sobol::nestedScrambleReversedInPlace(second, secondKey);
  reverseBits(second);
  toUnitFloat(second, y);
}

}  // namespace vpl::lane_sobol
