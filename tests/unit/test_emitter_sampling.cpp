// Emitter sampling: the spherical triangle (solid angle and uniform directions in it), the alias
// table that chooses a light by power, and EmitterSet::sample against pdfTriangle (the density an
// emitter hit is MIS-weighted with) and against the closed-form irradiance of a polygon.
//
// Random numbers come from std::mt19937_64 here, not from the renderer's generator, so these tests
// check the samplers for any uniform input.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <optional>
#include <random>
#include <vector>
#include "render/sampling/alias_table.h"
#include "render/sampling/spherical_triangle.h"
#include "render/scene/emitters.h"
#include "tests/unit/scene_builders.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

constexpr double kPiD = std::numbers::pi;
constexpr double kSignificance = 1e-3;

struct Uniforms {
  std::mt19937_64 engine;
  explicit Uniforms(uint64_t seed) : engine(seed) {}
  float next() { return float(engine() >> 40) * 0x1p-24f; }  // in [0, 1), 24 random bits
  glm::vec2 next2() {
    const float a = next();
    return {a, next()};
  }
};

// ---- Independent geometry for the checks -------------------------------------------------------
struct Triangle {
  glm::dvec3 v0, v1, v2;
};

// Barycentrics (b1, b2) and distance t where p + t w meets the plane of tri, not clamped;
// nullopt when w is parallel to it. (Written out here rather than taken from the renderer.)
struct PlaneHit {
  double b1, b2, t;
};
std::optional<PlaneHit> hitPlane(const Triangle& tri, const glm::dvec3& p, const glm::dvec3& w) {
  const glm::dvec3 n = glm::cross(tri.v1 - tri.v0, tri.v2 - tri.v0);
  const double dn = glm::dot(w, n);
  if (dn == 0.0) return std::nullopt;
  const double t = glm::dot(tri.v0 - p, n) / dn;
  const glm::dvec3 x = p + t * w;
  // Barycentrics by sub-triangle areas, signed against n.
  const double area2 = glm::dot(n, n);
  const double b1 = glm::dot(glm::cross(x - tri.v0, tri.v2 - tri.v0), n) / area2;  // weight of v1
  const double b2 = glm::dot(glm::cross(tri.v1 - tri.v0, x - tri.v0), n) / area2;  // weight of v2
  return PlaneHit{b1, b2, t};
}
bool hitsTriangle(const Triangle& tri, const glm::dvec3& p, const glm::dvec3& w) {
  const auto h = hitPlane(tri, p, w);
  return h && h->t > 0.0 && h->b1 >= 0.0 && h->b2 >= 0.0 && h->b1 + h->b2 <= 1.0;
}

double solidAngleOf(const Triangle& tri, const glm::dvec3& p) {
  return triangleSolidAngle(tri.v0 - p, tri.v1 - p, tri.v2 - p);
}

// Solid angle of the triangle from p by quadrature over its area: the integral of cos / d^2 =
// h / d^3 (h the distance from p to the plane), by the midpoint rule on k^2 congruent
// sub-triangles. Independent of the closed form, and it resolves thin and grazing triangles that
// a grid of directions cannot.
double solidAngleByQuadrature(const Triangle& tri, const glm::dvec3& p, int k) {
  const glm::dvec3 e1 = tri.v1 - tri.v0, e2 = tri.v2 - tri.v0;
  const glm::dvec3 n = glm::normalize(glm::cross(e1, e2));
  const double h = std::abs(glm::dot(tri.v0 - p, n));
  const double subArea = 0.5 * glm::length(glm::cross(e1, e2)) / (double(k) * k);
  double sum = 0.0;
  auto term = [&](double b1, double b2) {
    const glm::dvec3 d = tri.v0 + (b1 / k) * e1 + (b2 / k) * e2 - p;
    const double r2 = glm::dot(d, d);
    return h / (r2 * std::sqrt(r2));
  };
  for (int i = 0; i < k; ++i)
    for (int j = 0; i + j < k; ++j) {
      sum += term(i + 1.0 / 3.0, j + 1.0 / 3.0);                         // the sub-triangle with its corner at (i, j)
      if (i + j <= k - 2) sum += term(i + 2.0 / 3.0, j + 2.0 / 3.0);  // the one turned over
    }
  return sum * subArea;
}

