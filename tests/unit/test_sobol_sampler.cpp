// The stratified sampler (render/sampling/sobol.h, pixel_sampler.h): each sample is uniformly
// distributed (the estimates stay unbiased), the first 2^m samples of every slot in a pixel are
// stratified (one per elementary interval), and slots, pixels and seeds are independent of each
// other. The tile renderer hands pass k of a pixel sample index k.
#include <algorithm>
#include <array>
#include <cstdio>
#include <cmath>
#include <mutex>
#include <numbers>
#include <set>
#include <string>
#include <vector>
#include "render/core/frame.h"
#include "render/film/film.h"
#include "render/material/bsdf.h"
#include "render/sampling/lane_sobol.h"
#include "render/sampling/pixel_sampler.h"
#include "render/sampling/rng.h"
#include "render/sampling/sobol.h"
#include "render/session/tile_renderer.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

constexpr double kSignificance = 1e-3;

float unit(uint32_t v) { return sobol::toUnitFloat(v); }

// "" when every elementary interval of area 2^-m (2^a columns by 2^(m-a) rows, each a) holds
// exactly one of the 2^m points; else the first interval that does not.
std::string netDefect(const std::vector<glm::vec2>& points, int m) {
  if (points.size() != size_t(1) << m) return "wrong point count";
  for (int a = 0; a <= m; ++a) {
    const int cols = 1 << a, rows = 1 << (m - a);
    std::vector<int> count(size_t(cols) * size_t(rows), 0);
    for (const glm::vec2& p : points) ++count[size_t(int(p.y * float(rows))) * size_t(cols) + size_t(int(p.x * float(cols)))];
    for (size_t c = 0; c < count.size(); ++c)
      if (count[c] != 1)
        return "2^" + std::to_string(m) + " points, " + std::to_string(cols) + "x" + std::to_string(rows) + " cells: cell " +
               std::to_string(c) + " holds " + std::to_string(count[c]);
  }
  return "";
}

// The quality parameter t of 2^m points in [0,1)^d: the least t for which every elementary interval
// of volume 2^(t-m) (2^q_i parts along each axis i, the q_i summing to m - t) holds exactly 2^t points.
// A (0,m,2)-net has t = 0; Sobol's first four dimensions reach t <= 3 for m <= 12.
template <size_t D>
int netQuality(const std::vector<std::array<float, D>>& points, int m) {
  for (int t = 0; t <= m; ++t) {
    const int k = m - t;
    bool holds = true;
    std::array<int, D> q{};
    // Every composition of k into D parts, q[D - 1] taking what the others leave.
    const auto visit = [&](auto&& self, size_t axis, int left) -> void {
      if (!holds) return;
      if (axis + 1 == D) {
        q[axis] = left;
        std::vector<int> count(size_t(1) << k, 0);
        for (const auto& p : points) {
          size_t cell = 0;
          for (size_t i = 0; i < D; ++i) cell = (cell << q[i]) | size_t(p[i] * float(1 << q[i]));
          ++count[cell];
        }
        for (int c : count) holds &= c == (1 << t);
        return;
      }
      for (int part = 0; part <= left; ++part) {
        q[axis] = part;
        self(self, axis + 1, left - part);
      }
    };
    visit(visit, 0, k);
    if (holds) return t;
  }
  return m;
}

// "" when each of the 2^m intervals of width 2^-m holds exactly one value.
std::string strataDefect(const std::vector<float>& values, int m) {
  std::vector<int> count(size_t(1) << m, 0);
  for (float v : values) ++count[size_t(v * float(count.size()))];
  for (size_t c = 0; c < count.size(); ++c)
    if (count[c] != 1) return "2^" + std::to_string(m) + " values: interval " + std::to_string(c) + " holds " + std::to_string(count[c]);
  return "";
}

// Pearson chi-square of counts against equal expected counts: the upper-tail p-value.
double uniformChiSquareP(const std::vector<int>& counts) {
  double n = 0.0;
  for (int c : counts) n += c;
  const double expected = n / double(counts.size());
  double x2 = 0.0;
  for (int c : counts) x2 += (c - expected) * (c - expected) / expected;
  return test::chiSquareTail(x2, int(counts.size()) - 1);
}

std::vector<int> histogram1D(const std::vector<float>& values, int bins) {
  std::vector<int> counts(size_t(bins), 0);
  for (float v : values) ++counts[size_t(std::min(bins - 1, int(v * float(bins))))];
  return counts;
}

std::vector<int> histogram2D(const std::vector<glm::vec2>& points, int bins) {
  std::vector<int> counts(size_t(bins) * size_t(bins), 0);
  for (const glm::vec2& p : points)
    ++counts[size_t(std::min(bins - 1, int(p.y * float(bins)))) * size_t(bins) + size_t(std::min(bins - 1, int(p.x * float(bins))))];
  return counts;
}

double correlation(const std::vector<float>& a, const std::vector<float>& b) {
  double ma = 0, mb = 0;
  for (size_t i = 0; i < a.size(); ++i) ma += a[i], mb += b[i];
  ma /= double(a.size());
  mb /= double(b.size());
  double sab = 0, saa = 0, sbb = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return sab / std::sqrt(saa * sbb);
}

