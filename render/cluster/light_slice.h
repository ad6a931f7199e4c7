// Per-slice VPL clustering after LightSlice (Ou & Pellacini, SIGGRAPH Asia 2011): a global
// clustering of the VPLs from a reduced light matrix (rows = sampled slice representatives, with
// visibility), then, for every slice, a refinement that splits the clusters with the largest error
// estimated on the reduced rows nearest that slice, up to a budget.
//
// Parameters (LightSliceSettings):
//   globalClusters  int     100   clusters of the global clustering
//   clusterBudget   int     200   clusters per slice after refinement
//   reducedRows     int     64    slice representatives sampled as rows of the reduced matrix
//   refinementRows  int     8     reduced rows nearest a slice used to estimate its cluster errors
//   seed            uint64  1
#pragma once
#include <atomic>
#include <cstdint>
#include <span>
#include <string>
#include <vector>
#include <glm/glm.hpp>
#include "render/cluster/slice_tree.h"
#include "render/vpl/vpl.h"

namespace vpl {

struct LightSliceSettings {
  int globalClusters = 100;
  int clusterBudget = 200;
  int reducedRows = 64;
  int refinementRows = 8;
  uint64_t seed = 1;
  bool keepMembers = false;  // keep each slice's member lists (tests; costs slices x VPLs indices)
  std::string validate() const;
};

// What the clustering needs to know of light transport.
class LightTransport {
 public:
  virtual ~LightTransport() = default;
  // Luminance that VPL `vpl` sends towards slice `slice`'s representative (non-negative, finite);
  // with visibility when `visible` is true, else unoccluded.
  virtual float contribution(uint32_t slice, uint32_t vpl, bool visible) const = 0;
  // Every VPL's contribution at slice `slice` without visibility, into out[0, vpl count): the row
  // that the slice's refinement compares columns on. Only the row's shape matters there, so a
  // transport may approximate it (for instance without the BSDFs' glossy lobes) when exact rows cost
  // more than the clustering gains; by default, exact.
  virtual void unoccludedRow(uint32_t slice, std::span<float> out) const {
    for (uint32_t j = 0; j < out.size(); ++j) out[j] = contribution(slice, j, false);
  }
};

struct VplCluster {
  uint32_t representative = 0;          // VPL index, drawn among members with probability power / totalPower
  glm::vec3 totalFlux{0.0f};            // sum of member fluxes (W)
  float totalPower = 0.0f;              // sum of member powers (luminance of flux)
  float estimate = 0.0f;                // representative's contribution at the slice representative, x totalPower / its power, with visibility
  float spread = 0.0f;                  // power-weighted RMS distance of the members from the representative (world units)
  uint32_t memberBegin = 0, memberEnd = 0;  // into SliceClusters::members when keepMembers
};

struct SliceClusters {
  std::vector<VplCluster> clusters;
  std::vector<uint32_t> members;
};

struct LightSliceResult {
  std::vector<SliceClusters> slices;
  uint32_t globalClusterCount = 0;
  uint64_t evaluations = 0;  // contribution() calls
  // Wall seconds of the three steps: the reduced matrix (shadow rays), the global clustering, the
  // per-slice refinement with the clusters' estimates.
  double matrixSeconds = 0.0, globalSeconds = 0.0, refineSeconds = 0.0;
};

// When *cancel becomes true the remaining work is skipped: the result is then valid (every slice has
// a possibly empty cluster list) but incomplete, and the caller discards it.
LightSliceResult clusterLightSlice(std::span<const Vpl> vpls, std::span<const GatherPoint> points, const SliceTree& tree,
                                   const LightTransport& transport, const LightSliceSettings& settings,
                                   const std::atomic<bool>* cancel = nullptr);

}  // namespace vpl