// Chi-square of directions against uniform solid angle, binned by which of k^2 congruent
// sub-triangles of the planar triangle they hit. A sub-triangle's expected share is its own
// solid angle over the whole one, so bins follow the triangle however small, thin or grazing it
// looks. Also checks that every direction hits the triangle (barycentrics within 1e-6).
test::ChiSquareResult chiSquareOnTriangle(const Triangle& tri, const glm::dvec3& p,
                                          const std::function<glm::dvec3()>& sample, int sampleCount, int k,
                                          int* offTriangle) {
  // Sub-triangle index of barycentrics (b1, b2): the cell (i, j) of the k-grid, then its upper or lower half.
  auto binOf = [k](double b1, double b2) {
    const double x = std::clamp(b1, 0.0, 1.0) * k, y = std::clamp(b2, 0.0, 1.0) * k;
    int i = std::min(int(x), k - 1), j = std::min(int(y), k - 1);
    if (i + j > k - 1) j = k - 1 - i;
    const bool upper = (x - i) + (y - j) > 1.0 && i + j <= k - 2;
    return (i * k + j) * 2 + (upper ? 1 : 0);
  };
  const int binCount = 2 * k * k;
  std::vector<double> observed(binCount + 1, 0.0), expected(binCount + 1, 0.0);
  *offTriangle = 0;
  for (int s = 0; s < sampleCount; ++s) {
    const glm::dvec3 w = sample();
    const auto h = hitPlane(tri, p, w);
    if (!h || !(h->t > 0.0)) {
      ++*offTriangle;
      observed[binCount] += 1;
      continue;
    }
    if (h->b1 < -1e-6 || h->b2 < -1e-6 || h->b1 + h->b2 > 1.0 + 1e-6) ++*offTriangle;
    observed[binOf(h->b1, h->b2)] += 1;
  }
  const double total = solidAngleOf(tri, p);
  auto at = [&](int i, int j) {
    return tri.v0 + (double(i) / k) * (tri.v1 - tri.v0) + (double(j) / k) * (tri.v2 - tri.v0);
  };
  double sum = 0.0;
  for (int i = 0; i < k; ++i)
    for (int j = 0; i + j < k; ++j) {
      const double lower = triangleSolidAngle(at(i, j) - p, at(i + 1, j) - p, at(i, j + 1) - p);
      expected[(i * k + j) * 2] = lower / total * sampleCount;
      sum += lower;
      if (i + j <= k - 2) {
        const double upper = triangleSolidAngle(at(i + 1, j) - p, at(i + 1, j + 1) - p, at(i, j + 1) - p);
        expected[(i * k + j) * 2 + 1] = upper / total * sampleCount;
        sum += upper;
      }
    }
  EXPECT_NEAR(sum / total, 1.0, 1e-9) << "the sub-triangles' solid angles do not add up";
  // Pool bins expecting fewer than 5 into one, as chiSquareSphere does.
  std::vector<std::pair<double, double>> bins;
  for (int b = 0; b <= binCount; ++b) bins.push_back({expected[b], observed[b]});
  std::sort(bins.begin(), bins.end());
  double chi2 = 0.0, poolE = 0.0, poolO = 0.0;
  int dof = -1;
  for (const auto& [e, o] : bins) {
    if (poolE < 5.0) {
      poolE += e;
      poolO += o;
      continue;
    }
    chi2 += (poolO - poolE) * (poolO - poolE) / poolE;
    ++dof;
    poolE = e;
    poolO = o;
  }
  if (poolE > 0.0) {
    chi2 += (poolO - poolE) * (poolO - poolE) / poolE;
    ++dof;
  } else if (poolO > 0.0) {
    chi2 = INFINITY;
  }
  test::ChiSquareResult r;
  r.statistic = chi2;
  r.degreesOfFreedom = dof;
  r.pValue = test::chiSquareTail(chi2, dof);
  r.report = "chi2=" + std::to_string(chi2) + " dof=" + std::to_string(dof);
  return r;
}

// The configurations every test below runs through: a triangle in the plane z = 0 seen from
// several points.
struct Config {
  const char* name;
  Triangle tri;
  glm::dvec3 p;
};
const Triangle kBig{{-1.0, -1.0, 0.0}, {2.0, -0.5, 0.0}, {-0.5, 1.5, 0.0}};
std::vector<Config> configs() {
  const double s = 1e-3;  // a small triangle, 1 mm across
  return {
      {"large (2.5 sr)", kBig, {0.1, 0.2, 0.8}},
      {"near a hemisphere (6.2 sr)", kBig, {0.1, 0.2, 0.01}},
      {"small, close (q = 0.2)", {{0.0, 0.0, 0.0}, {s, 0.0, 0.0}, {0.2 * s, 0.9 * s, 0.0}}, {0.3 * s, 0.3 * s, 5 * s}},
      {"grazing (2 degrees above the plane)", kBig, {6.0, 0.3, 0.2}},
      {"grazing (0.01 degrees)", kBig, {6.0, 0.3, 1e-3}},
      {"far (1000 sizes away)", kBig, {300.0, -500.0, 2000.0}},
      {"seen from below", kBig, {0.4, -0.3, -0.5}},
  };
}
// Beyond what EmitterSet asks of the sampler (it samples by area below 1e-10 sr and within 1e-6 sr
// of a hemisphere): the sampler itself still holds there, so those limits have a margin.
std::vector<Config> extremeConfigs() {
  const double s = 1e-5;
  return {
      {"tiny (4.5e-11 sr)", {{0.0, 0.0, 0.0}, {s, 0.0, 0.0}, {0.2 * s, 0.9 * s, 0.0}}, {0.3 * s, 0.3 * s, 1.0}},
      {"grazing (1e-7 above the plane, 2e-9 sr)", kBig, {6.0, 0.3, 1e-7}},
      {"6.5e-7 sr short of a hemisphere", kBig, {0.1, 0.2, 1e-7}},
      {"1e-8 above, near a vertex", kBig, {-0.99, -0.99, 1e-8}},
  };
}

// ---- The spherical triangle --------------------------------------------------------------------