// The named slots the tests look at: (vertex, dimension), 1D and 2D.
struct Slot1 {
  int vertex;
  VertexDimension d;
};
struct Slot2 {
  int vertex;
  VertexDimension d;
};
// A slot read in 1D is its first coordinate: the lists share no slot.
constexpr Slot1 kSlots1D[] = {{0, VertexDimension::LightChoiceRoulette}, {1, VertexDimension::StrategyGuideCell},
                              {2, VertexDimension::LightPoint}, {5, VertexDimension::LightChoiceRoulette},
                              {7, VertexDimension::GuidePoint}};
constexpr Slot2 kSlots2D[] = {{0, VertexDimension::LightPoint}, {0, VertexDimension::BsdfDirection},
                              {3, VertexDimension::GuidePoint}, {7, VertexDimension::BsdfDirection}};

float value1D(uint64_t seed, uint64_t pixel, uint64_t index, Slot1 s) { return PixelSampler(seed, pixel, index).get1D(s.vertex, s.d); }
glm::vec2 value2D(uint64_t seed, uint64_t pixel, uint64_t index, Slot2 s) {
  return PixelSampler(seed, pixel, index).get2D(s.vertex, s.d);
}

TEST(Sobol, FirstTwoDimensionsAreA02Sequence) {
  // From the definition: index 1 is (1/2, 1/2), index 2 (1/4, 3/4), index 3 (3/4, 1/4).
  EXPECT_EQ(unit(sobol::vanDerCorput(1)), 0.5f);
  EXPECT_EQ(unit(sobol::sobolSecond(1)), 0.5f);
  EXPECT_EQ(glm::vec2(unit(sobol::vanDerCorput(2)), unit(sobol::sobolSecond(2))), glm::vec2(0.25f, 0.75f));
  EXPECT_EQ(glm::vec2(unit(sobol::vanDerCorput(3)), unit(sobol::sobolSecond(3))), glm::vec2(0.75f, 0.25f));
  // Every aligned block of 2^m points is a (0,m,2)-net, not only the first.
  for (uint32_t block : {0u, 1u, 7u, 12345u})
    for (int m = 0; m <= 12; ++m) {
      if (uint64_t(block) << m >= (uint64_t(1) << 32)) continue;
      std::vector<glm::vec2> points;
      for (uint32_t i = 0; i < (1u << m); ++i) {
        const uint32_t index = (block << m) | i;
        points.push_back({unit(sobol::vanDerCorput(index)), unit(sobol::sobolSecond(index))});
      }
      EXPECT_EQ(netDefect(points, m), "") << "block " << block;
    }
}

// The third and fourth dimensions, from Joe & Kuo's direction numbers: each a (0,1)-sequence, and the
// four together a (t,4)-sequence whose first 2^m points have Sobol's own t (at most 3 up to 2^12; a
// wrong initial number or polynomial raises it), in every aligned block.
TEST(Sobol, ThirdAndFourthDimensionsMakeA4DSequence) {
  const int kQuality[13] = {0, 1, 1, 2, 2, 2, 2, 2, 3, 3, 2, 2, 3};  // the unscrambled first four dimensions
  for (uint32_t block : {0u, 5u})
    for (int m = 0; m <= 12; ++m) {
      std::vector<std::array<float, 4>> points;
      std::vector<float> third, fourth;
      for (uint32_t i = 0; i < (1u << m); ++i) {
        const uint32_t index = (block << m) | i;
        points.push_back({unit(sobol::vanDerCorput(index)), unit(sobol::sobolSecond(index)), unit(sobol::sobolThird(index)),
                          unit(sobol::sobolFourth(index))});
        third.push_back(points.back()[2]);
        fourth.push_back(points.back()[3]);
      }
      EXPECT_EQ(strataDefect(third, m), "") << "block " << block;
      EXPECT_EQ(strataDefect(fourth, m), "") << "block " << block;
      EXPECT_LE(netQuality(points, m), kQuality[m]) << "2^" << m << " points, block " << block;
    }
}

TEST(Sobol, ShuffleMapsEveryPrefixOntoAnAlignedBlock) {
  for (uint32_t seed : {0u, 1u, 0xdeadbeefu, 0x9e3779b9u})
    for (int m = 0; m <= 14; ++m) {
      std::set<uint32_t> images;
      for (uint32_t i = 0; i < (1u << m); ++i) images.insert(sobol::shuffleIndex(i, seed));
      ASSERT_EQ(images.size(), size_t(1) << m) << "seed " << seed << ", m " << m << ": not a permutation";
      const uint32_t block = m == 32 ? 0u : (*images.begin() >> m);
      EXPECT_EQ(*images.begin(), block << m) << "seed " << seed << ", m " << m;
      EXPECT_EQ(*images.rbegin() >> m, block) << "seed " << seed << ", m " << m;
    }
}

TEST(Sobol, OwenScramblingKeepsNets) {
  for (uint32_t seed : {3u, 0xabcdef01u})
    for (int m : {4, 8, 11}) {
      std::vector<glm::vec2> points;
      for (uint32_t i = 0; i < (1u << m); ++i)
        points.push_back({unit(sobol::owenScramble(sobol::vanDerCorput(i), seed)),
                          unit(sobol::owenScramble(sobol::sobolSecond(i), seed * 0x2545f491u + 1u))});
      EXPECT_EQ(netDefect(points, m), "") << "seed " << seed;
    }
}

