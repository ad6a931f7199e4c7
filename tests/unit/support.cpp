#include "tests/unit/support.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <sstream>
#include <vector>
#include "render/sampling/equal_area_map.h"

namespace vpl::test {
namespace {

constexpr double kPi = std::numbers::pi;

glm::vec3 directionFrom(double cosTheta, double phi) {
  const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
  return glm::vec3(float(sinTheta * std::cos(phi)), float(sinTheta * std::sin(phi)), float(cosTheta));
}

// Regularised lower incomplete gamma P(a, x) by its series (x < a + 1) or continued fraction.
double regularizedGammaP(double a, double x) {
  if (x <= 0.0) return 0.0;
  const double logPrefix = -x + a * std::log(x) - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 10000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-15) break;
    }
    return sum * std::exp(logPrefix);
  }
  // Lentz's continued fraction for Q(a, x).
  double b = x + 1.0 - a, c = 1e300, d = 1.0 / b, h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::abs(c) < 1e-300) c = 1e-300;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-15) break;
  }
  return 1.0 - std::exp(logPrefix) * h;
}

}  // namespace

namespace {
ChiSquareResult compareCounts(const std::vector<double>& observed, const std::vector<double>& expected, int sampleCount,
                              const std::function<std::string(int)>& binName) {
  const int binCount = int(observed.size()) - 1;
// Pool the low-expectation bins (in increasing order of expectation) as Nori and pbrt do.
  std::vector<int> order(binCount + 1);
  for (int k = 0; k <= binCount; ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return expected[a] < expected[b]; });

  ChiSquareResult r;
  double pooledObs = 0.0, pooledExp = 0.0;
  int used = 0;
  struct Worst { double contribution; int bin; double obs, exp; };
  std::vector<Worst> worst;
  for (int k : order) {
    if (expected[k] == 0.0 && observed[k] > 0.001 * sampleCount + 10.0) {
      // Many samples where the pdf says none can be (a few are quadrature misses at support edges).
      r.statistic = std::numeric_limits<double>::infinity();
      worst.push_back({r.statistic, k, observed[k], 0.0});
      continue;
    }
    if (expected[k] < 5.0) {
      pooledObs += observed[k];
      pooledExp += expected[k];
      if (pooledExp < 5.0) continue;
      const double diff = pooledObs - pooledExp;
      r.statistic += diff * diff / pooledExp;
      pooledObs = pooledExp = 0.0;
      ++used;
      continue;
    }
    const double diff = observed[k] - expected[k];
    const double c = diff * diff / expected[k];
    r.statistic += c;
    worst.push_back({c, k, observed[k], expected[k]});
    ++used;
  }
  if (pooledExp > 0.0) {
    const double diff = pooledObs - pooledExp;
    r.statistic += diff * diff / pooledExp;
    ++used;
  }
  r.degreesOfFreedom = std::max(1, used - 1);
  r.pValue = std::isfinite(r.statistic) ? chiSquareTail(r.statistic, r.degreesOfFreedom) : 0.0;

  std::sort(worst.begin(), worst.end(), [](const Worst& a, const Worst& b) { return a.contribution > b.contribution; });
  std::ostringstream os;
  os << "chi2=" << r.statistic << " dof=" << r.degreesOfFreedom << " p=" << r.pValue << "; worst bins:";
  for (size_t k = 0; k < std::min<size_t>(5, worst.size()); ++k) {
    const int b = worst[k].bin;
    os << " [" << binName(b) << " obs " << worst[k].obs << " exp " << worst[k].exp << "]";
  }
  r.report = os.str();
  return r;
}
}  // namespace


double chiSquareTail(double statistic, int dof) {
  if (dof <= 0) return 1.0;
  return std::clamp(1.0 - regularizedGammaP(0.5 * dof, 0.5 * statistic), 0.0, 1.0);
}

double integrateSphere(const std::function<double(const glm::vec3&)>& f, int cosThetaSteps, int phiSteps) {
  const double dz = 2.0 / cosThetaSteps, dphi = 2.0 * kPi / phiSteps;
  double sum = 0.0;
  for (int i = 0; i < cosThetaSteps; ++i) {
    const double z = -1.0 + (i + 0.5) * dz;
    for (int j = 0; j < phiSteps; ++j) sum += f(directionFrom(z, (j + 0.5) * dphi));
  }
  return sum * dz * dphi;
}