TEST(SphericalTriangle, SolidAngleAnchors) {
  const glm::dvec3 o(0.0);
  // An octant: pi / 2.
  EXPECT_NEAR(triangleSolidAngle({1, 0, 0}, {0, 1, 0}, {0, 0, 1}), kPiD / 2.0, 1e-14);
  EXPECT_NEAR(triangleSolidAngle({0, 0, 1}, {0, 1, 0}, {1, 0, 0}), kPiD / 2.0, 1e-14);  // either winding
  // Half a cube face from the cube's centre: 4 pi / 12.
  EXPECT_NEAR(triangleSolidAngle({-1, -1, 1}, {1, -1, 1}, {1, 1, 1}), kPiD / 3.0, 1e-14);
  // A face of a regular tetrahedron from its centre: pi.
  const glm::dvec3 t0(1, 1, 1), t1(1, -1, -1), t2(-1, 1, -1);
  EXPECT_NEAR(triangleSolidAngle(t0, t1, t2), kPiD, 1e-13);
  // A tiny triangle facing the point: area / d^2 to second order.
  const double a = 1e-5, d = 3.0;
  const double omega = triangleSolidAngle({0, 0, d}, {a, 0, d}, {0, a, d});
  EXPECT_NEAR(omega / (0.5 * a * a / (d * d)), 1.0, 1e-9);
  // In the triangle's plane: nothing.
  EXPECT_EQ(triangleSolidAngle({1, 0, 0}, {2, 0, 0}, {1, 1, 0}), 0.0);
  EXPECT_EQ(triangleSolidAngle(o, {1, 0, 0}, {0, 1, 0}), 0.0);
}

TEST(SphericalTriangle, PdfIntegratesToOne) {
  // The density 1 / solid angle integrated over the directions that hit the triangle: by
  // quadrature over its area for every configuration, and over the whole sphere of directions for
  // those large enough for the grid.
  for (const Config& c : configs()) {
    const double omega = solidAngleOf(c.tri, c.p);
    ASSERT_GT(omega, 0.0) << c.name;
    EXPECT_NEAR(solidAngleByQuadrature(c.tri, c.p, 2000) / omega, 1.0, 1e-4) << c.name << ", omega " << omega;
    if (omega > 1.0) {
      auto pdf = [&](const glm::vec3& w) { return hitsTriangle(c.tri, c.p, glm::dvec3(w)) ? 1.0 / omega : 0.0; };
      EXPECT_NEAR(test::integrateSphere(pdf, 1024, 2048), 1.0, 3e-3) << c.name;
    }
  }
}

TEST(SphericalTriangle, SamplesAreUniformOnTheTriangle) {
  std::vector<Config> all = configs();
  for (const Config& c : extremeConfigs()) all.push_back(c);
  for (const Config& c : all) {
    const SphericalTriangle st(c.tri.v0 - c.p, c.tri.v1 - c.p, c.tri.v2 - c.p);
    ASSERT_TRUE(st.valid()) << c.name;
    ASSERT_NEAR(st.solidAngle(), solidAngleOf(c.tri, c.p), 1e-15 * st.solidAngle()) << c.name;
    Uniforms u(17);
    int off = 0;
    const auto r = chiSquareOnTriangle(c.tri, c.p, [&] { return st.sample(glm::dvec2(u.next2())); }, 200000, 12, &off);
    EXPECT_GT(r.pValue, kSignificance) << c.name << ": " << r.report;
    EXPECT_EQ(off, 0) << c.name << ": samples off the triangle";
  }
}

TEST(SphericalTriangle, LargeTriangleMatchesPdfOnSphereBins) {
  // The same check with the suite's sphere histogram, for the two configurations large enough
  // for its bins.
  // Near a hemisphere the sub-triangle bins of the test above cannot follow the samples, which
  // crowd about the foot of the point; sphere bins can.
  for (const Config& c : {configs()[0], configs()[1], configs()[6], extremeConfigs()[2], extremeConfigs()[3]}) {
    const SphericalTriangle st(c.tri.v0 - c.p, c.tri.v1 - c.p, c.tri.v2 - c.p);
    Uniforms u(23);
    const auto r = test::chiSquareSphere([&] { return glm::vec3(st.sample(glm::dvec2(u.next2()))); },
                                         [&](const glm::vec3& w) {
                                           return hitsTriangle(c.tri, c.p, glm::dvec3(w)) ? 1.0 / st.solidAngle() : 0.0;
                                         },
                                         300000, 64, 128, 16);
    EXPECT_GT(r.pValue, kSignificance) << c.name << ": " << r.report;
  }
}

TEST(SphericalTriangle, EdgesOfTheSquareMapToEdgesOfTheTriangle) {
  // u = (0, *) is vertex A's corner sub-triangle of no area: the arc from B to A; u = (1, 1) is C.
  const Config c = configs()[0];
  const SphericalTriangle st(c.tri.v0 - c.p, c.tri.v1 - c.p, c.tri.v2 - c.p);
  const glm::dvec3 A = glm::normalize(c.tri.v0 - c.p), B = glm::normalize(c.tri.v1 - c.p),
                   C = glm::normalize(c.tri.v2 - c.p);
  EXPECT_LT(glm::length(st.sample({0.0, 1.0}) - A), 1e-12);
  EXPECT_LT(glm::length(st.sample({0.7, 0.0}) - B), 1e-12);
  EXPECT_LT(glm::length(st.sample({1.0, 1.0}) - C), 1e-9);
}

TEST(SphericalTriangle, BarycentricsOfTheSampledDirection) {
  const Config c = configs()[0];
  const glm::dvec3 x = 0.2 * c.tri.v0 + 0.5 * c.tri.v1 + 0.3 * c.tri.v2;
  const glm::dvec2 b = rayTriangleBarycentrics(c.p, glm::normalize(x - c.p), c.tri.v0, c.tri.v1, c.tri.v2);
  EXPECT_NEAR(b.x, 0.5, 1e-12);
  EXPECT_NEAR(b.y, 0.3, 1e-12);
  // Outside the triangle: clamped onto it.
  const glm::dvec3 outside = c.tri.v1 + 0.3 * (c.tri.v1 - c.tri.v0);
  const glm::dvec2 o = rayTriangleBarycentrics(c.p, glm::normalize(outside - c.p), c.tri.v0, c.tri.v1, c.tri.v2);
  EXPECT_GE(o.x, 0.0);
  EXPECT_GE(o.y, 0.0);
  EXPECT_LE(o.x + o.y, 1.0);
}

