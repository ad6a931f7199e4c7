// 6D slice tree and LightSlice clustering: invariants against brute force, on synthetic data.
#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <set>
#include "render/cluster/light_slice.h"
#include "render/cluster/slice_tree.h"
#include "render/sampling/rng.h"
#include "render/sampling/warps.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

std::vector<GatherPoint> randomPoints(size_t n, uint64_t seed) {
  Rng rng(seed);
  std::vector<GatherPoint> p(n);
  for (auto& g : p) {
    g.position = glm::vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 4.0f;
    g.normal = sampleUniformSphere(rng.uniform2());
  }
  return p;
}

TEST(SliceTree, EveryPointInExactlyOneSliceWithinBounds) {
  for (size_t n : {size_t(0), size_t(1), size_t(255), size_t(256), size_t(257), size_t(5000)}) {
    const auto points = randomPoints(n, 3);
    SliceSettings settings;
    const SliceTree tree = buildSliceTree(points, settings, 7.0f);
    std::vector<int> seen(n, 0);
    for (uint32_t s = 0; s < tree.slices.size(); ++s) {
      const Slice& slice = tree.slices[s];
      ASSERT_GT(slice.end, slice.begin);
      ASSERT_LE(slice.end - slice.begin, uint32_t(settings.maxSliceSize));
      bool repInside = false;
      for (uint32_t i = slice.begin; i < slice.end; ++i) {
        ++seen[tree.order[i]];
        EXPECT_EQ(tree.sliceOf[tree.order[i]], s);
        repInside |= tree.order[i] == slice.representative;
      }
      EXPECT_TRUE(repInside) << "slice " << s;
    }
    for (size_t i = 0; i < n; ++i) ASSERT_EQ(seen[i], 1) << "point " << i;
  }
}

// Gather points as a camera sees a level wall: one plane (x = 0), one normal, rows of one height,
// after `others` random points (the rest of the room). Many coordinates tie, which random points never do.
std::vector<GatherPoint> wallAfter(size_t others, uint64_t seed) {
  std::vector<GatherPoint> p = randomPoints(others, seed);
  for (int row = 0; row < 40; ++row)
    for (int column = 0; column < 60; ++column) {
      GatherPoint g;
      g.position = glm::vec3(0.0f, 0.05f * float(row), 0.05f * float(column));
      g.normal = glm::vec3(1, 0, 0);
      p.push_back(g);
    }
  return p;
}

// The first of the points [first, count) that lies strictly inside (on every coordinate `coords`
// gives) the box of another slice's points among them; -1 when none does.
template <size_t N>
int64_t pointInsideAnotherSlice(const SliceTree& tree, size_t first, size_t count,
                                const std::function<std::array<float, N>(size_t)>& coords) {
  std::vector<std::array<float, N>> lo(tree.slices.size()), hi(tree.slices.size());
  for (size_t s = 0; s < tree.slices.size(); ++s) {
    lo[s].fill(INFINITY);
    hi[s].fill(-INFINITY);
  }
  for (size_t i = first; i < count; ++i) {
    const auto e = coords(i);
    for (size_t k = 0; k < N; ++k) {
      lo[tree.sliceOf[i]][k] = std::min(lo[tree.sliceOf[i]][k], e[k]);
      hi[tree.sliceOf[i]][k] = std::max(hi[tree.sliceOf[i]][k], e[k]);
    }
  }
  for (size_t i = first; i < count; ++i) {
    const auto e = coords(i);
    for (size_t s = 0; s < tree.slices.size(); ++s) {
      if (s == tree.sliceOf[i]) continue;
      bool strictlyInside = true;
      for (size_t k = 0; k < N; ++k) strictlyInside &= e[k] > lo[s][k] && e[k] < hi[s][k];
      if (strictlyInside) return int64_t(i);
    }
  }
  return -1;
}

TEST(SliceTree, LeavesAreSeparatedAlongSplitAxes) {
  // Median splits give leaves whose 6D boxes overlap only on ties: check that for random points no
  // point lies strictly inside another leaf's box on every axis (a brute-force test of the partition).
  const auto points = randomPoints(3000, 5);
  SliceSettings settings;
  settings.maxSliceSize = 64;
  const SliceTree tree = buildSliceTree(points, settings, 7.0f);
  const std::function<std::array<float, 6>(size_t)> embed = [&](size_t i) {
    const auto& g = points[i];
    return std::array<float, 6>{g.position.x, g.position.y, g.position.z, g.normal.x * tree.normalScale,
                                g.normal.y * tree.normalScale, g.normal.z * tree.normalScale};
  };
  EXPECT_EQ(pointInsideAnotherSlice(tree, 0, points.size(), embed), -1) << "a point inside another slice's box";
  EXPECT_NEAR(tree.normalScale, 7.0f / 16.0f, 1e-6f);
}

