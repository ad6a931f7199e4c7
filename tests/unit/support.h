// Shared helpers of the unit tests: chi-square goodness of fit of direction samplers, paths to
// scenes, and a skip when ../shared is absent.
#pragma once
#include <functional>
#include <string>
#include <glm/glm.hpp>
#include <gtest/gtest.h>
#include "render/session/render_job.h"

namespace vpl::test {

struct ChiSquareResult {
  double statistic = 0.0;
  int degreesOfFreedom = 0;
  double pValue = 1.0;
  std::string report;  // a short table of the worst bins, for failure messages
};

// Bins n samples of a unit-direction sampler on an equal-area (cos theta, phi) grid of the whole
// sphere and compares them with the integral of pdf over each bin (Simpson-like sub-grid
// quadrature). Bins expecting fewer than 5 samples are pooled. A sampler that returns
// std::nullopt-like failures should return a zero vector; those count as "no sample" and are
// compared with 1 - integral(pdf).
ChiSquareResult chiSquareSphere(const std::function<glm::vec3()>& sample,
                                const std::function<double(const glm::vec3&)>& pdf, int sampleCount,
                                int cosThetaBins = 32, int phiBins = 64, int subdivisions = 8,
                                bool renormalise = false);
// renormalise: the sampler never fails and its pdf's integral is tested elsewhere, so scale the
// expected counts to sum to the sample count (removes quadrature error of very peaked pdfs).

// The same test with the cells of the equal-area square map (render/sampling/equal_area_map.h) as
// bins, resolution x resolution of them: exact for pdfs that are constant over cells of that grid
// (the guide's), where the (cos theta, phi) bins would cut through their steps.
ChiSquareResult chiSquareEqualArea(const std::function<glm::vec3()>& sample,
                                   const std::function<double(const glm::vec3&)>& pdf, int sampleCount, int resolution,
                                   int subdivisions = 4);

// Integral of f over the unit sphere by a fine (cos theta, phi) midpoint grid.
double integrateSphere(const std::function<double(const glm::vec3&)>& f, int cosThetaSteps = 512,
                       int phiSteps = 1024);

// Upper tail of the chi-square distribution: P(X >= statistic) with dof degrees of freedom.
double chiSquareTail(double statistic, int dof);

// Every clustering, slice and per-pass budget of the preview at its minimum, 1 (DESIGN.md §5).
void setPreviewBudgetsToOne(RenderJobSettings& settings);

std::string sourceDir();
std::string sharedDir();
// Path of a built-in scene by its file name: scenes/NAME.gltf in the source tree, NAME.glb where the
// build generates it (the interior and the skylit hall, target interior_scene).
std::string builtInScene(const std::string& file);
// Path of a scene in ../shared/scenes, or "" (and GTEST_SKIP from the caller) when absent.
std::string sharedScene(const std::string& relativePath);

}  // namespace vpl::test

// Skips the current test with a clear message when ../shared/scenes is not beside the repo.
#define VPL_REQUIRE_SHARED_SCENE(var, rel)                                                   \
  const std::string var = ::vpl::test::sharedScene(rel);                                     \
  if (var.empty()) GTEST_SKIP() << "../shared/scenes/" << (rel) << " is absent: test skipped"