// ---- The alias table ---------------------------------------------------------------------------

// Exact selection frequencies: u on a grid fine enough that every bin boundary is resolved to 1e-6.
std::vector<double> exactFrequencies(const AliasTable& t, int steps) {
  std::vector<double> f(t.size(), 0.0);
  for (int i = 0; i < steps; ++i) f[t.sample((float(i) + 0.5f) / float(steps))] += 1.0 / steps;
  return f;
}

TEST(AliasTable, FrequenciesMatchWeights) {
  const std::vector<std::vector<float>> cases = {
      {1.0f, 2.0f, 3.0f, 4.0f},
      {0.0f, 3.0f, 0.0f, 1.0f, 5.0f, 0.5f, 0.0f},  // zero weights, never returned
      {7.0f},                                       // one weight
      {0.0f, 0.0f, 4.0f, 0.0f},                     // one non-zero weight among zeros
      {1e-6f, 1.0f, 1e6f, -2.0f, NAN, INFINITY},    // 12 decades; invalid weights count as 0
  };
  for (const auto& w : cases) {
    const AliasTable table(w);
    ASSERT_FALSE(table.empty());
    double total = 0.0;
    for (float x : w) total += std::isfinite(x) && x > 0.0f ? double(x) : 0.0;
    const std::vector<double> f = exactFrequencies(table, 1 << 22);
    Uniforms u(5);
    std::vector<double> counts(w.size(), 0.0);
    const int n = 200000;
    for (int s = 0; s < n; ++s) {
      float pmf = -1.0f;
      const size_t i = table.sample(u.next(), &pmf);
      ASSERT_LT(i, w.size());
      ASSERT_GT(w[i], 0.0f) << "a zero weight was returned";
      ASSERT_EQ(pmf, table.pmf(i));
      counts[i] += 1;
    }
    double chi2 = 0.0;
    int dof = -1;
    for (size_t i = 0; i < w.size(); ++i) {
      const double p = std::isfinite(w[i]) && w[i] > 0.0f ? double(w[i]) / total : 0.0;
      EXPECT_NEAR(table.pmf(i), p, 1e-7 * std::max(p, 1e-30) + 1e-12) << "entry " << i;
      EXPECT_NEAR(f[i], p, 2e-6) << "entry " << i << ": exact frequency";
      if (p * n >= 5.0) {
        chi2 += (counts[i] - p * n) * (counts[i] - p * n) / (p * n);
        ++dof;
      }
    }
    if (dof > 0) EXPECT_GT(test::chiSquareTail(chi2, dof), kSignificance) << "chi2 " << chi2;
  }
}

TEST(AliasTable, ManyWeightsAndTheRemappedUniform) {
  // 1000 entries with a heavy tail and a few zeros; the remapped u, given the entry, is uniform.
  std::vector<float> w(1000);
  std::mt19937 engine(3);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (size_t i = 0; i < w.size(); ++i) w[i] = i % 97 == 0 ? 0.0f : std::pow(unit(engine), 4.0f) * 100.0f;
  const AliasTable table(w);
  double total = 0.0;
  for (float x : w) total += x;
  const std::vector<double> f = exactFrequencies(table, 1 << 24);
  for (size_t i = 0; i < w.size(); ++i) EXPECT_NEAR(f[i], double(w[i]) / total, 2e-6) << "entry " << i;

  Uniforms u(8);
  const int bins = 20, n = 400000;
  std::vector<double> remapped(bins, 0.0);
  for (int s = 0; s < n; ++s) {
    float r = -1.0f;
    table.sample(u.next(), nullptr, &r);
    ASSERT_GE(r, 0.0f);
    ASSERT_LT(r, 1.0f);
    remapped[size_t(std::min(bins - 1, int(r * bins)))] += 1;
  }
  double chi2 = 0.0;
  for (double c : remapped) chi2 += (c - double(n) / bins) * (c - double(n) / bins) / (double(n) / bins);
  EXPECT_GT(test::chiSquareTail(chi2, bins - 1), kSignificance) << "remapped u, chi2 " << chi2;
}

TEST(AliasTable, EmptyAndAllZero) {
  EXPECT_TRUE(AliasTable().empty());
  const std::vector<float> zeros = {0.0f, 0.0f, -1.0f};
  EXPECT_TRUE(AliasTable(zeros).empty());
}

// ---- EmitterSet: next-event estimation and the MIS density -------------------------------------

// An emissive irregular quad (two triangles of different areas, so their choice pmfs differ) in
// the plane y = 1, facing down, and a small emissive triangle far to the side.
SceneData emitterScene() {
  SceneData s;
  Material wall;
  wall.metallic = 0.0f;
  s.materials.push_back(wall);
  Material light;
  light.baseColor = glm::vec3(0.0f);
  light.emission = glm::vec3(3.0f, 2.0f, 1.0f);
  s.materials.push_back(light);
  MeshData quad;
  quad.positions = {{-1.0f, 1.0f, -1.0f}, {-1.0f, 1.0f, 1.0f}, {1.0f, 1.0f, 1.2f}, {1.5f, 1.0f, -1.0f}};
  quad.indices = {0, 2, 1, 0, 3, 2};  // wound so the normal is -y
  quad.material = 1;
  s.meshes.push_back(quad);
  MeshData small;
  small.positions = {{8.0f, 0.0f, 0.0f}, {8.0f, 0.1f, 0.0f}, {8.0f, 0.0f, 0.1f}};
  small.indices = {0, 1, 2};
  small.material = 1;
  s.meshes.push_back(small);
  s.boundsMin = glm::vec3(-2.0f);
  s.boundsMax = glm::vec3(9.0f);
  return s;
}