TEST(PixelSampler, FirstSamplesOfEverySlotAreStratified) {
  for (uint64_t seed : {1ull, 77ull})
    for (uint64_t pixel : {0ull, 1ull, 4242ull, 65535ull}) {
      for (const Slot2& slot : kSlots2D) {
        std::vector<glm::vec2> points;
        std::vector<glm::vec2> camera, preview;
        for (int m = 0; m <= 10; ++m) {
          while (points.size() < size_t(1) << m) {
            points.push_back(value2D(seed, pixel, points.size(), slot));
            camera.push_back(PixelSampler(seed, pixel, camera.size()).cameraJitter());
            preview.push_back(PixelSampler(seed, pixel, preview.size()).previewChoices());
          }
          ASSERT_EQ(netDefect(points, m), "") << "vertex " << slot.vertex << " dimension " << int(slot.d) << ", pixel " << pixel;
          ASSERT_EQ(netDefect(camera, m), "") << "camera jitter, pixel " << pixel;
          ASSERT_EQ(netDefect(preview, m), "") << "preview choices, pixel " << pixel;
        }
      }
      for (const Slot1& slot : kSlots1D) {
        std::vector<float> values, clusters;
        for (int m = 0; m <= 12; ++m) {
          while (values.size() < size_t(1) << m) {
            values.push_back(value1D(seed, pixel, values.size(), slot));
            clusters.push_back(PixelSampler(seed, pixel, clusters.size()).previewChoices().x);
          }
          ASSERT_EQ(strataDefect(values, m), "") << "vertex " << slot.vertex << " dimension " << int(slot.d) << ", pixel " << pixel;
          ASSERT_EQ(strataDefect(clusters, m), "") << "preview clusters, pixel " << pixel;
        }
      }
    }
}

// Vertex 1's BSDF direction is not padded: it shares vertex 0's shuffle, so in every pixel the first
// 2^m samples of the two bounces' directions are one 4D net of Sobol's own quality (scrambles and the
// shuffle keep nets), and vertex 1's alone a net of the third and fourth dimensions' (t <= 2). Padded
// slots pair their points at random: vertex 2's direction with vertex 0's is no such net.
TEST(PixelSampler, FirstTwoBouncesDirectionsAreOne4DNet) {
  const int kQuality[11] = {0, 1, 1, 2, 2, 2, 2, 2, 3, 3, 2};
  const int kSecondQuality[11] = {0, 0, 1, 2, 0, 1, 1, 1, 1, 1, 1};  // the third and fourth dimensions alone
  for (uint64_t seed : {1ull, 77ull})
    for (uint64_t pixel : {0ull, 4242ull, 65535ull}) {
      std::vector<std::array<float, 4>> joined, padded;
      std::vector<std::array<float, 2>> second;
      for (int m = 0; m <= 10; ++m) {
        while (joined.size() < size_t(1) << m) {
          PixelSampler s(seed, pixel, joined.size());
          const glm::vec2 a = s.get2D(0, VertexDimension::BsdfDirection), b = s.get2D(1, VertexDimension::BsdfDirection);
          const glm::vec2 c = s.get2D(2, VertexDimension::BsdfDirection);
          joined.push_back({a.x, a.y, b.x, b.y});
          padded.push_back({a.x, a.y, c.x, c.y});
          second.push_back({b.x, b.y});
        }
        ASSERT_LE(netQuality(joined, m), kQuality[m]) << "2^" << m << " samples, pixel " << pixel << ", seed " << seed;
        ASSERT_LE(netQuality(second, m), kSecondQuality[m]) << "2^" << m << " samples, pixel " << pixel << ", seed " << seed;
        if (m >= 8) EXPECT_GT(netQuality(padded, m), kQuality[m] + 2) << "2^" << m << " samples, pixel " << pixel;
      }
    }
}

// Owen scrambling makes every single sample uniform over [0,1)^d: across pixels, sample k of a slot
// is uniform for every k (what keeps each pixel's estimate unbiased). A "too good" fit would mean the
// pixels' scrambles are related, so both tails are checked.
TEST(PixelSampler, EverySampleIsUniformAcrossPixels) {
  constexpr int kPixels = 40000;
  for (uint64_t index : {0ull, 1ull, 6ull, 1000ull, (1ull << 33) + 5}) {
    for (const Slot1& slot : kSlots1D) {
      std::vector<float> v;
      for (int p = 0; p < kPixels; ++p) v.push_back(value1D(9, uint64_t(p), index, slot));
      const double pv = uniformChiSquareP(histogram1D(v, 100));
      EXPECT_GT(pv, kSignificance) << "index " << index << " vertex " << slot.vertex << " dimension " << int(slot.d);
      EXPECT_LT(pv, 1.0 - kSignificance) << "index " << index << " vertex " << slot.vertex << " dimension " << int(slot.d);
    }
    for (const Slot2& slot : kSlots2D) {
      std::vector<glm::vec2> v;
      for (int p = 0; p < kPixels; ++p) v.push_back(value2D(9, uint64_t(p), index, slot));
      const double pv = uniformChiSquareP(histogram2D(v, 20));
      EXPECT_GT(pv, kSignificance) << "index " << index << " vertex " << slot.vertex << " dimension " << int(slot.d);
      EXPECT_LT(pv, 1.0 - kSignificance) << "index " << index << " vertex " << slot.vertex << " dimension " << int(slot.d);
    }
  }
}