// Points that tie on a split axis, as a camera sees a level wall, must divide along a line of the
// wall, not by their place in the array: divided that way, runs of rows joined the slices of other
// surfaces and the preview drew each run as a thin dark line. On the wall's own coordinates (y, z),
// no wall point may lie strictly inside the box of another slice's wall points.
TEST(SliceTree, TiedPointsOfAWallDivideAlongALine) {
  constexpr size_t kOthers = 1500;
  const std::vector<GatherPoint> points = wallAfter(kOthers, 5);
  SliceSettings settings;
  settings.maxSliceSize = 64;
  const SliceTree tree = buildSliceTree(points, settings, 7.0f);
  const std::function<std::array<float, 2>(size_t)> onTheWall = [&](size_t i) {
    return std::array<float, 2>{points[i].position.y, points[i].position.z};
  };
  const int64_t inside = pointInsideAnotherSlice(tree, kOthers, points.size(), onTheWall);
  EXPECT_EQ(inside, -1) << "wall point " << inside - int64_t(kOthers) << " inside the wall part of another slice";
}

TEST(SliceTree, NeighboursMatchBruteForce) {
  const auto points = randomPoints(4000, 7);
  SliceSettings settings;
  settings.maxSliceSize = 100;
  settings.neighbours = 5;
  const SliceTree tree = buildSliceTree(points, settings, 7.0f);
  auto d2 = [&](uint32_t a, uint32_t b) {
    const glm::vec3 dp = points[a].position - points[b].position;
    const glm::vec3 dn = (points[a].normal - points[b].normal) * tree.normalScale;
    return glm::dot(dp, dp) + glm::dot(dn, dn);
  };
  for (uint32_t s = 0; s < tree.slices.size(); ++s) {
    std::vector<std::pair<float, uint32_t>> all;
    for (uint32_t t = 0; t < tree.slices.size(); ++t)
      all.push_back({t == s ? -1.0f : d2(tree.slices[s].representative, tree.slices[t].representative), t});
    std::sort(all.begin(), all.end());
    const auto got = tree.neighboursOf(s);
    ASSERT_EQ(got[0], s);
    for (int k = 0; k < tree.neighbourCount; ++k) EXPECT_FLOAT_EQ(d2(tree.slices[s].representative, tree.slices[got[k]].representative),
                                                                 k == 0 ? 0.0f : all[size_t(k)].first);
  }
}

// Synthetic light transport: clamped inverse-square falloff and receiver cosine, no visibility.
class SyntheticTransport final : public LightTransport {
 public:
  SyntheticTransport(const std::vector<Vpl>& vpls, const std::vector<GatherPoint>& points, const SliceTree& tree)
      : vpls_(vpls), points_(points), tree_(tree) {}
  float contribution(uint32_t slice, uint32_t v, bool) const override {
    const GatherPoint& g = points_[tree_.slices[slice].representative];
    return exact(g, v);
  }
  float exact(const GatherPoint& g, uint32_t v) const {
    const glm::vec3 d = vpls_[v].position - g.position;
    const float d2 = std::max(glm::dot(d, d), 0.01f);
    const float cosR = std::max(0.0f, glm::dot(g.normal, glm::normalize(d)));
    return vpls_[v].power() * cosR / d2;
  }

 private:
  const std::vector<Vpl>& vpls_;
  const std::vector<GatherPoint>& points_;
  const SliceTree& tree_;
};

std::vector<Vpl> randomVpls(size_t n, uint64_t seed) {
  Rng rng(seed);
  std::vector<Vpl> v(n);
  for (auto& l : v) {
    l.position = glm::vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 6.0f - 1.0f;
    l.flux = glm::vec3(0.1f + rng.uniform(), 0.1f + rng.uniform(), 0.1f + rng.uniform());
    l.bounce = 1;
  }
  return v;
}

struct SyntheticScene {
  std::vector<GatherPoint> points;
  SliceTree tree;
  std::vector<Vpl> vpls;
};