struct EmitterHit {
  SurfaceHit hit;
  double t;
};
// The emitting triangle along the ray p + t w (nearest), by brute force over the scene's emitters.
std::optional<EmitterHit> traceEmitters(const SceneData& scene, const glm::dvec3& p, const glm::dvec3& w) {
  std::optional<EmitterHit> best;
  for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
    const MeshData& mesh = scene.meshes[m];
    if (!scene.materials[mesh.material].isEmissive()) continue;
    for (uint32_t t = 0; t < mesh.indices.size() / 3; ++t) {
      const Triangle tri{mesh.positions[mesh.indices[3 * t]], mesh.positions[mesh.indices[3 * t + 1]],
                         mesh.positions[mesh.indices[3 * t + 2]]};
      const auto h = hitPlane(tri, p, w);
      const double eps = 1e-7;
      if (!h || h->t <= 0.0 || h->b1 < -eps || h->b2 < -eps || h->b1 + h->b2 > 1.0 + eps) continue;
      if (best && best->t <= h->t) continue;
      const glm::dvec3 n = glm::normalize(glm::cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
      EmitterHit e;
      e.t = h->t;
      e.hit.position = glm::vec3(p + h->t * w);
      e.hit.frontFace = glm::dot(n, w) < 0.0;
      e.hit.geometricNormal = glm::vec3(e.hit.frontFace ? n : -n);
      e.hit.mesh = m;
      e.hit.triangle = t;
      best = e;
    }
  }
  return best;
}

using test::polygonIrradiance;

struct Receiver {
  const char* name;
  glm::vec3 p, n;
  bool expectSolidAngle;  // on the quad
};
const Receiver kReceivers[] = {
    {"near, under the quad", {0.1f, 0.95f, 0.0f}, {0, 1, 0}, true},
    {"a metre below", {0.2f, 0.0f, -0.1f}, {0, 1, 0}, true},
    {"grazing, beside the quad", {4.0f, 0.98f, 0.0f}, {-1, 0, 0}, true},
    {"far below", {5.0f, -60.0f, 3.0f}, {0, 1, 0}, false},
    // By area, and seen at a slant (the light's cosine about 0.2), so that the area density's
    // cosine matters.
    {"far to the side", {30.0f, -5.0f, 0.5f}, glm::normalize(glm::vec3(-29.9f, 6.0f, -0.45f)), false},
};

// One light sample from p, drawn by one of EmitterSet's samplers from the numbers of u.
using DrawLight = std::function<std::optional<LightSample>(const EmitterSet&, const glm::vec3& p, Uniforms& u)>;

// MIS needs pdfTriangle (asked when a BSDF ray hits an emitter) to be the density with which the
// sampler produced that direction from the same point: per sample, and as a histogram.
void expectDensityEqualsPdfTriangle(const DrawLight& draw, uint64_t seed, uint64_t histogramSeed) {
  const SceneData scene = emitterScene();
  const EmitterSet emitters(scene, glm::vec3(0.0f), glm::vec3(3.5f), 10.0f);
  for (const Receiver& r : kReceivers) {
    EXPECT_EQ(emitters.sampledBySolidAngle(r.p, 0, 0), r.expectSolidAngle) << r.name;
    EXPECT_EQ(emitters.sampledBySolidAngle(r.p, 0, 1), r.expectSolidAngle) << r.name;
    EXPECT_FALSE(emitters.sampledBySolidAngle(r.p, 1, 0)) << r.name << ": the small triangle is far from all";
    Uniforms u(seed);
    int compared = 0;
    for (int s = 0; s < 20000; ++s) {
      const auto ls = draw(emitters, r.p, u);
      if (!ls) continue;
      const auto e = traceEmitters(scene, glm::dvec3(r.p), glm::dvec3(ls->wi));
      ASSERT_TRUE(e.has_value()) << r.name << ": a light sample that misses every emitter";
      EXPECT_NEAR(e->t / ls->distance, 1.0, 1e-4) << r.name;
      const float pdf = emitters.pdfTriangle(r.p, e->hit);
      ASSERT_NEAR(pdf / ls->pdf, 1.0, 1e-5) << r.name << ": sample " << s << ", triangle " << e->hit.mesh << "/"
                                           << e->hit.triangle;
      ++compared;
    }
    EXPECT_GT(compared, 15000) << r.name;
  }
  // The histogram of the directions against pdfTriangle over the sphere, where the quad is large
  // enough for the bins (without the small triangle, too small for them).
  SceneData quadOnly = emitterScene();
  quadOnly.meshes.pop_back();
  const EmitterSet quadEmitters(quadOnly, glm::vec3(0.0f), glm::vec3(0.0f), 3.0f);
  for (const Receiver& r : {kReceivers[0], kReceivers[1]}) {
    Uniforms u(histogramSeed);
    const auto chi = test::chiSquareSphere(
        [&] {
          const auto ls = draw(quadEmitters, r.p, u);
          return ls ? ls->wi : glm::vec3(0.0f);
        },
        [&](const glm::vec3& w) {
          const auto e = traceEmitters(quadOnly, glm::dvec3(r.p), glm::dvec3(w));
          return e ? double(quadEmitters.pdfTriangle(r.p, e->hit)) : 0.0;
        },
        300000, 64, 128, 32);  // fine sub-bins: near the quad its edges run along the horizon
    EXPECT_GT(chi.pValue, kSignificance) << r.name << ": " << chi.report;
  }
}

