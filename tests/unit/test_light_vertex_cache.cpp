// The light vertex cache's choice of the vertex a camera vertex joins: the probability that each pick
// reports (through its scale) is the one it is drawn with, before and after learning. That the joins
// stay unbiased on whole scenes is WhiteFurnace.ConvergesWithVplConnections and the guided modes'
// agreement with brdf (test_guided_modes), which join by the learned choice.
#include <map>
#include <thread>
#include <vector>
#include "render/integrator/light_vertex_cache.h"
#include "render/sampling/rng.h"
#include "render/vpl/light_walk.h"
#include "render/scene/gltf_loader.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

constexpr int kPaths = 256;
// One join per camera vertex: a pick's scale is then one over its probability times the paths.
constexpr ConnectionSettings kOneJoin{.learnChoice = true, .joinsPerVertex = 1};
constexpr ConnectionSettings kOneUniformJoin{.learnChoice = false, .joinsPerVertex = 1};

// Each vertex's pick probability as its scale states it: scale = 1 / (probability x paths).
std::vector<double> statedProbabilities(const LightVertexCache& cache) {
  std::vector<double> p(cache.vertices().size(), 0.0);
  const size_t n = p.size();
  // Every vertex is reached by some u: sweep u finely enough to land in each one.
  for (size_t i = 0; i < 64 * n; ++i) {
    float scale = 0.0f;
    const LightVertex& v = cache.pick((float(i) + 0.5f) / float(64 * n), scale);
    p[size_t(&v - cache.vertices().data())] = 1.0 / (double(scale) * kPaths);
  }
  return p;
}

// Draws picks with random numbers and compares the histogram of vertices with the stated
// probabilities (chi-square; vertices expected fewer than 5 times pooled).
double pickChiSquarePValue(const LightVertexCache& cache, const std::vector<double>& stated, int draws) {
  std::vector<double> counts(stated.size(), 0.0);
  Rng rng(7);
  for (int i = 0; i < draws; ++i) {
    float scale = 0.0f;
    ++counts[size_t(&cache.pick(rng.uniform(), scale) - cache.vertices().data())];
  }
  double statistic = 0.0, pooledExpected = 0.0, pooledCount = 0.0;
  int bins = 0;
  for (size_t i = 0; i < stated.size(); ++i) {
    const double expected = stated[i] * draws;
    if (expected < 5.0) {
      pooledExpected += expected;
      pooledCount += counts[i];
      continue;
    }
    statistic += (counts[i] - expected) * (counts[i] - expected) / expected;
    ++bins;
  }
  if (pooledExpected >= 5.0) {
    statistic += (pooledCount - pooledExpected) * (pooledCount - pooledExpected) / pooledExpected;
    ++bins;
  }
  return test::chiSquareTail(statistic, bins - 1);
}

RenderScene cornellBox() { return RenderScene(loadGltf(test::sourceDir() + "/scenes/cornell_box.gltf")); }

TEST(LightVertexCache, UniformChoiceGivesEveryVertexTheSameProbability) {
  const RenderScene scene = cornellBox();
  LightVertexCache cache(kOneUniformJoin);
  cache.build(scene, 1, 0, kPaths, 8, true);
  ASSERT_FALSE(cache.empty());
  for (size_t i = 0; i < cache.vertices().size(); ++i) cache.record(cache.vertices()[i], 5.0f);  // ignored
  cache.build(scene, 1, 1, kPaths, 8, true);
  EXPECT_EQ(cache.learnedShare(), 0.0f);
  const std::vector<double> p = statedProbabilities(cache);
  for (const double pi : p) EXPECT_NEAR(pi * double(p.size()), 1.0, 1e-4);
  EXPECT_GT(pickChiSquarePValue(cache, p, 200000), 1e-3);
}

