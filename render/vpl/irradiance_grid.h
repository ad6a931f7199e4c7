// The VPLs read as photons: the irradiance arriving anywhere on the scene's surfaces, estimated as
// the VPLs' incident flux per unit of surface area in a cell of a sparse grid. It costs no ray, and
// a lookup is a hash probe or two, so a path tracer can ask at every vertex how much light a
// continuation from there is worth (render/integrator/weight_window.h).
//
// Cells are cubes, kept per facing side: a surface point's bucket is the signed dominant axis of
// its normal (towards the side it is seen from), so the two sides of a wall never share light.
// Every level doubles the cell size; a lookup takes the finest level whose cell holds at least
// kMinVpls VPLs, so sparse light is averaged over a wider area rather than read as darkness.
//
// Parameters:
//   finestCells  int  128  cells across the scene's bounding diagonal at the finest level
//   levels       int  5    levels, each with cells twice as large as the one before
//   photons      int  262144  light path vertices splatted (the VPL tracer's, in batches that are
//                             dropped once splatted: far more than the VPLs a preview can afford)
#pragma once
#include <cstdint>
#include <vector>
#include <glm/glm.hpp>
#include "render/scene/render_scene.h"
#include "render/vpl/vpl.h"

namespace vpl {

class IrradianceGrid {
 public:
  static constexpr int kFinestCells = 128;
  static constexpr int kLevels = 5;
  static constexpr uint32_t kMinVpls = 16;

  IrradianceGrid() = default;
  static constexpr int kPhotons = 1 << 18;

  // Surface area from points on every triangle (a regular subdivision), incident flux from
  // `photons` light path vertices (every surface vertex, direct light included) of the light paths
  // that complete a path tracer's paths of `pathDepth` segments (vplSettingsForPaths).
  IrradianceGrid(const RenderScene& scene, int photons, uint64_t seed, int pathDepth);

  bool empty() const { return totalFlux_ <= 0.0f; }
  // Irradiance (W/m^2 per channel) at p on a surface facing n (unit, towards the viewer's side).
  // Zero where no level's cell holds a VPL.
  glm::vec3 irradiance(const glm::vec3& p, const glm::vec3& n) const;
  size_t cellCount() const { return cellCount_; }
  size_t memoryBytes() const;

 private:
  struct Cell {
    uint32_t key = 0;
    glm::vec3 flux{0.0f};
    float area = 0.0f;
    uint32_t vpls = 0;
  };
  uint32_t keyOf(const glm::vec3& p, const glm::vec3& n, int level) const;
  int32_t find(uint32_t key) const;
  Cell& insert(uint32_t key);
  void splat(const std::vector<Vpl>& vpls, float weight);

  glm::vec3 origin_{0.0f};
  float finestSize_ = 1.0f;
  // Open addressing (linear probing) from key to cell; key 0 is the empty slot.
  std::vector<uint32_t> keys_;
  std::vector<int32_t> slots_;
  std::vector<Cell> cells_;
  // What a lookup reads, made once the cells are resolved: the key and the irradiance of the finest
  // level with enough VPLs side by side in one open-addressed table, so a probe touches one cache
  // line (key, slot and cell in three arrays of 64-bit keys missed the cache three times: 16 % of a
  // door_ajar render's time).
  struct Resolved {  // 16 bytes, four to a cache line
    uint32_t key = 0;
    glm::vec3 irradiance{0.0f};
  };
  std::vector<Resolved> resolved_;
  float totalFlux_ = 0.0f;
  size_t cellCount_ = 0;
};

}  // namespace vpl