// Within one pixel, a long run of one slot is uniform (a non-power-of-two count too).
TEST(PixelSampler, OnePixelsSequenceIsUniform) {
  for (int n : {1000, 4096}) {
    for (const Slot1& slot : kSlots1D) {
      std::vector<float> v;
      for (int k = 0; k < n; ++k) v.push_back(value1D(3, 321, uint64_t(k), slot));
      EXPECT_GT(uniformChiSquareP(histogram1D(v, 50)), kSignificance) << n << " samples, dimension " << int(slot.d);
    }
    for (const Slot2& slot : kSlots2D) {
      std::vector<glm::vec2> v;
      for (int k = 0; k < n; ++k) v.push_back(value2D(3, 321, uint64_t(k), slot));
      EXPECT_GT(uniformChiSquareP(histogram2D(v, 10)), kSignificance) << n << " samples, dimension " << int(slot.d);
    }
  }
}

// For a fixed sample index, any two slots are jointly uniform across pixels: what keeps an estimate
// of a function of several decisions (light choice and point, lobe and direction, one bounce and
// the next) unbiased.
TEST(PixelSampler, AnyTwoSlotsAreJointlyUniformAcrossPixels) {
  constexpr int kPixels = 40000;
  for (uint64_t index : {0ull, 3ull, 255ull}) {
    for (size_t a = 0; a < std::size(kSlots1D); ++a) {
      const Slot1 s1 = kSlots1D[a], s1b = kSlots1D[(a + 1) % std::size(kSlots1D)];
      const Slot2 s2 = kSlots2D[a % std::size(kSlots2D)];
      std::vector<glm::vec2> oneOne, oneTwo, twoTwo;
      for (int p = 0; p < kPixels; ++p) {
        PixelSampler s(21, uint64_t(p), index);
        const glm::vec2 d = s.get2D(s2.vertex, s2.d);
        oneOne.push_back({s.get1D(s1.vertex, s1.d), s.get1D(s1b.vertex, s1b.d)});
        oneTwo.push_back({s.get1D(s1.vertex, s1.d), d.y});
        twoTwo.push_back({d.x, s.cameraJitter().x});
      }
      for (const auto* pairs : {&oneOne, &oneTwo, &twoTwo}) {
        const double pv = uniformChiSquareP(histogram2D(*pairs, 20));
        EXPECT_GT(pv, kSignificance) << "index " << index << ", slots " << a << ", pair kind " << (pairs - &oneOne);
        EXPECT_LT(pv, 1.0 - kSignificance) << "index " << index << ", slots " << a << ", pair kind " << (pairs - &oneOne);
      }
    }
  }
}

// Within a pixel, padding pairs the points of two slots by their independent shuffles: the pairs
// (slot A, slot B) show no correlation and fill the square evenly. Burley's shuffle pairs them in a
// nested way (samples 2j and 2j + 1 are opposite in both slots), which spreads the statistics a
// little more than a random pairing does (measured, averages over 64 pixels of 4096 samples):
//   N r^2 (squared correlation times N)   about 1.6, against 1 for a random pairing or independent numbers
//   chi-square of a 16 x 16 histogram      230-250, against 225 for a random pairing, 255 independent
// Without the shuffle two van der Corput slots would be one and the same sequence: N r^2 and the
// chi-square in the thousands.
TEST(PixelSampler, DifferentSlotsOfOnePixelAreUncorrelated) {
  constexpr int kN = 4096, kPixels = 64;
  // Every slot as 1D series of one pixel: the 1D slots, both axes of the 2D slots, the camera's x.
  struct Series {
    std::string name, slot;  // slot: the same for the two axes of one 2D slot
    std::vector<float> values;
  };
  auto seriesOf = [](uint64_t pixel) {
    std::vector<Series> all;
    for (const Slot1& s : kSlots1D) {
      const std::string name = "1D v" + std::to_string(s.vertex) + " d" + std::to_string(int(s.d));
      all.push_back({name, name, {}});
      for (int k = 0; k < kN; ++k) all.back().values.push_back(value1D(5, pixel, uint64_t(k), s));
    }
    for (const Slot2& s : kSlots2D)
      for (int axis = 0; axis < 2; ++axis) {
        const std::string slot = "2D v" + std::to_string(s.vertex) + " d" + std::to_string(int(s.d));
        all.push_back({slot + (axis ? ".y" : ".x"), slot, {}});
        for (int k = 0; k < kN; ++k) all.back().values.push_back(value2D(5, pixel, uint64_t(k), s)[axis]);
      }
    all.push_back({"camera.x", "camera", {}});
    for (int k = 0; k < kN; ++k) all.back().values.push_back(PixelSampler(5, pixel, uint64_t(k)).cameraJitter().x);
    return all;
  };
  std::vector<std::vector<double>> meanChi2, meanNr2;
  std::vector<Series> series;
  for (int p = 0; p < kPixels; ++p) {
    series = seriesOf(uint64_t(1000 + p));
    if (meanChi2.empty()) meanChi2 = meanNr2 = std::vector<std::vector<double>>(series.size(), std::vector<double>(series.size(), 0.0));
    for (size_t a = 0; a < series.size(); ++a)
      for (size_t b = a + 1; b < series.size(); ++b) {
        if (series[a].slot == series[b].slot) continue;  // x and y of one 2D slot: a net, not independent
        const double r = correlation(series[a].values, series[b].values);
        meanNr2[a][b] += kN * r * r / kPixels;
        std::vector<glm::vec2> pairs;
        for (int k = 0; k < kN; ++k) pairs.push_back({series[a].values[size_t(k)], series[b].values[size_t(k)]});
        const double expected = kN / 256.0;
        double x2 = 0.0;
        for (int c : histogram2D(pairs, 16)) x2 += (c - expected) * (c - expected) / expected;
        meanChi2[a][b] += x2 / kPixels;
      }
  }
  double largestNr2 = 0.0, largestChi2 = 0.0;
  for (size_t a = 0; a < series.size(); ++a)
    for (size_t b = a + 1; b < series.size(); ++b) largestNr2 = std::max(largestNr2, meanNr2[a][b]), largestChi2 = std::max(largestChi2, meanChi2[a][b]);
  std::printf("slot pairs over %d pixels: largest mean N r^2 %.2f, largest mean chi-square %.1f\n", kPixels, largestNr2, largestChi2);
  for (size_t a = 0; a < series.size(); ++a)
    for (size_t b = a + 1; b < series.size(); ++b)
      if (series[a].slot != series[b].slot) {
        EXPECT_LT(meanNr2[a][b], 3.0) << series[a].name << " against " << series[b].name;
        EXPECT_LT(meanChi2[a][b], 270.0) << series[a].name << " against " << series[b].name;
      }
}