SyntheticScene makeSetup(size_t points, size_t vpls, int sliceSize = 128) {
  SyntheticScene s;
  s.points = randomPoints(points, 11);
  SliceSettings settings;
  settings.maxSliceSize = sliceSize;
  s.tree = buildSliceTree(s.points, settings, 7.0f);
  s.vpls = randomVpls(vpls, 13);
  return s;
}

TEST(LightSlice, EveryVplInExactlyOneClusterAndFluxIsConserved) {
  const SyntheticScene s = makeSetup(2000, 3000);
  const SyntheticTransport transport(s.vpls, s.points, s.tree);
  LightSliceSettings settings;
  settings.keepMembers = true;
  settings.globalClusters = 20;
  settings.clusterBudget = 50;
  const LightSliceResult r = clusterLightSlice(s.vpls, s.points, s.tree, transport, settings);
  glm::dvec3 total(0.0);
  for (const Vpl& v : s.vpls) total += glm::dvec3(v.flux);
  ASSERT_EQ(r.slices.size(), s.tree.slices.size());
  for (const SliceClusters& sc : r.slices) {
    EXPECT_LE(sc.clusters.size(), 50u);
    EXPECT_GE(sc.clusters.size(), 20u);
    std::vector<int> seen(s.vpls.size(), 0);
    glm::dvec3 sum(0.0);
    for (const VplCluster& c : sc.clusters) {
      sum += glm::dvec3(c.totalFlux);
      bool repIsMember = false;
      for (uint32_t i = c.memberBegin; i < c.memberEnd; ++i) {
        ++seen[sc.members[i]];
        repIsMember |= sc.members[i] == c.representative;
      }
      EXPECT_TRUE(repIsMember);
      // The spread is the power-weighted RMS distance of the members from the representative.
      double spread2 = 0.0, power = 0.0;
      for (uint32_t i = c.memberBegin; i < c.memberEnd; ++i) {
        const Vpl& v = s.vpls[sc.members[i]];
        const glm::vec3 d = v.position - s.vpls[c.representative].position;
        spread2 += double(v.power()) * glm::dot(d, d);
        power += v.power();
      }
      EXPECT_NEAR(c.spread, std::sqrt(spread2 / power), 1e-4 * (1.0 + std::sqrt(spread2 / power)));
    }
    for (int count : seen) ASSERT_EQ(count, 1);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(sum[k], total[k], 1e-4 * total[k]);
  }
}

TEST(LightSlice, BudgetAtLeastVplCountGivesSingletons) {
  const SyntheticScene s = makeSetup(600, 150);
  const SyntheticTransport transport(s.vpls, s.points, s.tree);
  LightSliceSettings settings;
  settings.keepMembers = true;
  settings.globalClusters = 10;
  settings.clusterBudget = 150;
  const LightSliceResult r = clusterLightSlice(s.vpls, s.points, s.tree, transport, settings);
  for (size_t slice = 0; slice < r.slices.size(); ++slice) {
    const SliceClusters& sc = r.slices[slice];
    ASSERT_EQ(sc.clusters.size(), s.vpls.size());
    // Singleton clusters: the clustered sum at the representative is the exact VPL sum.
    double clustered = 0.0, exact = 0.0;
    for (const VplCluster& c : sc.clusters) {
      ASSERT_EQ(c.memberEnd - c.memberBegin, 1u);
      ASSERT_EQ(c.spread, 0.0f);
      clustered += c.estimate;
    }
    for (uint32_t v = 0; v < s.vpls.size(); ++v) exact += transport.contribution(uint32_t(slice), v, true);
    EXPECT_NEAR(clustered, exact, 1e-5 * exact);
  }
}

TEST(LightSlice, BudgetOfOneIsOneClusterOfEverything) {
  const SyntheticScene s = makeSetup(500, 400);
  const SyntheticTransport transport(s.vpls, s.points, s.tree);
  LightSliceSettings settings;
  settings.keepMembers = true;
  settings.globalClusters = 1;
  settings.clusterBudget = 1;
  const LightSliceResult r = clusterLightSlice(s.vpls, s.points, s.tree, transport, settings);
  for (const SliceClusters& sc : r.slices) {
    ASSERT_EQ(sc.clusters.size(), 1u);
    EXPECT_EQ(sc.members.size(), s.vpls.size());
  }
}