// After a pass whose joins brought light back from a few cells only, those cells are picked more
// often, every other vertex keeps at least the uniform share, and each pick's scale is exact.
TEST(LightVertexCache, LearnedChoiceDrawsEachVertexWithTheProbabilityItsScaleStates) {
  const RenderScene scene = cornellBox();
  LightVertexCache cache(kOneJoin);
  cache.build(scene, 1, 0, kPaths, 8, true);
  ASSERT_FALSE(cache.empty());
  EXPECT_EQ(cache.learnedShare(), 0.0f);  // nothing learned yet: uniform
  std::map<uint32_t, int> cellsSeen;
  for (const LightVertex& v : cache.vertices()) ++cellsSeen[v.cell];
  ASSERT_GT(cellsSeen.size(), 4u);
  // Joins to the vertices of every third cell brought light back, the rest none.
  for (const LightVertex& v : cache.vertices())
    if (v.cell % 3 == 0) cache.record(v, 0.25f);
  cache.build(scene, 1, 1, kPaths, 8, true);
  EXPECT_FLOAT_EQ(cache.learnedShare(), 1.0f - LightVertexCache::kUniformShare);

  const std::vector<double> p = statedProbabilities(cache);
  double sum = 0.0, lit = 0.0, smallest = 1.0, largest = 0.0;
  const double uniform = 1.0 / double(p.size());
  for (size_t i = 0; i < p.size(); ++i) {
    sum += p[i];
    if (cache.vertices()[i].cell % 3 == 0) lit += p[i];
    smallest = std::min(smallest, p[i]);
    largest = std::max(largest, p[i]);
  }
  EXPECT_NEAR(sum, 1.0, 1e-4);
  EXPECT_GE(smallest, LightVertexCache::kUniformShare * uniform * (1.0 - 1e-4));
  EXPECT_GT(largest, 2.0 * uniform);  // the learned choice is not uniform
  EXPECT_GT(lit, 1.0 - LightVertexCache::kUniformShare);
  EXPECT_GT(pickChiSquarePValue(cache, p, 400000), 1e-3);
}

// What is recorded is summed as integers: the same records in another order give the same choice.
TEST(LightVertexCache, RecordsInAnyOrderGiveTheSameChoice) {
  const RenderScene scene = cornellBox();
  LightVertexCache forward(kOneJoin), backward(kOneJoin);
  forward.build(scene, 3, 0, kPaths, 8, true);
  backward.build(scene, 3, 0, kPaths, 8, true);
  const std::vector<LightVertex>& v = forward.vertices();
  for (size_t i = 0; i < v.size(); ++i) forward.record(v[i], 0.1f + 0.37f * float(i % 7));
  for (size_t i = v.size(); i-- > 0;) backward.record(backward.vertices()[i], 0.1f + 0.37f * float(i % 7));
  forward.build(scene, 3, 1, kPaths, 8, true);
  backward.build(scene, 3, 1, kPaths, 8, true);
  EXPECT_EQ(statedProbabilities(forward), statedProbabilities(backward));
}

// Records from several threads (each writes its own lane of the sums) give the choice that the same
// records from one thread give.
TEST(LightVertexCache, RecordsFromManyThreadsGiveTheSameChoiceAsFromOne) {
  const RenderScene scene = cornellBox();
  LightVertexCache single(kOneJoin), threaded(kOneJoin);
  single.build(scene, 5, 0, kPaths, 8, true);
  threaded.build(scene, 5, 0, kPaths, 8, true);
  const auto value = [](size_t i) { return 0.2f + 0.53f * float(i % 5); };
  for (size_t i = 0; i < single.vertices().size(); ++i) single.record(single.vertices()[i], value(i));
  constexpr size_t kThreads = 4;
  std::vector<std::thread> threads;
  for (size_t t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      const std::vector<LightVertex>& v = threaded.vertices();
      for (size_t i = t; i < v.size(); i += kThreads) threaded.record(v[i], value(i));
    });
  for (std::thread& t : threads) t.join();
  single.build(scene, 5, 1, kPaths, 8, true);
  threaded.build(scene, 5, 1, kPaths, 8, true);
  EXPECT_GT(threaded.learnedShare(), 0.0f);
  EXPECT_EQ(statedProbabilities(single), statedProbabilities(threaded));
}

// `--sampler random` reaches the light paths: the same seed and pass trace other paths than the
// stratified ones, and the same paths again when asked twice.
TEST(LightVertexCache, TheRandomSamplerGivesTheLightPathsNumbersOfTheirOwn) {
  const RenderScene scene = cornellBox();
  const auto positions = [&](bool stratified) {
    LightVertexCache cache(kOneUniformJoin);
    cache.build(scene, 9, 0, kPaths, 8, stratified);
    std::vector<glm::vec3> p;
    for (const LightVertex& v : cache.vertices()) p.push_back(v.position);
    return p;
  };
  EXPECT_EQ(positions(true), positions(true));
  EXPECT_EQ(positions(false), positions(false));
  EXPECT_NE(positions(true), positions(false));
}