// Neighbouring pixels and consecutive seeds draw unrelated sequences (the same measure as above:
// no correlation, and pair histograms no more spread than nested pairing makes them).
TEST(PixelSampler, PixelsAndSeedsAreIndependent) {
  constexpr int kN = 4096, kPairs = 48;
  const Slot2 slot = kSlots2D[1];
  auto seriesOf = [&](uint64_t seed, uint64_t pixel, int axis) {
    std::vector<float> v;
    for (int k = 0; k < kN; ++k) v.push_back(value2D(seed, pixel, uint64_t(k), slot)[axis]);
    return v;
  };
  struct Neighbour {
    const char* name;
    uint64_t seedStep, pixelStep;
  };
  for (const Neighbour& n : {Neighbour{"next pixel", 0, 1}, Neighbour{"pixel below", 0, 256}, Neighbour{"next seed", 1, 0}}) {
    double meanChi2 = 0.0, meanNr2 = 0.0;
    for (int i = 0; i < kPairs; ++i) {
      const uint64_t pixel = 100 + 7 * uint64_t(i);
      const int axis = i % 2;
      const std::vector<float> a = seriesOf(1, pixel, axis), b = seriesOf(1 + n.seedStep, pixel + n.pixelStep, axis);
      const double r = correlation(a, b);
      meanNr2 += kN * r * r / kPairs;
      std::vector<glm::vec2> pairs;
      for (int k = 0; k < kN; ++k) pairs.push_back({a[size_t(k)], b[size_t(k)]});
      const double expected = kN / 256.0;
      for (int c : histogram2D(pairs, 16)) meanChi2 += (c - expected) * (c - expected) / expected / kPairs;
    }
    std::printf("%s: mean N r^2 %.2f, mean chi-square %.1f\n", n.name, meanNr2, meanChi2);
    EXPECT_LT(meanNr2, 3.0) << n.name;
    EXPECT_LT(meanChi2, 270.0) << n.name;
  }
}

// What stratification is for: a smooth 2D integrand over one 2D slot, and an additive one over two
// 1D slots, have a far smaller error than with independent numbers (same count, many pixels).
TEST(PixelSampler, StratifiedEstimatesBeatIndependentOnes) {
  auto f2 = [](glm::vec2 u) { return double(std::exp(u.x) * std::sin(2.0f * u.y + 0.5f)); };
  const double exact2 = (std::numbers::e - 1.0) * (std::cos(0.5) - std::cos(2.5)) / 2.0;
  auto f1 = [](float a, float b) { return double(a * a + std::sqrt(b)); };
  const double exact1 = 1.0 / 3.0 + 2.0 / 3.0;
  constexpr int kPixels = 200, kN = 256;
  double se2 = 0, se2Random = 0, se1 = 0, se1Random = 0;
  for (int p = 0; p < kPixels; ++p) {
    Rng rng = Rng::hashed(uint64_t(p));
    double s2 = 0, s2r = 0, s1 = 0, s1r = 0;
    for (int k = 0; k < kN; ++k) {
      PixelSampler sampler(11, uint64_t(p), uint64_t(k));
      PixelSampler independent(rng);
      s2 += f2(sampler.get2D(1, VertexDimension::BsdfDirection));
      s2r += f2(independent.get2D(1, VertexDimension::BsdfDirection));
      s1 += f1(sampler.get1D(1, VertexDimension::LightChoiceRoulette), sampler.get1D(1, VertexDimension::StrategyGuideCell));
      const float a = independent.get1D(1, VertexDimension::LightChoiceRoulette);
      s1r += f1(a, independent.get1D(1, VertexDimension::StrategyGuideCell));
    }
    se2 += std::pow(s2 / kN - exact2, 2);
    se2Random += std::pow(s2r / kN - exact2, 2);
    se1 += std::pow(s1 / kN - exact1, 2);
    se1Random += std::pow(s1r / kN - exact1, 2);
  }
  std::printf("MSE ratio stratified / independent at %d samples: 2D slot %.3g, two 1D slots %.3g\n", kN, se2 / se2Random, se1 / se1Random);
  EXPECT_LT(se2, 0.01 * se2Random);
  EXPECT_LT(se1, 0.01 * se1Random);
}

