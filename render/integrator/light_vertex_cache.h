// VPL connections: the light vertices a camera path connects to (bidirectional path tracing with a
// light vertex cache, Davidovič et al. 2014). Each pass traces fresh light paths from the emitters,
// as instant radiosity does for its VPLs, and keeps every vertex they reach. A camera vertex joins
// one of them, chosen uniformly; multiple importance sampling (the balance of all ways to make a
// path: BSDF sampling, next-event estimation, connection at each vertex; power heuristic) weights
// each connection, so the VPLs carry the light that reaches the camera's room through a door while
// the short connections, which instant radiosity clamps, are left to the other strategies: no bias.
// The MIS weights follow the recursive form of Georgiev's "Implementing Vertex Connection and
// Merging" (2012), without merging and without light tracing to the camera.
//
// Parameters:
//   paths     per pass (ConnectionSettings::paths): more paths, less correlation between pixels of
//             one pass, more tracing per pass and a cache that falls out of the CPU's
//   maxLength most segments of a light subpath (the path tracer's maxDepth - 1)
#pragma once
#include <cstdint>
#include <string>
#include <vector>
#include <glm/glm.hpp>
#include "render/integrator/sampling_mode.h"
#include "render/material/bsdf.h"
#include "render/scene/render_scene.h"

namespace vpl {

// The heuristic applied to every density ratio of the weights (power 2, as the tracer's own MIS).
inline float connectionMis(float ratio) { return ratio * ratio; }

struct ConnectionSettings {
  // Light paths per pass; 0: no connections; -1 (auto): in the guided modes a 32nd of the pixels,
  // at least 1024, at most 8192; none in brdf. Fewer paths than that measured faster at the same
  // error: the joins' random reads stay in cache (door_ajar 320x240 mis 10 s: 19200 paths 57 spp,
  // relMSE 0.185; 4096 81 spp, 0.137; 1024 83 spp, 0.134).
  int paths = -1;

  int pathsFor(int pixels, SamplingMode mode) const;
  std::string validate() const;
};

struct LightVertex {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f};  // geometric, on the side the light arrived from
  glm::vec3 wIn{0.0f};     // unit, back towards the previous vertex of the light path
  // The light path's throughput to here over its density, with the arriving segment's cosine at
  // this vertex divided out: a connection multiplies it by both BSDFs and the cosine towards the
  // camera vertex over the squared distance.
  glm::vec3 alpha{0.0f};
  float dVC = 0.0f, dVCM = 0.0f;  // the MIS partial sums (Georgiev 2012) at this vertex
  int length = 0;                 // segments from the light
  Bsdf bsdf;
};

class LightVertexCache {
 public:
  // Traces `paths` light paths of pass `pass`, each with numbers of its own hashed from (seed,
  // pass, path): the cache depends on nothing else (not threads). Subpaths end after maxLength
  // segments or by Russian roulette. Empty for lights that connections do not support.
  void build(const RenderScene& scene, uint64_t seed, uint64_t pass, int paths, int maxLength);

  bool empty() const { return vertices_.empty(); }
  const std::vector<LightVertex>& vertices() const { return vertices_; }
  // One uniformly chosen vertex stands for all of them: its contribution is scaled by the vertex
  // count over the path count (each camera path sees one light path's worth on average).
  const LightVertex& pick(float u, float& scale) const {
    const size_t i = std::min(vertices_.size() - 1, size_t(u * float(vertices_.size())));
    scale = scale_;
    return vertices_[i];
  }
  uint64_t rays() const { return rays_; }

 private:
  std::vector<LightVertex> vertices_;
  int paths_ = 0;
  float scale_ = 0.0f;  // vertex count over path count
  uint64_t rays_ = 0;
};

}  // namespace vpl