TEST(EmitterSampling, SampleDensityEqualsPdfTriangle) {
  expectDensityEqualsPdfTriangle(
      [](const EmitterSet& e, const glm::vec3& p, Uniforms& u) {
        const float uLight = u.next();
        return e.sample(p, uLight, u.next2());
      },
      31, 37);
}

TEST(EmitterSampling, FoldedChoiceHasTheDensityOfSample) {
  // sampleStratified() chooses the emitter with u.x and reuses its rest for the point.
  expectDensityEqualsPdfTriangle(
      [](const EmitterSet& e, const glm::vec3& p, Uniforms& u) {
        const glm::vec2 uPoint = u.next2();
        return e.sampleStratified(p, uPoint, u.next());
      },
      53, 59);
}

TEST(EmitterSampling, FoldedChoiceKeepsAGridStratifiedOverEachTriangle) {
  // The quad's irradiance from the 64 x 64 cell centres of the unit square, as a quadrature: with
  // the choice folded into x each triangle gets half the grid, itself a grid, and the estimate is
  // nearly exact. A choice of its own (the spare number, random) hands each triangle a random half
  // of the points: an error of random sampling. Measured: folded 2.7e-4 and 4.6e-4 of the
  // irradiance, the choice of its own 1.3e-3 and 3.0e-3. (Nearer the quad the grid's own error is
  // as large as the random choice's; far away, by area, both are below 3e-4.)
  SceneData scene = emitterScene();
  scene.meshes.pop_back();
  const EmitterSet emitters(scene, glm::vec3(0.0f), glm::vec3(0.0f), 3.0f);
  const MeshData& quad = scene.meshes[0];
  std::vector<glm::dvec3> polygon;
  for (const glm::vec3& v : quad.positions) polygon.push_back(glm::dvec3(v));
  for (const Receiver& r : {kReceivers[1], kReceivers[2]}) {
    const double expected = 3.0 * polygonIrradiance(polygon, glm::dvec3(r.p), glm::dvec3(r.n));
    Uniforms spare(61);
    const int k = 64;
    double folded = 0.0, ownChoice = 0.0;
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j) {
        const glm::vec2 cell((float(i) + 0.5f) / float(k), (float(j) + 0.5f) / float(k));
        const float uSpare = spare.next();
        auto irradiance = [&](const std::optional<LightSample>& ls) {
          return ls ? double(ls->radiance.x) * std::max(0.0f, glm::dot(r.n, ls->wi)) / double(ls->pdf) : 0.0;
        };
        folded += irradiance(emitters.sampleStratified(r.p, cell, uSpare));
        ownChoice += irradiance(emitters.sample(r.p, uSpare, cell));
      }
    const double foldedError = std::abs(folded / (k * k) / expected - 1.0);
    const double ownChoiceError = std::abs(ownChoice / (k * k) / expected - 1.0);
    EXPECT_LT(foldedError, 1e-3) << r.name << " (a choice of its own: " << ownChoiceError << ")";
    EXPECT_GT(ownChoiceError, 2.0 * foldedError) << r.name << ": the test no longer tells the two apart";
  }
}

TEST(EmitterSampling, AnEmitterWithASmallShareLeavesTheChoiceToTheSpareNumber) {
  // An emitter with a share below kMinFoldedShare would get too few values of x for its points:
  // there the spare number chooses, exactly as sample() does. The quad alone folds; the quad with
  // a dim triangle (a millionth of its power) does not, nor does it with 257 small ones of equal
  // power.
  SceneData quadOnly = emitterScene();
  quadOnly.meshes.pop_back();
  EXPECT_TRUE(EmitterSet(quadOnly, glm::vec3(0.0f), glm::vec3(0.0f), 3.0f).foldsChoice());

  SceneData dim = quadOnly;
  Material dimLight = dim.materials[1];
  dimLight.emission *= 1e-6f;
  dim.materials.push_back(dimLight);
  MeshData dimTriangle = dim.meshes[0];
  dimTriangle.indices.resize(3);
  dimTriangle.material = uint32_t(dim.materials.size() - 1);
  dim.meshes.push_back(dimTriangle);

  SceneData many = quadOnly;
  MeshData strip;
  strip.material = 1;
  for (uint32_t t = 0; t < 257; ++t) {
    const float x = 0.01f * float(t);
    strip.positions.insert(strip.positions.end(), {{x, 2.0f, 0.0f}, {x, 2.0f, 0.01f}, {x + 0.01f, 2.0f, 0.0f}});
    strip.indices.insert(strip.indices.end(), {3 * t, 3 * t + 1, 3 * t + 2});
  }
  many.meshes.push_back(strip);

  for (const SceneData* scene : {&dim, &many}) {
    const EmitterSet emitters(*scene, glm::vec3(0.0f), glm::vec3(0.0f), 10.0f);
    EXPECT_FALSE(emitters.foldsChoice());
    Uniforms u(67);
    int same = 0;
    for (int s = 0; s < 1000; ++s) {
      const glm::vec2 uPoint = u.next2();
      const float uSpare = u.next();
      const auto a = emitters.sampleStratified(kReceivers[1].p, uPoint, uSpare);
      const auto b = emitters.sample(kReceivers[1].p, uSpare, uPoint);
      ASSERT_EQ(a.has_value(), b.has_value());
      if (!a) continue;
      EXPECT_EQ(a->wi, b->wi);
      EXPECT_EQ(a->pdf, b->pdf);
      ++same;
    }
    EXPECT_GT(same, 500);
  }
}