// The ablation `--sampler random`: every slot, the camera's too, gets independent uniform numbers, so
// no pixel's first samples are stratified and a smooth integrand's error is that of an independent
// stream, not the stratified sampler's hundredfold smaller one.
TEST(PixelSampler, RandomSamplerIsIndependentUniformAtEverySlot) {
  constexpr int kPixels = 64, kStrata = 4;  // 2^4 = 16 first samples per pixel
  int stratifiedPixels[2][3] = {};
  std::vector<float> camera, choice, direction;
  std::vector<glm::vec2> lightPoints;
  for (int p = 0; p < kPixels; ++p)
    for (int mode = 0; mode < 2; ++mode) {
      const bool stratified = mode == 1;
      std::vector<float> c, l, d;
      for (int k = 0; k < 512; ++k) {
        PixelSampler sampler(3, uint64_t(p), uint64_t(k), stratified);
        const float cx = sampler.cameraJitter().x, lx = sampler.get1D(0, VertexDimension::LightChoiceRoulette);
        const glm::vec2 dir = sampler.get2D(2, VertexDimension::BsdfDirection);
        if (k < (1 << kStrata)) {
          c.push_back(cx);
          l.push_back(lx);
          d.push_back(dir.y);
        }
        if (!stratified) {
          camera.push_back(cx);
          choice.push_back(lx);
          direction.push_back(dir.y);
          lightPoints.push_back(sampler.get2D(0, VertexDimension::LightPoint));
        }
      }
      stratifiedPixels[mode][0] += strataDefect(c, kStrata).empty();
      stratifiedPixels[mode][1] += strataDefect(l, kStrata).empty();
      stratifiedPixels[mode][2] += strataDefect(d, kStrata).empty();
    }
  for (int consumer = 0; consumer < 3; ++consumer) {
    // Sixteen independent numbers fall one per stratum with probability 16!/16^16, about 1e-6.
    EXPECT_EQ(stratifiedPixels[0][consumer], 0) << "consumer " << consumer;
    EXPECT_EQ(stratifiedPixels[1][consumer], kPixels) << "consumer " << consumer;
  }
  EXPECT_GT(uniformChiSquareP(histogram1D(camera, 32)), kSignificance);
  EXPECT_GT(uniformChiSquareP(histogram1D(choice, 32)), kSignificance);
  EXPECT_GT(uniformChiSquareP(histogram1D(direction, 32)), kSignificance);
  EXPECT_GT(uniformChiSquareP(histogram2D(lightPoints, 16)), kSignificance);

  auto f = [](glm::vec2 u) { return double(std::exp(u.x) * std::sin(2.0f * u.y + 0.5f)); };
  const double exact = (std::numbers::e - 1.0) * (std::cos(0.5) - std::cos(2.5)) / 2.0;
  constexpr int kEstimates = 400, kN = 64;
  double seHashed = 0, seIndependent = 0;
  for (int p = 0; p < kEstimates; ++p) {
    Rng rng = Rng::hashed(uint64_t(p) + 1000);
    double hashed = 0, independent = 0;
    for (int k = 0; k < kN; ++k) {
      hashed += f(PixelSampler(11, uint64_t(p), uint64_t(k), false).get2D(1, VertexDimension::BsdfDirection));
      independent += f(PixelSampler(rng).get2D(1, VertexDimension::BsdfDirection));
    }
    seHashed += std::pow(hashed / kN - exact, 2);
    seIndependent += std::pow(independent / kN - exact, 2);
  }
  // Each sum averages 400 squared errors: their ratio stays within [0.7, 1.4] but for 1 in 10^3 or so.
  std::printf("MSE ratio random sampler / independent stream at %d samples: %.3g\n", kN, seHashed / seIndependent);
  EXPECT_GT(seHashed, 0.7 * seIndependent);
  EXPECT_LT(seHashed, 1.4 * seIndependent);
}

TEST(PixelSampler, DeterministicInSeedPixelIndexAndIndependentOfCallOrder) {
  PixelSampler a(4, 77, 12), b(4, 77, 12);
  const float strategy = a.get1D(2, VertexDimension::StrategyGuideCell);
  const glm::vec2 light = a.get2D(0, VertexDimension::LightPoint);
  const glm::vec2 jitter = a.cameraJitter();
  // b asks in another order, and asks for other slots in between.
  EXPECT_EQ(b.cameraJitter(), jitter);
  b.get1D(0, VertexDimension::LightChoiceRoulette);
  EXPECT_EQ(b.get2D(0, VertexDimension::LightPoint), light);
  EXPECT_EQ(b.get1D(2, VertexDimension::StrategyGuideCell), strategy);
  EXPECT_EQ(a.get1D(2, VertexDimension::StrategyGuideCell), strategy);  // asking twice gives the same number
  // A vertex's paired decisions are the two coordinates of one slot, whichever is asked first.
  VertexSamples v(a, 2);
  EXPECT_EQ(v.guideCell(), a.get2D(2, VertexDimension::StrategyGuideCell).y);
  EXPECT_EQ(v.connectionChoice(), strategy);
  EXPECT_EQ(v.strategy(), strategy);
  EXPECT_EQ(VertexSamples(b, 3).roulette(), a.get2D(3, VertexDimension::LightChoiceRoulette).y);
  EXPECT_EQ(VertexSamples(b, 3).lightChoice(), a.get2D(3, VertexDimension::LightChoiceRoulette).x);
  EXPECT_NE(PixelSampler(5, 77, 12).cameraJitter(), jitter);
  EXPECT_NE(PixelSampler(4, 78, 12).cameraJitter(), jitter);
  EXPECT_NE(PixelSampler(4, 77, 13).cameraJitter(), jitter);
  EXPECT_NE(PixelSampler(4, 77, 12 + (1ull << 32)).cameraJitter(), jitter);
  // Independent mode is the given stream, in the order asked.
  Rng r1(8), r2(8);
  PixelSampler independent(r1);
  EXPECT_EQ(independent.get1D(0, VertexDimension::LightChoiceRoulette), r2.uniform());
  EXPECT_EQ(independent.cameraJitter(), r2.uniform2());
}