ChiSquareResult chiSquareSphere(const std::function<glm::vec3()>& sample,
                                const std::function<double(const glm::vec3&)>& pdf, int sampleCount,
                                int cosThetaBins, int phiBins, int subdivisions, bool renormalise) {
  const int binCount = cosThetaBins * phiBins;
  std::vector<double> observed(binCount + 1, 0.0), expected(binCount + 1, 0.0);  // last = "no sample"

  for (int s = 0; s < sampleCount; ++s) {
    const glm::vec3 d = sample();
    const float len2 = glm::dot(d, d);
    if (!(len2 > 0.5f)) {
      observed[binCount] += 1.0;
      continue;
    }
    const glm::vec3 w = d / std::sqrt(len2);
    double phi = std::atan2(double(w.y), double(w.x));
    if (phi < 0.0) phi += 2.0 * kPi;
    const int i = std::clamp(int((double(w.z) + 1.0) * 0.5 * cosThetaBins), 0, cosThetaBins - 1);
    const int j = std::clamp(int(phi / (2.0 * kPi) * phiBins), 0, phiBins - 1);
    observed[i * phiBins + j] += 1.0;
  }

  // Expected counts: integrate the pdf over each bin on a sub-grid.
  const double dz = 2.0 / cosThetaBins, dphi = 2.0 * kPi / phiBins;
  const double sdz = dz / subdivisions, sdphi = dphi / subdivisions;
  double total = 0.0;
  for (int i = 0; i < cosThetaBins; ++i)
    for (int j = 0; j < phiBins; ++j) {
      double integral = 0.0;
      for (int a = 0; a < subdivisions; ++a)
        for (int b = 0; b < subdivisions; ++b)
          integral += pdf(directionFrom(-1.0 + i * dz + (a + 0.5) * sdz, j * dphi + (b + 0.5) * sdphi));
      integral *= sdz * sdphi;
      expected[i * phiBins + j] = integral * sampleCount;
      total += integral;
    }
  if (renormalise && total > 0.0) {
    for (int k = 0; k < binCount; ++k) expected[k] /= total;
    total = 1.0;
  }
  expected[binCount] = std::max(0.0, 1.0 - total) * sampleCount;

  return compareCounts(observed, expected, sampleCount, [phiBins, binCount](int b) {
    return b == binCount ? std::string("none") : std::to_string(b / phiBins) + "," + std::to_string(b % phiBins);
  });
}

ChiSquareResult chiSquareEqualArea(const std::function<glm::vec3()>& sample,
                                   const std::function<double(const glm::vec3&)>& pdf, int sampleCount, int resolution,
                                   int subdivisions) {
  const int binCount = resolution * resolution;
  std::vector<double> observed(binCount + 1, 0.0), expected(binCount + 1, 0.0);  // last = "no sample"
  for (int s = 0; s < sampleCount; ++s) {
    const glm::vec3 d = sample();
    const float len2 = glm::dot(d, d);
    if (!(len2 > 0.5f)) observed[binCount] += 1.0;
    else observed[equalAreaCell(d / std::sqrt(len2), resolution)] += 1.0;
  }
  // Each cell holds 4 pi / N steradians, so its integral is the mean of the pdf over a sub-grid.
  double total = 0.0;
  for (int c = 0; c < binCount; ++c) {
    double sum = 0.0;
    for (int a = 0; a < subdivisions; ++a)
      for (int b = 0; b < subdivisions; ++b)
        sum += pdf(equalAreaSquareToSphere({float((c % resolution + (a + 0.5) / subdivisions) / resolution),
                                            float((c / resolution + (b + 0.5) / subdivisions) / resolution)}));
    const double integral = sum / (subdivisions * subdivisions) * 4.0 * kPi / binCount;
    expected[c] = integral * sampleCount;
    total += integral;
  }
  expected[binCount] = std::max(0.0, 1.0 - total) * sampleCount;
  return compareCounts(observed, expected, sampleCount, [resolution, binCount](int b) {
    return b == binCount ? std::string("none") : std::to_string(b % resolution) + "," + std::to_string(b / resolution);
  });
}

void setPreviewBudgetsToOne(RenderJobSettings& s) {
  s.preview.clustering.globalClusters = 1;
  s.preview.clustering.clusterBudget = 1;
  s.preview.clustering.reducedRows = 1;
  s.preview.clustering.refinementRows = 1;
  s.preview.slices.maxSliceSize = 1;
  s.preview.clustersPerPass = 1;
}

std::string sourceDir() { return VPLVIEW_SOURCE_DIR; }
std::string sharedDir() { return VPLVIEW_SHARED_DIR; }
std::string builtInScene(const std::string& file) {
  const bool generated = std::filesystem::path(file).extension() == ".glb";
  return (std::filesystem::path(generated ? VPLVIEW_BINARY_DIR : VPLVIEW_SOURCE_DIR) / "scenes" / file).string();
}

std::string sharedScene(const std::string& relativePath) {
  const std::filesystem::path p = std::filesystem::path(sharedDir()) / "scenes" / relativePath;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

}  // namespace vpl::test
