// The directional distribution of one cache point (Hua & Low 2015): representatives are the
// directions to its VPL clusters with weights (their estimated contribution, W/sr-like luminance).
// Each representative spreads its weight evenly over the cells of an equal-area map of the sphere
// (render/sampling/equal_area_map.h) whose centres lie within a cone around it (half-angle thetaC, or
// wider for a representative that asks for it, such as a large cluster close to the cache point),
// or over its own cell when the cone holds no centre. The target f(w) is the tabulated density of
// w's cell: the mean incoming radiance predicted around w, as the authors' lookup radius on an
// equal-area square. Its sphere integral is exactly Z = sum of weights, and
//   pdf(w) = (1 - eps) f(w) / Z + eps / (4 pi)        (uniform when Z = 0)
// costs one table read; sampling picks a cell by its mass, then a uniform point in it.
// Bilinear (the default): f is instead interpolated over the square from values at the cells'
// corners (each the mean of the cells around it), so it no longer jumps at every cell edge; a
// cell's mass is the mean of its corners, and a sample picks a cell by it, then warps the point in
// the cell to the bilinear density (two linear inversions). f cos / pdf then varies smoothly, which
// stratified numbers integrate better: per sample at 64 spp, relMSE 0.92x for `mixture` on the
// Cornell box and 0.95x for `mis` on cornell_glossy.
#pragma once
#include <cstdint>
#include <optional>
#include <span>
#include <vector>
#include <glm/glm.hpp>
#include "render/sampling/distribution_1d.h"
#include "render/sampling/rng.h"

namespace vpl {

struct GuideRepresentative {
  glm::vec3 direction{0, 0, 1};  // unit, world space, from the cache point towards the cluster
  float weight = 0.0f;           // >= 0
  float coneAngle = 0.0f;        // half-angle of its cone (radians); at most the distribution's own is used
};

class GuideDistribution {
 public:
  // Cells per side of the equal-area map: 1024 cells of 0.0123 sr (about 6 degrees across), fine
  // against the default 20-degree cone and 12 KiB per cache point (16 KiB with the corners).
  static constexpr int kResolution = 32;
  static constexpr int kCells = kResolution * kResolution;
  static constexpr double kCellSolidAngle = 4.0 * 3.14159265358979323846 / kCells;

  GuideDistribution() = default;
  GuideDistribution(const std::vector<GuideRepresentative>& representatives, float coneAngle, float defensive,
                    bool bilinear = true);
  // A table given cell by cell (kCells weights >= 0), as the learner blends it; Z is their sum.
  GuideDistribution(std::span<const float> cellWeights, float defensive, bool bilinear = true);

  // f(w): weight per steradian around w (of w's cell, or interpolated).
  float target(const glm::vec3& w) const {
    return float((corners_.empty() ? choice_.pmf(size_t(cellOf(w))) : interpolatedShare(w)) * total_ / kCellSolidAngle);
  }
  // Density of sample() per solid angle (includes the defensive term).
  float pdf(const glm::vec3& w) const;
  // uCell picks the defensive share or a cell, uPoint the point in the cell.
  glm::vec3 sample(float uCell, glm::vec2 uPoint) const;
  // The same density from one 2D number: u.x picks the defensive share or a cell and, rescaled within
  // the cell's share, places the point in it with u.y. A stratified u gives stratified directions,
  // so a guide that shares the BSDF's number (mis) keeps that number's stratification.
  glm::vec3 sample(glm::vec2 u) const;
  glm::vec3 sample(Rng& rng) const {
    const float u = rng.uniform();
    return sample(u, rng.uniform2());
  }

  double totalWeight() const { return total_; }
  // The table's share of cell c (0 everywhere for a uniform guide, Z = 0).
  float cellShare(int c) const { return choice_.pmf(size_t(c)); }
  bool uniform() const { return choice_.empty(); }
  size_t size() const { return representativeCount_; }
  float defensive() const { return defensive_; }

  static int cellOf(const glm::vec3& w);
  // A point of the cell from [0,1)^2, strictly inside it, so that cellOf() gives the cell back.
  static glm::vec3 pointInCell(int cell, glm::vec2 u);
  static glm::vec3 cellCentre(int cell);
  // Cells whose centres lie within the cone of cosine cosCone around the unit vector d: the cone
  // query (nanoflann kd-tree over the cell centres), and a brute-force scan for tests.
  static void coneCells(const glm::vec3& d, float cosCone, std::vector<uint32_t>& cells);
  static void coneCellsLinear(const glm::vec3& d, float cosCone, std::vector<uint32_t>& cells);

  size_t memoryBytes() const;

 private:
  // Bilinear: makes the corner values from the cells' weights, and replaces each weight by the
  // mean of its corners (the cell's integral of the interpolated density).
  void interpolateFromCorners(std::vector<float>& cellWeights);
  // Then: the table's share per cell, interpolated at w ...
  float interpolatedShare(const glm::vec3& w) const;
  // ... and a point in [0,1)^2 of the cell, distributed by it, from a uniform u.
  glm::vec2 warpInCell(int cell, glm::vec2 u) const;
  // sample(u)'s inversion within a row, continuous across rows too: the height in the row follows
  // the density integrated across it, then the cell and the point follow the density along that
  // height. A point of the square, or nothing where rounding left the height without density.
  std::optional<glm::vec2> sampleAlongRow(int row, float uInRow, float ux) const;
  // Makes the table from the cells' weights: choice_ (and, bilinear, the corners in its units).
  void setTable(std::vector<float>& mass, bool bilinear);
  // The corners of cell (x, y): [0] and [1] at its lower edge, [kResolution + 1] and the next at its upper.
  const float* cornersBelow(int x, int y) const { return &corners_[size_t(y * (kResolution + 1) + x)]; }

  Distribution1D choice_;  // cells by their share of the weight (empty when Z = 0)
  std::vector<float> corners_;  // bilinear: (kResolution + 1)^2 values, in units of a cell's share; else empty
  double total_ = 0.0;
  float cellDensity_ = 0.0f;  // (1 - eps) / cell solid angle: pdf = cellDensity_ pmf(cell) + eps / (4 pi)
  float defensive_ = 0.01f;
  size_t representativeCount_ = 0;
};

}  // namespace vpl