// VertexSamples draws ahead and leaves a shared slot's second number until asked: neither may change
// a number, at any vertex (tabulated, hashed past them, or a split path's branch).
TEST(PixelSampler, DrawnAheadAndLazyNumbersAreGet2DsNumbers) {
  for (uint64_t k = 0; k < 300; ++k) {
    PixelSampler plain(9, 31 + k, k), sampler(9, 31 + k, k);
    const PixelSampler branch = plain.branch(uint32_t(k + 1));
    for (int vertex = 0; vertex < PixelSampler::kTabulatedVertices + 2; ++vertex) {
      for (PixelSampler s : {sampler, branch}) {
        PixelSampler reference = s;
        VertexSamples v(s, vertex);
        v.drawAhead();
        ASSERT_EQ(v.lightPoint(), reference.get2D(vertex, VertexDimension::LightPoint));
        ASSERT_EQ(v.bsdfDirection(), reference.get2D(vertex, VertexDimension::BsdfDirection));
        ASSERT_EQ(v.roulette(), reference.get2D(vertex, VertexDimension::LightChoiceRoulette).y);
        ASSERT_EQ(v.lightChoice(), reference.get2D(vertex, VertexDimension::LightChoiceRoulette).x);
        ASSERT_EQ(v.connectionChoice(), reference.get2D(vertex, VertexDimension::StrategyGuideCell).x);
        ASSERT_EQ(v.guideCell(), reference.get2D(vertex, VertexDimension::StrategyGuideCell).y);
      }
    }
  }
}

// Eight lanes' numbers at once (lane_sobol.h, the path lanes' draw): each lane's point is its own
// sampler's get2D, bit for bit, whatever its pixel, sample index (past 2^32 too), vertex and slot; and
// only the vertices that draw from the stratified slots say so.
TEST(PixelSampler, LanesDrawEachSamplersOwnNumbers) {
  typedef float F __attribute__((vector_size(32)));
  typedef uint32_t U __attribute__((vector_size(32)));
  typedef uint64_t U64 __attribute__((vector_size(64)));
  for (const uint64_t index : {0ull, 1ull, 7ull, 1000ull, 0x100000003ull}) {
    for (int vertex = 0; vertex < PixelSampler::kTabulatedVertices; ++vertex) {
      U64 keys;
      U reversed, slot;
      std::vector<PixelSampler> samplers;
      for (int k = 0; k < 8; ++k) {
        const VertexDimension d = VertexDimension(uint32_t(k) % uint32_t(VertexDimension::Count));
        samplers.emplace_back(5 + uint64_t(k % 2), uint64_t(k) * 7919u + index, index + uint64_t(k / 4));
        ASSERT_TRUE(samplers.back().stratifiedAt(vertex));
        keys[k] = samplers.back().pixelKey();
        reversed[k] = samplers.back().reversedIndex();
        slot[k] = PixelSampler::slotOf(vertex, d);
      }
      F x, y;
      lane_sobol::point(keys, reversed, slot, x, y);
      for (int k = 0; k < 8; ++k) {
        const glm::vec2 expected = samplers[size_t(k)].get2D(vertex, VertexDimension(uint32_t(k) % uint32_t(VertexDimension::Count)));
        ASSERT_EQ(x[k], expected.x) << "lane " << k << " vertex " << vertex << " index " << index;
        ASSERT_EQ(y[k], expected.y) << "lane " << k << " vertex " << vertex << " index " << index;
      }
    }
  }
  PixelSampler sampler(5, 3, 4);
  EXPECT_FALSE(sampler.stratifiedAt(PixelSampler::kTabulatedVertices));
  EXPECT_FALSE(sampler.branch(1).stratifiedAt(0));
  EXPECT_FALSE(PixelSampler(5, 3, 4, false).stratifiedAt(0));
  Rng rng(1);
  EXPECT_FALSE(PixelSampler(rng).stratifiedAt(0));
}

// Past the tabulated vertices, and in the per-vertex streams, numbers are hashed random: uniform,
// deterministic, different from vertex to vertex.
TEST(PixelSampler, DeepVerticesAndStreamsAreUniformAndDeterministic) {
  constexpr int kN = 20000;
  const int deep = PixelSampler::kTabulatedVertices;
  std::vector<float> a, b, streamA, streamB;
  std::vector<glm::vec2> dirs;
  for (int k = 0; k < kN; ++k) {
    PixelSampler s(2, 10, uint64_t(k));
    a.push_back(s.get1D(deep, VertexDimension::LightChoiceRoulette));
    b.push_back(s.get1D(deep + 1, VertexDimension::LightChoiceRoulette));
    dirs.push_back(s.get2D(deep + 20, VertexDimension::BsdfDirection));
    streamA.push_back(s.random(0).uniform());
    streamB.push_back(s.random(1).uniform());
    ASSERT_EQ(PixelSampler(2, 10, uint64_t(k)).get1D(deep, VertexDimension::LightChoiceRoulette), a.back());
    ASSERT_EQ(PixelSampler(2, 10, uint64_t(k)).random(0).uniform(), streamA.back());
  }
  const double bound = 4.0 / std::sqrt(double(kN));
  EXPECT_GT(uniformChiSquareP(histogram1D(a, 100)), kSignificance);
  EXPECT_GT(uniformChiSquareP(histogram1D(b, 100)), kSignificance);
  EXPECT_GT(uniformChiSquareP(histogram2D(dirs, 20)), kSignificance);
  EXPECT_GT(uniformChiSquareP(histogram1D(streamA, 100)), kSignificance);
  EXPECT_LT(std::abs(correlation(a, b)), bound);
  EXPECT_LT(std::abs(correlation(streamA, streamB)), bound);
  std::vector<float> dx, dy;
  for (const glm::vec2& d : dirs) dx.push_back(d.x), dy.push_back(d.y);
  EXPECT_LT(std::abs(correlation(dx, dy)), bound);
}

