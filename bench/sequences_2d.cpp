// The renderer's 2D slot (Owen-scrambled Sobol', render/sampling/pixel_sampler.h) against progressive
// multi-jittered (0,2) points (pmj02: Christensen, Kensler & Kilpatrick 2018, the pattern of the
// Cycles runs in bench/vs_cycles.sh) and against independent random numbers, on 2D integrands with a
// known answer: the issue asked for the sampler to be picked by measurement.
//
// Every trial is one pixel: the Sobol' slot with that pixel's shuffle and scrambles, a pmj02 sequence
// generated afresh (it is random by construction), the same sequence Owen-scrambled, a pmj02 sequence
// whose every aligned block is a net too, and random numbers. Each estimate is the mean of a prefix of
// n points; the table gives each sampler's mean squared error over the trials at every n, powers of two
// and between them (docs/measurements/stratification.md reads it).
//
// Usage: sequences_2d [TRIALS]   (default 16384)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "render/sampling/pixel_sampler.h"
#include "render/sampling/rng.h"
#include "render/sampling/sobol.h"
#include "render/sampling/warps.h"

namespace {

using vpl::Rng;

constexpr int kMaxLevel = 8;  // 256 points
constexpr int kMaxPoints = 1 << kMaxLevel;

struct Point2 {
  uint32_t x, y;  // 0.32 fixed point
};

// The top `bits` binary digits of a 0.32 fraction.
uint32_t top(uint32_t v, int bits) { return bits == 0 ? 0u : v >> (32 - bits); }

// pmj02 by the progressive construction of Christensen et al.: from 2^(L-1) points to 2^L, each old point
// gets a new one in the subsquare of its grid cell that pmj names (the diagonally opposite one after a
// square number of points; after twice a square, the cell's two points both swap in x or both in y), at a
// random place that leaves every elementary interval of area 2^-L with one point: each prefix of 2^m
// points is a (0,m,2)-net. With `everyBlock` false the swaps are drawn at random and only the prefixes are
// nets; with it true every aligned block of 2^m points must be a net too, as in a (0,2)-sequence (Sobol's
// first two dimensions are one), and each cell's swap is whichever its first new point's place needs. A
// choice can leave a new point no place; the doubling is then drawn again (counted in `redraws`).
class Pmj02 {
 public:
  explicit Pmj02(bool everyBlock) : everyBlock_(everyBlock) {}
  std::vector<Point2> generate(Rng& rng, int levels) {
    std::vector<Point2> points{{rng.next(), rng.next()}};
    for (int level = 1; level <= levels; ++level) {
      const size_t old = points.size();
      for (long attempts = 1; !doubleOnce(rng, level, points); ++attempts) {
        points.resize(old);
        ++redraws;
        if (attempts > 100000) {
          std::fprintf(stderr, "sequences_2d: pmj02 generation keeps failing\n");
          std::exit(1);
        }
      }
    }
    return points;
  }
  long redraws = 0;

 private:
  // The elementary interval of area 2^-m and shape a (2^a columns, 2^(m-a) rows) holding the fine cell
  // (col, row) of the 2^level grid.
  static uint32_t cell(uint32_t col, uint32_t row, int level, int m, int a) {
    return (col >> (level - a)) << (m - a) | (row >> (level - m + a));
  }

