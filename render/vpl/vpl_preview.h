// The instant-radiosity preview (DESIGN.md §2 steps 2–5): VPLs, slices of gather points, LightSlice
// clusters per slice, and a pixel shader that adds direct light (emitter sampling) to the indirect
// light of the pixel's slice clusters. Each pass draws a few clusters per pixel in proportion to
// their estimated contribution (mostly moved from the slice's centre to the pixel's own hit), so
// passes average to the full clustered sum: a coarse image at once, sharper with every pass.
//
// Parameters (PreviewSettings):
//   vpl.count            int    16384  VPLs (see VplSettings)
//   slices.*                            see SliceSettings
//   clustering.*                        see LightSliceSettings
//   clampFraction        float  0.03   geometry-term clamp: 1/d^2 <= 1/(clampFraction x scene diagonal)^2
//                                       (`vplview sweep`, 3 seeds, 2 s, 1 thread: against 0.01 the preview's relMSE
//                                       is 0.85x on the Cornell box, 0.24x on two_rooms, 0.96x on the interior, its
//                                       bias 0.2-1.8 points darker; `mis` at 10 s unchanged, 0.99x and 1.01x)
//   clustersPerPass      int    16     clusters sampled per pixel and pass
//   pixelChoiceShare     float  0.8    share of a pixel's cluster choice made at its own hit (ClusterPoints),
//                                       the rest by its slice's choice; 0 is the choice of the slice alone
//                                       (relMSE at 2 s against 0: 0.16x interior, 0.56x two_rooms, 0.38x Cornell box)
#pragma once
#include <algorithm>
#include <memory>
#include <string>
#include <vector>
#include "render/cluster/light_slice.h"
#include "render/sampling/distribution_1d.h"
#include "render/session/tile_renderer.h"
#include "render/vpl/gather.h"
#include "render/vpl/vpl_tracer.h"

namespace vpl {

struct PreviewSettings {
  VplSettings vpl;
  SliceSettings slices;
  LightSliceSettings clustering;
  float clampFraction = 0.03f;
  int clustersPerPass = 16;
  float pixelChoiceShare = 0.8f;
  std::string validate() const;
};

// Point lights (VPLs, or clusters by their representatives) as one array per coordinate, each with
// a weight: the loops that weigh all of them against one receiver vectorize.
struct PointLights {
  std::vector<float> px, py, pz, nx, ny, nz, weight;
  size_t size() const { return px.size(); }
  void push(const glm::vec3& position, const glm::vec3& normal, float w) {
    px.push_back(position.x), py.push_back(position.y), pz.push_back(position.z);
    nx.push_back(normal.x), ny.push_back(normal.y), nz.push_back(normal.z);
    weight.push_back(w);
  }
  // weight x the unoccluded diffuse transport from light j to x facing n: both cosines over the
  // squared distance, clamped below at sqrt(clamp2) (vplContribution without the albedos).
  float transport(size_t j, const glm::vec3& x, const glm::vec3& n, float clamp2) const {
    const float dx = px[j] - x.x, dy = py[j] - x.y, dz = pz[j] - x.z;
    const float d2 = dx * dx + dy * dy + dz * dz;
    const float cosLight = std::max(0.0f, -(nx[j] * dx + ny[j] * dy + nz[j] * dz));  // x |d|
    const float cosHere = std::max(0.0f, n.x * dx + n.y * dy + n.z * dz);              // x |d|
    return weight[j] * cosLight * cosHere / std::max(d2 * std::max(d2, clamp2), 1e-30f);
  }
};

// A slice's clusters as point lights: a pass weighs every cluster by its unoccluded transport to the
// pixel's own hit, so that a cluster next to that hit is drawn as often as it matters there, not as
// at the slice's centre. The weight is (visible estimate + unoccluded share) / unoccluded transport,
// at the slice representative.
using ClusterPoints = PointLights;

// Everything the preview and the guide build for one camera (VPLs are the camera-independent part).
struct VplField {
  std::shared_ptr<const VplSet> vpls;
  CameraGather gather;
  SliceTree tree;
  LightSliceResult clusters;
  std::vector<Distribution1D> clusterChoice;  // per slice: which cluster a pass samples
  std::vector<ClusterPoints> clusterPoints;   // per slice: its clusters as points, for each pixel's own choice
  float minDistance = 0.0f;                   // geometry-term clamp distance (world units)
  uint64_t rays = 0;
  double gatherSeconds = 0.0, sliceSeconds = 0.0;  // wall time of those stages (LightSlice's are in `clusters`)
};

// The camera-dependent part; `vpls` is reused across camera moves. When *cancel becomes true the
// clustering stops early and the (valid but incomplete) field is for the bin.
VplField buildVplField(const RenderScene& scene, const Camera& camera, std::shared_ptr<const VplSet> vpls,
                       const PreviewSettings& settings, const std::atomic<bool>* cancel = nullptr);

PixelShaderFactory previewShader(const RenderScene& scene, const VplField& field, const PreviewSettings& settings);

// `s` with slices large enough that `pixels` gather points make about `maxSlices` of them or fewer (the
// kd-tree's median splits stop between half and twice that; LightSlice's cost grows with the slice
// count: a large window gets larger slices, not more).
PreviewSettings withAtMostSlices(const PreviewSettings& s, size_t pixels, int maxSlices);

// A first preview, shown while the full one is built: the same VPLs, but about `slices` slices
// (LightSlice's per-slice refinement, the dominant cost, shrinks with them) and fewer clusters per
// pixel in its one pass. Measured by bench/preview_stages.cpp.
struct CoarsePreview {
  int slices = 48;
  int clustersPerPass = 4;
  size_t maxPixels = 400000;  // larger windows get it at half their width and height, upscaled
};
// Its divisor of the window's width and height: 1, or 2 past CoarsePreview::maxPixels.
inline int coarsePreviewDivisor(int width, int height, const CoarsePreview& coarse = {}) {
  return size_t(width) * size_t(height) > coarse.maxPixels ? 2 : 1;
}
PreviewSettings coarsePreviewSettings(const PreviewSettings& full, size_t pixels, const CoarsePreview& coarse = {});

}  // namespace vpl