// A pass's light paths start as a pixel's samples spread: 1024 starts on the Cornell box's light (two
// triangles, the emitter folded into the position), counted on an 8 x 8 grid over the light's
// extent, and their directions on an 8 x 8 grid of the cosine-weighted hemisphere's disk. The
// counts' chi-square statistic over its degrees of freedom, about 1 for random starts, falls far
// below it when the starts are stratified (measured: positions 0.073 against 1.03 for random,
// directions 0.056 against 0.83).
double startChiSquarePerDegree(const RenderScene& scene, bool stratified, bool directions) {
  constexpr int kStarts = 1024, kGrid = 8;
  std::vector<glm::vec2> points;
  for (int i = 0; i < kStarts; ++i) {
    std::optional<EmissionSample> e;
    if (stratified) {
      StratifiedWalkNumbers numbers{PixelSampler(11, ~uint64_t(0), uint64_t(i))};
      e = startLightPath(scene, numbers);
    } else {
      Rng rng = Rng::hashed(uint64_t(i) * 7919u + 11u);
      RandomWalkNumbers numbers{rng};
      e = startLightPath(scene, numbers);
    }
    if (!e) continue;
    // The light faces down (-y): its extent in x and z; a direction's x and z on the unit disk.
    points.push_back(directions ? glm::vec2(e->direction.x, e->direction.z) * 0.5f + 0.5f
                                : glm::vec2(e->position.x, e->position.z));
  }
  EXPECT_EQ(points.size(), size_t(kStarts));
  glm::vec2 lo(INFINITY), hi(-INFINITY);
  for (const glm::vec2& p : points) lo = glm::min(lo, p), hi = glm::max(hi, p);
  if (directions) lo = glm::vec2(0.0f), hi = glm::vec2(1.0f);
  std::vector<double> counts(kGrid * kGrid, 0.0), expected(kGrid * kGrid, 0.0);
  for (const glm::vec2& p : points) {
    const glm::ivec2 c = glm::min(glm::ivec2((p - lo) / (hi - lo) * float(kGrid)), glm::ivec2(kGrid - 1));
    ++counts[size_t(c.y * kGrid + c.x)];
  }
  // Uniform over the light's rectangle; over the disk, the cosine-weighted hemisphere's projection is
  // uniform on the disk: the expected share of a cell is its area inside the unit circle.
  double chi = 0.0, total = 0.0;
  for (int y = 0; y < kGrid; ++y)
    for (int x = 0; x < kGrid; ++x) {
      double inside = 1.0;
      if (directions) {
        constexpr int kSub = 64;
        int n = 0;
        for (int a = 0; a < kSub; ++a)
          for (int b = 0; b < kSub; ++b) {
            const double u = (x + (a + 0.5) / kSub) / kGrid * 2.0 - 1.0, v = (y + (b + 0.5) / kSub) / kGrid * 2.0 - 1.0;
            n += u * u + v * v < 1.0;
          }
        inside = double(n) / (kSub * kSub);
      }
      expected[size_t(y * kGrid + x)] = inside;
      total += inside;
    }
  int cells = 0;
  for (size_t k = 0; k < counts.size(); ++k) {
    const double e = expected[k] / total * double(points.size());
    if (e < 5.0) continue;
    chi += (counts[k] - e) * (counts[k] - e) / e;
    ++cells;
  }
  return chi / double(cells - 1);
}

TEST(LightWalk, PathsOfAPassStartStratifiedOverTheLightAndItsDirections) {
  const RenderScene scene = cornellBox();
  for (const bool directions : {false, true}) {
    const double stratified = startChiSquarePerDegree(scene, true, directions);
    const double random = startChiSquarePerDegree(scene, false, directions);
    EXPECT_LT(stratified, 0.25) << (directions ? "directions" : "positions");
    EXPECT_GT(random, 0.5) << (directions ? "directions" : "positions") << ": the test no longer tells the two apart";
  }
}

}  // namespace
}  // namespace vpl