  bool doubleOnce(Rng& rng, int level, std::vector<Point2>& points) {
    // taken[m][a]: the intervals of area 2^-m and shape a that the current aligned block of 2^m points
    // holds (m < level only when every block must be a net).
    std::vector<std::vector<std::vector<uint8_t>>> taken(size_t(level) + 1);
    for (int m = 0; m <= level; ++m) taken[size_t(m)].assign(size_t(m) + 1, std::vector<uint8_t>(size_t(1) << m, 0));
    auto mark = [&](uint32_t col, uint32_t row, int fromLevel) {
      for (int m = fromLevel; m <= level; ++m)
        for (int a = 0; a <= m; ++a) taken[size_t(m)][size_t(a)][cell(col, row, level, m, a)] = 1;
    };
    const size_t old = points.size();
    for (const Point2& p : points) mark(top(p.x, level), top(p.y, level), level);  // old points share only the whole

    const int grid = (level - 1) / 2;          // the square cells' digits: 2^grid cells a side
    const bool square = (level - 1) % 2 == 0;  // one old point per square cell, else two
    // After twice a square: whether a cell's two points swap in x (1), in y (0), or not decided yet (-1).
    std::vector<int8_t> swapX(size_t(1) << (2 * grid), -1);
    if (!everyBlock_)
      for (auto& s : swapX) s = int8_t(rng.next() & 1u);

    const int span = level - (grid + 1);  // fine columns (and rows) across a subsquare, as digits
    const int firstLevel = everyBlock_ ? 1 : level;
    struct Candidate {
      uint32_t col, row;
      int8_t swap;
    };
    std::vector<Candidate> valid;
    for (size_t i = 0; i < old; ++i) {
      const size_t index = old + i;
      for (int m = firstLevel; m < level; ++m)  // a new aligned block of 2^m starts: forget the last one
        if ((index & ((size_t(1) << m) - 1)) == 0)
          for (auto& shape : taken[size_t(m)]) std::fill(shape.begin(), shape.end(), 0);
      const Point2 p = points[i];
      const uint32_t sx = top(p.x, grid + 1) & 1u, sy = top(p.y, grid + 1) & 1u;
      const size_t gridCell = size_t(top(p.x, grid) << grid | top(p.y, grid));
      valid.clear();
      for (int8_t swap = 0; swap <= 1; ++swap) {
        if (!square && swapX[gridCell] >= 0 && swapX[gridCell] != swap) continue;
        if (square && swap == 0) continue;  // one subsquare only: the diagonal one
        const uint32_t qx = square || swap ? sx ^ 1u : sx, qy = square || !swap ? sy ^ 1u : sy;
        const uint32_t colBase = (top(p.x, grid) << 1 | qx) << span, rowBase = (top(p.y, grid) << 1 | qy) << span;
        for (uint32_t dc = 0; dc < (1u << span); ++dc)
          for (uint32_t dr = 0; dr < (1u << span); ++dr) {
            bool free = true;
            for (int m = firstLevel; m <= level && free; ++m)
              for (int a = 0; a <= m && free; ++a)
                free = !taken[size_t(m)][size_t(a)][cell(colBase + dc, rowBase + dr, level, m, a)];
            if (free) valid.push_back({colBase + dc, rowBase + dr, swap});
          }
      }
      if (valid.empty()) return false;
      const Candidate c = valid[rng.next() % valid.size()];
      if (!square) swapX[gridCell] = c.swap;
      const uint32_t lowMask = ~0u >> level;
      mark(c.col, c.row, firstLevel);
      points.push_back(
          {c.col << (32 - level) | (rng.next() & lowMask), c.row << (32 - level) | (rng.next() & lowMask)});
    }
    return true;
  }
  bool everyBlock_;
};

// Whether every block of 2^m points that starts at a multiple of `stride(m)` is a (0,m,2)-net: with
// stride 2^m, every aligned block (a (0,2)-sequence); with a stride past the end, the prefixes only.
template <class Stride>
bool blocksAreNets(const std::vector<Point2>& points, Stride stride) {
  for (int m = 0; (size_t(1) << m) <= points.size(); ++m) {
    const size_t n = size_t(1) << m;
    for (size_t start = 0; start + n <= points.size(); start += stride(n))
      for (int a = 0; a <= m; ++a) {
        std::vector<uint8_t> seen(n, 0);
        for (size_t i = start; i < start + n; ++i)
          if (seen[top(points[i].x, a) << (m - a) | top(points[i].y, m - a)]++) return false;
      }
  }
  return true;
}

float unit(uint32_t v) { return vpl::sobol::toUnitFloat(v); }

struct Integrand {
  std::string name;
  std::function<double(double, double)> f;
  double exact;
};

// The renderer's Lambertian sampling (sampleCosineHemisphere, the concentric disk lifted): its estimate of
// the share of a square light (z = 1, x in [-0.25, 0.25], y in [0.1, 0.6]) is the indicator of a hit.
double cosineLightHit(double u, double v) {
  const glm::vec3 w = vpl::sampleCosineHemisphere(glm::vec2(float(u), float(v)));
  if (w.z <= 0.0f) return 0.0;
  const double hx = double(w.x) / w.z, hy = double(w.y) / w.z;
  return (hx >= -0.25 && hx <= 0.25 && hy >= 0.1 && hy <= 0.6) ? 1.0 : 0.0;
}

// The light's share without sampling noise: 2^22 points of the first two Sobol' dimensions (a
// (0,22,2)-net), whose error on an indicator is far below the table's.
double cosineLightExact() {
  double sum = 0.0;
  const uint32_t n = 1u << 22;
  for (uint32_t i = 0; i < n; ++i)
    sum += cosineLightHit((double(vpl::sobol::vanDerCorput(i)) + 0.5) * 0x1p-32,
                          (double(vpl::sobol::sobolSecond(i)) + 0.5) * 0x1p-32);
  return sum / n;
}

}  // namespace