// Bsdf::sample(wo, u) picks the lobe with u.x and reuses it, rescaled, for the direction: the
// directions must have the BSDF's pdf (chi-square), as the three-number form's do in test_bsdf.
TEST(PixelSampler, BsdfFromOneTwoDNumberMatchesItsPdf) {
  struct Case {
    const char* name;
    glm::vec3 diffuse, f0;
    float f90, alpha;
  };
  for (const Case& c : {Case{"dielectric", glm::vec3(0.7f, 0.5f, 0.3f), glm::vec3(0.04f), 1.0f, 0.2f},
                        Case{"metal", glm::vec3(0.0f), glm::vec3(0.9f, 0.6f, 0.5f), 1.0f, 0.5f},
                        Case{"diffuse", glm::vec3(0.8f), glm::vec3(0.0f), 0.0f, 1.0f}})
    for (float cosO : {0.9f, 0.3f}) {
      BsdfParams params;
      params.diffuse = c.diffuse;
      params.f0 = c.f0;
      params.f90 = c.f90;
      params.alpha = c.alpha;
      const Bsdf bsdf(params, Frame::fromNormal(glm::normalize(glm::vec3(0.2f, 0.3f, 0.9f))));
      const float sinO = std::sqrt(1.0f - cosO * cosO);
      const glm::vec3 wo = bsdf.frame().toWorld(glm::vec3(sinO * std::cos(0.7f), sinO * std::sin(0.7f), cosO));
      Rng rng(17);
      auto sample = [&]() -> glm::vec3 {
        const auto s = bsdf.sample(wo, rng.uniform2());
        return s ? bsdf.frame().toLocal(s->wi) : glm::vec3(0.0f);
      };
      auto pdf = [&](const glm::vec3& wLocal) { return double(bsdf.pdf(wo, bsdf.frame().toWorld(wLocal))); };
      const auto r = test::chiSquareSphere(sample, pdf, 200000, 48, 96, 8);
      EXPECT_GT(r.pValue, kSignificance) << c.name << " cosO " << cosO << ": " << r.report;
    }
}

// Streams made from neighbouring keys are unrelated, number by number.
TEST(Rng, HashedStreamsOfNeighbouringKeysAreIndependent) {
  constexpr int kN = 20000;
  for (int step = 0; step < 3; ++step) {
    std::vector<float> a, b;
    for (int k = 0; k < kN; ++k) {
      Rng x = Rng::hashed(uint64_t(k)), y = Rng::hashed(uint64_t(k) + 1);
      for (int i = 0; i < step; ++i) x.next(), y.next();
      a.push_back(x.uniform());
      b.push_back(y.uniform());
    }
    std::vector<glm::vec2> pairs;
    for (int k = 0; k < kN; ++k) pairs.push_back({a[size_t(k)], b[size_t(k)]});
    EXPECT_GT(uniformChiSquareP(histogram2D(pairs, 20)), kSignificance) << "number " << step;
    EXPECT_LT(std::abs(correlation(a, b)), 4.0 / std::sqrt(double(kN))) << "number " << step;
  }
}

// The tile renderer gives pass k of every pixel sample index k, whatever the thread count: a
// pixel's first 16 camera jitters form a (0,4,2)-net.
TEST(PixelSampler, TileRendererPassIsTheSampleIndex) {
  constexpr int kWidth = 20, kHeight = 18, kPasses = 16;
  CameraData data;
  data.eye = {0, 0, 5};
  data.target = {0, 0, 0};
  const Camera camera(data, kWidth, kHeight);
  std::mutex mutex;
  std::vector<std::vector<glm::vec2>> jitters(size_t(kWidth) * kHeight);
  PixelShaderFactory shader = [&](uint32_t, uint64_t) -> PixelShader {
    return [&](const Ray&, uint64_t pixel, PixelSampler& sampler, PathStats&, JoinDepthCounterfactual*) {
      const glm::vec2 j = sampler.cameraJitter();  // slots do not depend on call order: the renderer's jitter
      std::lock_guard lock(mutex);
      jitters[pixel].push_back(j);
      return glm::vec3(0.0f);
    };
  };
  const TileRenderer renderer(camera, 31, shader);
  Film film(kWidth, kHeight);
  for (int pass = 0; pass < kPasses; ++pass) renderer.renderPass(film, uint64_t(pass));
  for (size_t p = 0; p < jitters.size(); ++p) {
    ASSERT_EQ(jitters[p].size(), size_t(kPasses));
    EXPECT_EQ(jitters[p][5], PixelSampler(31, p, 5).cameraJitter()) << "pixel " << p;
    EXPECT_EQ(netDefect(jitters[p], 4), "") << "pixel " << p;
  }
}

}  // namespace
}  // namespace vpl