TEST(EmitterSampling, FoldedEmissionTakesItsSideFromTheSpareNumber) {
  // A two-sided quad's light paths leave from either side half the time, and from points spread
  // the same way over the quad on both sides: the side must not be read from the point's number.
  SceneData scene = emitterScene();
  scene.meshes.pop_back();
  scene.materials[1].doubleSided = true;
  const EmitterSet emitters(scene, glm::vec3(0.0f), glm::vec3(0.0f), 3.0f);
  ASSERT_TRUE(emitters.foldsChoice());
  Uniforms u(71);
  const int n = 200000;
  int front = 0;
  glm::dvec3 meanFront(0.0), meanBack(0.0);
  for (int s = 0; s < n; ++s) {
    const glm::vec2 uPos = u.next2(), uDir = u.next2();
    const auto e = emitters.sampleEmissionStratified(uPos, uDir, u.next());
    ASSERT_TRUE(e.has_value());
    if (e->normal.y < 0.0f) {  // the quad's front faces -y
      ++front;
      meanFront += glm::dvec3(e->position);
    } else {
      meanBack += glm::dvec3(e->position);
    }
  }
  EXPECT_NEAR(double(front) / n, 0.5, 0.005);
  meanFront /= double(front);
  meanBack /= double(n - front);
  EXPECT_LT(glm::length(meanFront - meanBack), 0.02) << "the sides' points spread differently";
}

TEST(EmitterSampling, NextEventEstimateMatchesPolygonIrradiance) {
  // The mean of Le cos / pdf over light samples is the irradiance, which Lambert's formula gives in
  // closed form, by both strategies (solid angle near and grazing, area far). A pdf off by 2 % in
  // either is 30 standard errors here.
  SceneData scene = emitterScene();
  scene.meshes.pop_back();  // the quad alone: irradiance in closed form
  const EmitterSet emitters(scene, glm::vec3(0.0f), glm::vec3(0.0f), 3.0f);
  const MeshData& quad = scene.meshes[0];
  std::vector<glm::dvec3> polygon;
  for (const glm::vec3& v : quad.positions) polygon.push_back(glm::dvec3(v));
  for (const Receiver& r : kReceivers) {
    ASSERT_EQ(emitters.sampledBySolidAngle(r.p, 0, 0), r.expectSolidAngle) << r.name;
    const double expected = 3.0 * polygonIrradiance(polygon, glm::dvec3(r.p), glm::dvec3(r.n));
    Uniforms u(41);
    const int n = 400000;
    double sum = 0.0, sum2 = 0.0;
    for (int s = 0; s < n; ++s) {
      const auto ls = emitters.sample(r.p, u.next(), u.next2());
      if (!ls) continue;
      const double x = double(ls->radiance.x) * std::max(0.0f, glm::dot(r.n, ls->wi)) / double(ls->pdf);
      sum += x;
      sum2 += x * x;
    }
    const double mean = sum / n, se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
    EXPECT_NEAR(mean, expected, 4.0 * se + 1e-9 * expected) << r.name << " (standard error " << se / expected << ")";
    EXPECT_LT(se / expected, 2e-3) << r.name << ": too noisy to see a 2 % error";
  }
}

// A globe lamp of many small triangles (a latitude-longitude sphere of radius 0.15, wound outwards,
// emitting from its outside), as lamp_rooms has: from a ceiling above it (the whole globe below the
// receiver's tangent plane, and a convex globe hides none of its facets from another), the irradiance
// is Lambert's formula summed over the facets that face the receiver. Its facets are seen at every
// angle from head-on to grazing (from here, each sampled by area).
TEST(EmitterSampling, NextEventEstimateFromAGlobeMatchesPolygonIrradiance) {
  SceneData scene;
  Material light;
  light.baseColor = glm::vec3(0.0f);
  light.emission = glm::vec3(3.0f, 2.0f, 1.0f);
  light.doubleSided = false;
  scene.materials.push_back(light);
  const glm::dvec3 centre(2.0, 2.2, -0.3);
  const MeshData globe = test::globe(centre, 0.15, 12, 24, 0);
  scene.meshes.push_back(globe);
  scene.boundsMin = glm::vec3(0.0f);
  scene.boundsMax = glm::vec3(4.0f, 2.8f, 2.0f);
  const EmitterSet emitters(scene, glm::vec3(0.0f), glm::vec3(2.0f, 1.4f, 0.0f), 3.0f);
  ASSERT_GT(emitters.triangleCount(), 400u);
  const glm::dvec3 down(0.0, -1.0, 0.0);
  for (const glm::dvec3 offset : {glm::dvec3(0.0, 0.0, 0.0), glm::dvec3(0.3, 0.0, 0.1), glm::dvec3(1.2, 0.0, -0.5)}) {
    const glm::dvec3 p = glm::dvec3(centre.x, 2.8, centre.z) + offset;
    const double expected = 3.0 * test::convexMeshIrradiance(globe, p, down);
    Uniforms u(53);
    const int samples = 4000000;
    double sum = 0.0, sum2 = 0.0;
    int compared = 0;
    for (int s = 0; s < samples; ++s) {
      const auto ls = emitters.sample(glm::vec3(p), u.next(), u.next2());
      if (!ls) continue;
      if (s % 100 == 0) {  // the density an emitter hit along the sample's direction is weighed with
        const auto e = traceEmitters(scene, p, glm::dvec3(ls->wi));
        ASSERT_TRUE(e.has_value());
        EXPECT_NEAR(emitters.pdfTriangle(glm::vec3(p), e->hit) / ls->pdf, 1.0, 2e-3) << "sample " << s;
        ++compared;
      }
      const double x = double(ls->radiance.x) * std::max(0.0, glm::dot(down, glm::dvec3(ls->wi))) / double(ls->pdf);
      sum += x;
      sum2 += x * x;
    }
    const double mean = sum / samples, se = std::sqrt(std::max(0.0, sum2 / samples - mean * mean) / samples);
    EXPECT_NEAR(mean, expected, 4.0 * se + 1e-9 * expected) << "offset (" << offset.x << ", " << offset.z << "): "
                                                             << (mean / expected - 1.0) * 100.0 << " %, standard error "
                                                             << se / expected * 100.0 << " %";
    EXPECT_LT(se / expected, 1e-3) << "too noisy to see a 0.5 % error";
    std::printf("globe, offset (%g, %g): NEE %+.3f %% from Lambert's formula (standard error %.3f %%)\n", offset.x, offset.z,
                (mean / expected - 1.0) * 100.0, se / expected * 100.0);
  }
}