int main(int argc, char** argv) {
  const long trials = argc > 1 ? std::atol(argv[1]) : 16384;
  if (trials < 16) {
    std::fprintf(stderr, "sequences_2d: TRIALS must be at least 16\n");
    return 2;
  }
  const double gaussian = std::pow(std::sqrt(M_PI) / 2.0 * std::erf(1.0), 2.0);
  const std::vector<Integrand> integrands{
      {"quarter disk (r = 0.9)", [](double x, double y) { return x * x + y * y < 0.81 ? 1.0 : 0.0; },
       M_PI * 0.81 / 4.0},
      {"tilted step (x + 0.7y < 0.6)", [](double x, double y) { return x + 0.7 * y < 0.6 ? 1.0 : 0.0; }, 0.36 / 1.4},
      {"Gaussian exp(-x^2-y^2)", [](double x, double y) { return std::exp(-x * x - y * y); }, gaussian},
      {"bilinear xy", [](double x, double y) { return x * y; }, 0.25},
      {"square light, cosine-sampled", cosineLightHit, cosineLightExact()},
  };
  const std::vector<int> counts{4, 8, 12, 16, 24, 32, 48, 64, 96, 128, 192, 256};
  enum Sampler { kSobol, kPmj, kPmjOwen, kPmjBlocks, kRandom, kSamplers };
  const char* names[kSamplers] = {"sobol slot", "pmj02", "pmj02 Owen", "pmj02 every block", "random"};

  // sum and sum of squares of the squared error, per integrand, count and sampler
  const size_t cells = integrands.size() * counts.size() * kSamplers;
  std::vector<double> se(cells, 0.0), se2(cells, 0.0);
  auto at = [&](size_t f, size_t c, int s) { return (f * counts.size() + c) * kSamplers + size_t(s); };

  Pmj02 pmj(false), pmjBlocks(true);
  long notNets = 0, zeroTwo = 0, sobolZeroTwo = 0, strictNotZeroTwo = 0;
  std::array<std::vector<std::array<double, 2>>, kSamplers> pts;
  for (auto& p : pts) p.resize(kMaxPoints);
  for (long t = 0; t < trials; ++t) {
    const uint64_t key = vpl::mix64(uint64_t(t) ^ 0x5e9ae9ce5ull);
    std::vector<Point2> slot(kMaxPoints);
    for (int i = 0; i < kMaxPoints; ++i) {
      vpl::PixelSampler sampler(7, uint64_t(t), uint64_t(i));
      const glm::vec2 u = sampler.get2D(0, vpl::VertexDimension::BsdfDirection);
      pts[kSobol][size_t(i)] = {u.x, u.y};
      slot[size_t(i)] = {uint32_t(double(u.x) * 0x1p32), uint32_t(double(u.y) * 0x1p32)};
    }
    sobolZeroTwo += blocksAreNets(slot, [](size_t n) { return n; }) ? 1 : 0;
    Rng rng = Rng::hashed(key);
    const std::vector<Point2> seq = pmj.generate(rng, kMaxLevel);
    const std::vector<Point2> strict = pmjBlocks.generate(rng, kMaxLevel);
    notNets += blocksAreNets(seq, [](size_t) { return size_t(kMaxPoints) + 1; }) ? 0 : 1;
    zeroTwo += blocksAreNets(seq, [](size_t n) { return n; }) ? 1 : 0;
    strictNotZeroTwo += blocksAreNets(strict, [](size_t n) { return n; }) ? 0 : 1;
    const uint32_t seedX = uint32_t(vpl::mix64(key + 1)), seedY = uint32_t(vpl::mix64(key + 2));
    for (int i = 0; i < kMaxPoints; ++i) {
      const Point2 p = seq[size_t(i)];
      pts[kPmj][size_t(i)] = {unit(p.x), unit(p.y)};
      pts[kPmjOwen][size_t(i)] = {unit(vpl::sobol::owenScramble(p.x, seedX)),
                                  unit(vpl::sobol::owenScramble(p.y, seedY))};
      pts[kPmjBlocks][size_t(i)] = {unit(strict[size_t(i)].x), unit(strict[size_t(i)].y)};
      pts[kRandom][size_t(i)] = {rng.uniform(), rng.uniform()};
    }
    for (size_t f = 0; f < integrands.size(); ++f)
      for (int s = 0; s < kSamplers; ++s) {
        double sum = 0.0;
        size_t c = 0;
        for (int i = 0; i < kMaxPoints; ++i) {
          sum += integrands[f].f(pts[size_t(s)][size_t(i)][0], pts[size_t(s)][size_t(i)][1]);
          if (c < counts.size() && i + 1 == counts[c]) {
            const double e = sum / counts[c] - integrands[f].exact;
            se[at(f, c, s)] += e * e;
            se2[at(f, c, s)] += e * e * e * e;
            ++c;
          }
        }
      }
  }

  std::printf(
      "# sequences_2d: %ld trials of %d points; pmj02 doublings drawn again: %ld; pmj02 sequences whose 2^m "
      "prefixes are not all nets: %ld; that are (0,2)-sequences (every aligned block a net): %ld; Sobol' slots that "
      "are: %ld; pmj02 every block: doublings drawn again %ld, sequences that are not (0,2)-sequences %ld\n",
      trials, kMaxPoints, pmj.redraws, notNets, zeroTwo, sobolZeroTwo, pmjBlocks.redraws, strictNotZeroTwo);
  std::printf("# MSE x n per sampler (its standard error in %%), and MSE ratios to the Sobol' slot\n");
  for (size_t f = 0; f < integrands.size(); ++f) {
    std::printf("\n## %s, exact %.9f\n\n| n |", integrands[f].name.c_str(), integrands[f].exact);
    for (const char* n : names) std::printf(" %s |", n);
    std::printf(" pmj02 / sobol | pmj02 Owen / sobol | every block / sobol | sobol / random |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
    for (size_t c = 0; c < counts.size(); ++c) {
      double mse[kSamplers];
      std::printf("| %d |", counts[c]);
      for (int s = 0; s < kSamplers; ++s) {
        mse[s] = se[at(f, c, s)] / double(trials);
        const double var = se2[at(f, c, s)] / double(trials) - mse[s] * mse[s];
        const double rel = mse[s] > 0.0 ? 100.0 * std::sqrt(std::max(0.0, var) / double(trials)) / mse[s] : 0.0;
        std::printf(" %.3e (%.1f) |", mse[s] * counts[c], rel);
      }
      std::printf(" %.3f | %.3f | %.3f | %.3f |\n", mse[kPmj] / mse[kSobol], mse[kPmjOwen] / mse[kSobol],
                  mse[kPmjBlocks] / mse[kSobol], mse[kSobol] / mse[kRandom]);
    }
  }
  return notNets == 0 && strictNotZeroTwo == 0 && sobolZeroTwo == trials ? 0 : 1;
}