TEST(LightSlice, ZeroAndOneVplAndNoSlices) {
  SyntheticScene s = makeSetup(300, 0);
  const SyntheticTransport transport(s.vpls, s.points, s.tree);
  const LightSliceResult none = clusterLightSlice(s.vpls, s.points, s.tree, transport, {});
  for (const SliceClusters& sc : none.slices) EXPECT_TRUE(sc.clusters.empty());

  s.vpls = randomVpls(1, 2);
  const SyntheticTransport one(s.vpls, s.points, s.tree);
  const LightSliceResult r = clusterLightSlice(s.vpls, s.points, s.tree, one, {});
  for (const SliceClusters& sc : r.slices) {
    ASSERT_EQ(sc.clusters.size(), 1u);
    EXPECT_EQ(sc.clusters[0].representative, 0u);
  }
  const SliceTree empty = buildSliceTree({}, {}, 1.0f);
  EXPECT_TRUE(clusterLightSlice(s.vpls, {}, empty, one, {}).slices.empty());
}

TEST(LightSlice, ClusteredEstimateIsUnbiasedOverRepresentativeChoices) {
  // sum_c contribution(rep_c) totalPower_c / power(rep_c) has the exact VPL sum as its mean over seeds.
  const SyntheticScene s = makeSetup(400, 500, 400);
  const SyntheticTransport transport(s.vpls, s.points, s.tree);
  double exact = 0.0;
  for (uint32_t v = 0; v < s.vpls.size(); ++v) exact += transport.contribution(0, v, true);
  std::vector<double> estimates;
  for (uint64_t seed = 1; seed <= 200; ++seed) {
    LightSliceSettings settings;
    settings.seed = seed;
    settings.globalClusters = 4;
    settings.clusterBudget = 8;
    const LightSliceResult r = clusterLightSlice(s.vpls, s.points, s.tree, transport, settings);
    double e = 0.0;
    for (const VplCluster& c : r.slices[0].clusters) e += c.estimate;
    estimates.push_back(e);
  }
  const double mean = std::accumulate(estimates.begin(), estimates.end(), 0.0) / estimates.size();
  double var = 0.0;
  for (double e : estimates) var += (e - mean) * (e - mean);
  const double stderr_ = std::sqrt(var / (estimates.size() - 1) / estimates.size());
  EXPECT_NEAR(mean, exact, 4.0 * stderr_ + 1e-6 * exact);
}

TEST(LightSlice, EstimatorVarianceShrinksAsTheBudgetGrows) {
  // With the representative drawn by power, a cluster's estimate c_rep P / p_rep has the exact
  // variance P sum_i c_i^2 / p_i - (sum_i c_i)^2: a deterministic measure of the clustering itself.
  const SyntheticScene s = makeSetup(800, 2000, 200);
  const SyntheticTransport transport(s.vpls, s.points, s.tree);
  auto variance = [&](int budget) {
    LightSliceSettings settings;
    settings.keepMembers = true;
    settings.globalClusters = std::min(budget, 8);
    settings.clusterBudget = budget;
    const LightSliceResult r = clusterLightSlice(s.vpls, s.points, s.tree, transport, settings);
    double total = 0.0, exact = 0.0;
    for (uint32_t slice = 0; slice < r.slices.size(); ++slice) {
      const SliceClusters& sc = r.slices[slice];
      for (const VplCluster& c : sc.clusters) {
        double sumC = 0.0, sumC2overP = 0.0;
        for (uint32_t i = c.memberBegin; i < c.memberEnd; ++i) {
          const uint32_t v = sc.members[i];
          const double ci = transport.contribution(slice, v, true), pi = s.vpls[v].power();
          sumC += ci;
          sumC2overP += ci * ci / pi;
          exact += ci;
        }
        total += std::max(0.0, c.totalPower * sumC2overP - sumC * sumC);
      }
    }
    return std::sqrt(total) / exact;  // relative standard deviation, all slices together
  };
  const double v8 = variance(8), v64 = variance(64), v512 = variance(512), vAll = variance(2000);
  std::printf("relative std. dev. by budget: 8 %.3f, 64 %.3f, 512 %.3f, 2000 %.3g\n", v8, v64, v512, vAll);
  // Refinement weighs the neighbouring rows too, so the error at the representative alone falls
  // steadily rather than by the square root of the budget.
  EXPECT_LT(v64, 0.8 * v8);
  EXPECT_LT(v512, v64);
  EXPECT_NEAR(vAll, 0.0, 1e-6);
}

}  // namespace
}  // namespace vpl
