// The Sobol' (0,2)-sequence with hash-based Owen scrambling: the generator behind every stratified
// number of the renderer (pixel_sampler.h decides which decision draws from which dimension).
//
// Most consumers use the first two Sobol' dimensions: the van der Corput sequence and its partner whose
// generator matrix is Pascal's triangle mod 2. Together they form a (0,2)-sequence in base 2: every
// aligned block of 2^m points is a (0,m,2)-net, one point in each elementary interval of area 2^-m.
// More dimensions come from "padding" (Kollig & Keller 2002; pbrt-v4's PaddedSobolSampler): every
// consumer gets its own copy of these two, shuffled and scrambled independently of the others. The
// third and fourth dimensions (Joe & Kuo's direction numbers) serve the one consumer that shares
// another's shuffle, so that the two form one 4D Sobol' point (pixel_sampler.h says which).
// All values are 0.32 fixed-point fractions until toUnitFloat().
#pragma once
#include <array>
#include <cstdint>

namespace vpl::sobol {

// Bit reversal byte by byte from a table (x86 has no instruction for it; this is the cheaper of the
// portable forms here).
inline constexpr auto kReversedByte = [] {
  std::array<uint8_t, 256> table{};
  for (uint32_t x = 0; x < 256; ++x)
    for (int bit = 0; bit < 8; ++bit) table[x] = uint8_t(table[x] | (((x >> bit) & 1u) << (7 - bit)));
  return table;
}();

inline uint32_t reverseBits(uint32_t v) {
  return uint32_t(kReversedByte[v & 0xffu]) << 24 | uint32_t(kReversedByte[(v >> 8) & 0xffu]) << 16 |
         uint32_t(kReversedByte[(v >> 16) & 0xffu]) << 8 | uint32_t(kReversedByte[v >> 24]);
}

// First dimension: the base-2 radical inverse of the index.
inline uint32_t vanDerCorput(uint32_t index) { return reverseBits(index); }

// The direction numbers of a Sobol' dimension from its primitive polynomial of degree s (a: its
// inner coefficients as bits, highest first) and its initial numbers m_1..m_s (odd, m_k < 2^k):
// v_k = m_k / 2^k, then v_k = v_{k-s} xor v_{k-s} / 2^s xor the a-selected v_{k-j} (Bratley & Fox 1988).
// Bit k of the index adds v_{k+1}.
inline constexpr std::array<uint32_t, 32> directionNumbers(int s, uint32_t a, std::array<uint32_t, 3> m) {
  std::array<uint32_t, 32> v{};
  for (int k = 1; k <= 32; ++k) {
    if (k <= s) {
      v[size_t(k - 1)] = m[size_t(k - 1)] << (32 - k);
      continue;
    }
    uint32_t x = v[size_t(k - s - 1)] ^ (v[size_t(k - s - 1)] >> s);
    for (int j = 1; j < s; ++j)
      if ((a >> (s - 1 - j)) & 1u) x ^= v[size_t(k - j - 1)];
    v[size_t(k - 1)] = x;
  }
  return v;
}
// The second dimension (x + 1): v_k = v_{k-1} xor v_{k-1} / 2, the rows of Pascal's triangle mod 2.
// The third and fourth: Joe & Kuo's (2008) first two entries past it, x^2 + x + 1 with m = 1, 3 and
// x^3 + x + 1 with m = 1, 3, 1.
inline constexpr std::array<uint32_t, 32> kSecondDirections = directionNumbers(1, 0, {1});
inline constexpr std::array<uint32_t, 32> kThirdDirections = directionNumbers(2, 1, {1, 3});
inline constexpr std::array<uint32_t, 32> kFourthDirections = directionNumbers(3, 1, {1, 3, 1});

// The index byte by byte: table[b][x] is the xor of the direction numbers of the bits set in x as
// byte b of the index (4 KB a dimension, made at compile time), four reads instead of a loop over
// bits. Stored bit-reversed, the form the scramble below works in.
using ByteTable = std::array<std::array<uint32_t, 256>, 4>;
inline constexpr ByteTable byteTable(const std::array<uint32_t, 32>& directions) {
  ByteTable table{};
  for (int b = 0; b < 4; ++b)
    for (uint32_t x = 0; x < 256; ++x)
      for (int bit = 0; bit < 8; ++bit)
        if (x & (1u << bit)) table[size_t(b)][x] ^= directions[size_t(8 * b + bit)];
  for (auto& row : table)
    for (uint32_t& v : row) {
      uint32_t r = 0;
      for (int bit = 0; bit < 32; ++bit) r |= ((v >> bit) & 1u) << (31 - bit);
      v = r;
    }
  return table;
}
inline constexpr ByteTable kSecondByByte = byteTable(kSecondDirections);
inline constexpr ByteTable kThirdByByte = byteTable(kThirdDirections);
inline constexpr ByteTable kFourthByByte = byteTable(kFourthDirections);

inline uint32_t reversedSobol(const ByteTable& table, uint32_t index) {
  return table[0][index & 0xffu] ^ table[1][(index >> 8) & 0xffu] ^ table[2][(index >> 16) & 0xffu] ^ table[3][index >> 24];
}
inline uint32_t reversedSobolSecond(uint32_t index) { return reversedSobol(kSecondByByte, index); }
inline uint32_t sobolSecond(uint32_t index) { return reverseBits(reversedSobolSecond(index)); }
inline uint32_t sobolThird(uint32_t index) { return reverseBits(reversedSobol(kThirdByByte, index)); }
inline uint32_t sobolFourth(uint32_t index) { return reverseBits(reversedSobol(kFourthByByte, index)); }

// Owen's nested uniform scramble (1995) by a hash (Laine & Karras 2011; the multipliers are Vegdahl's
// 2021 improvement, the hash pbrt-v4 calls FastOwenScrambler). Owen flips each binary digit of the
// fraction as a random function of the digits before it. With the bits reversed, "before" means
// "below", and x + c, x * odd and x ^ (x * even) each change a bit only as a function of the bits
// below it: their composition is such a scramble. It keeps every net a net and makes each point
// uniformly distributed, so estimates stay unbiased. This is the scramble on reversed bits, in place; T
// is uint32_t, or a vector of them (lane_sobol.h draws eight lanes' numbers at once).
template <class T>
inline void nestedScrambleReversedInPlace(T& x, const T& seed) {
  x ^= x * 0x3d20adeau;
  x += seed;
  x *= (seed >> 16) | 1u;
  x ^= x * 0x05526c56u;
  x ^= x * 0x53a22864u;
}
inline uint32_t nestedScrambleReversed(uint32_t x, uint32_t seed) {
  nestedScrambleReversedInPlace(x, seed);
  return x;
}
inline uint32_t owenScramble(uint32_t v, uint32_t seed) { return reverseBits(nestedScrambleReversed(reverseBits(v), seed)); }

// The scrambled points themselves. The van der Corput point of index i reversed is i itself, so each
// costs one bit reversal.
inline uint32_t scrambledVanDerCorput(uint32_t index, uint32_t seed) { return reverseBits(nestedScrambleReversed(index, seed)); }
inline uint32_t scrambledSobolSecond(uint32_t index, uint32_t seed) {
  return reverseBits(nestedScrambleReversed(reversedSobolSecond(index), seed));
}
inline uint32_t scrambledSobolThird(uint32_t index, uint32_t seed) {
  return reverseBits(nestedScrambleReversed(reversedSobol(kThirdByByte, index), seed));
}
inline uint32_t scrambledSobolFourth(uint32_t index, uint32_t seed) {
  return reverseBits(nestedScrambleReversed(reversedSobol(kFourthByByte, index), seed));
}

// A shuffle of the sequence's order (Burley 2020): the same scramble applied to the index itself,
// most significant bit first. The first 2^m indices, whose high bits are all zero, map to one aligned
// block of 2^m (the high bits are flipped by a function of zeros only), so every prefix of 2^m
// shuffled points is still a (0,m,2)-net. Two consumers with different shuffles pair their points
// at random: that is what decorrelates padded dimensions, and unlike a permutation of a fixed
// sample count it leaves the sequence open-ended, as progressive rendering needs.
inline uint32_t shuffleIndex(uint32_t index, uint32_t seed) { return owenScramble(index, seed); }

// [0, 1) from the 24 high bits (a float has 24): never rounds up to 1.
inline float toUnitFloat(uint32_t v) { return float(v >> 8) * 0x1p-24f; }

}  // namespace vpl::sobol
