// Instant radiosity (Keller 1997): light paths from the emitters, chosen by power, leave a VPL at
// every non-specular surface vertex they reach. VPLs depend on the scene only, not on the camera.
//
// Parameters (VplSettings):
//   count     int    16384  target number of VPLs; paths are traced in batches until it is reached
//                           (measured: 16K with 200 clusters per slice beat 8K and 32K on preview relMSE)
//   maxDepth  int    31     maximum bounces of a light path (0: no VPLs). A VPL of bounce k ends a
//                           path of k + 1 camera-side vertices: every caller sets it from the path
//                           tracer's depth by vplSettingsForPaths (8, fixed, lost 5 % of two_rooms'
//                           light)
//   seed      uint64 1
#pragma once
#include <cstdint>
#include <string>
#include <vector>
#include "render/scene/render_scene.h"
#include "render/vpl/vpl.h"

namespace vpl {

struct VplSettings {
  int count = 16384;
  int maxDepth = 31;
  uint64_t seed = 1;
  std::string validate() const;
};

struct VplSet {
  std::vector<Vpl> vpls;   // bounce >= 1 only: direct light is sampled from the emitters instead
  uint64_t lightPaths = 0; // paths traced; every VPL's flux is already divided by it
  uint64_t rays = 0;
};

VplSet traceVpls(const RenderScene& scene, const VplSettings& settings);

// The VPLs that complete the paths a path tracer of `pathDepth` segments sums, traced from `seed`.
VplSettings vplSettingsForPaths(VplSettings base, int pathDepth, uint64_t seed);

// Radiance a VPL sends to receiver point x through a receiver BSDF, without visibility:
// flux * f_vpl * f_x / max(d^2, minDistance^2) (the clamped geometry term of instant radiosity).
glm::vec3 vplContribution(const Vpl& light, const glm::vec3& x, const Bsdf& receiver, const glm::vec3& wo,
                          float minDistance);

}  // namespace vpl