TEST(EmitterSampling, SolidAngleSamplingIsUniformInSolidAngleNearTheLight) {
  // Near the quad every sampled direction carries the same Le / pdf (the point of sampling by
  // solid angle); by area it would vary with d^3.
  const SceneData scene = emitterScene();
  const EmitterSet emitters(scene, glm::vec3(0.0f), glm::vec3(3.5f), 10.0f);
  const glm::vec3 p = kReceivers[0].p;
  Uniforms u(43);
  float lo = INFINITY, hi = 0.0f;
  for (int s = 0; s < 10000; ++s) {
    const auto ls = emitters.sample(p, u.next(), u.next2());
    if (!ls) continue;
    const auto e = traceEmitters(scene, glm::dvec3(p), glm::dvec3(ls->wi));
    if (!e || e->hit.mesh != 0 || e->hit.triangle != 0) continue;
    lo = std::min(lo, ls->pdf);
    hi = std::max(hi, ls->pdf);
  }
  EXPECT_NEAR(hi / lo, 1.0f, 1e-5f);
}

TEST(EmitterSampling, BackOfAOneSidedEmitterSendsNothing) {
  const SceneData scene = emitterScene();
  const EmitterSet emitters(scene, glm::vec3(0.0f), glm::vec3(3.5f), 10.0f);
  const glm::vec3 above(0.1f, 1.3f, 0.0f);  // behind the quad, which emits downwards
  Uniforms u(47);
  for (int s = 0; s < 2000; ++s) {
    const auto ls = emitters.sample(above, u.next(), u.next2());
    if (!ls) continue;
    const auto e = traceEmitters(scene, glm::dvec3(above), glm::dvec3(ls->wi));
    ASSERT_TRUE(e.has_value());
    EXPECT_EQ(e->hit.mesh, 1u) << "a sample of the quad's back";
  }
  SurfaceHit back;
  back.position = glm::vec3(0.1f, 1.0f, 0.0f);
  back.mesh = 0;
  back.triangle = 0;
  back.frontFace = false;
  EXPECT_EQ(emitters.pdfTriangle(above, back), 0.0f);
}

TEST(EmitterSampling, APointInTheLightsPlaneGetsNothingFromIt) {
  // A path vertex on the back of a one-sided light (its reflective side) has a hit point that
  // rounds to either side of the light's plane. Had it rounded 1e-7 below, sampling by solid angle
  // would light it by the whole hemisphere: 20x fireflies over the Cornell box's light. Within
  // 1e-4 of the coordinate scale of the plane a point counts as in it, for sample() and pdfTriangle
  // alike; 1e-3 below, the point is lit (by almost pi Le: the quad is nearly a hemisphere there).
  SceneData scene = emitterScene();
  scene.meshes.pop_back();
  const EmitterSet emitters(scene, glm::vec3(0.0f), glm::vec3(0.0f), 3.0f);
  SurfaceHit hit;
  hit.position = glm::vec3(0.1f, 1.0f, 0.0f);
  hit.mesh = 0;
  hit.triangle = 0;
  hit.frontFace = true;
  for (float below : {1e-7f, 1e-5f, 1e-3f}) {
    const glm::vec3 p(0.1f, 1.0f - below, 0.0f);
    Uniforms u(53);
    int lit = 0;
    double sum = 0.0, sum2 = 0.0;
    const int n = 100000;
    for (int s = 0; s < n; ++s) {
      const auto ls = emitters.sample(p, u.next(), u.next2());
      if (!ls) continue;
      ++lit;
      const double x = double(ls->radiance.x) * std::max(0.0f, ls->wi.y) / double(ls->pdf);
      sum += x;
      sum2 += x * x;
    }
    if (below < 1e-4f) {
      EXPECT_EQ(lit, 0) << below << " below the light";
      EXPECT_EQ(emitters.pdfTriangle(p, hit), 0.0f) << below << " below the light";
    } else {
      EXPECT_EQ(lit, n) << below << " below the light";
      EXPECT_GT(emitters.pdfTriangle(p, hit), 0.0f);
      const double expected = 3.0 * polygonIrradiance({{-1, 1, -1}, {-1, 1, 1}, {1, 1, 1.2}, {1.5, 1, -1}}, glm::dvec3(p),
                                                      glm::dvec3(0, 1, 0));
      const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
      EXPECT_NEAR(mean, expected, 4.0 * se);
      EXPECT_LT(se / expected, 0.005);
      EXPECT_GT(expected, 0.99 * 3.0 * kPiD);
    }
  }
}

}  // namespace
}  // namespace vpl
