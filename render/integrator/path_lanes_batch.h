// PathLanes' batch of eight lanes (path_lanes.h says what they do), shared by the files that define
// its parts: path_lanes.cpp (a tile's samples, a vertex's bounce), path_lane_lights.cpp (next-event
// estimation's light samples in lanes) and path_lane_joins.cpp (the joins to light vertices). Private
// to them: everything here is compiled for AVX2 and FMA alone, which PathLanes::unsupported() checks.
#pragma once
#include <immintrin.h>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <vector>
#include <embree3/rtcore.h>
#include "render/integrator/light_vertex_cache.h"
#include "render/integrator/path_lanes.h"
#include "render/sampling/pixel_sampler.h"

// Brackets the code compiled for AVX2 and FMA alone (the header's and each file's); PathLanes::unsupported()
// keeps other CPUs out.
#if defined(__clang__)
#define VPL_LANES_TARGET_BEGIN _Pragma("clang attribute push(__attribute__((target(\"avx2,fma\"))), apply_to = function)")
#define VPL_LANES_TARGET_END _Pragma("clang attribute pop")
#else
#define VPL_LANES_TARGET_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx2,fma\")")
#define VPL_LANES_TARGET_END _Pragma("GCC pop_options")
#endif

VPL_LANES_TARGET_BEGIN

namespace vpl::lanes {

typedef float F8 __attribute__((vector_size(32)));
typedef int32_t I8 __attribute__((vector_size(32)));
typedef uint32_t U8 __attribute__((vector_size(32)));
typedef uint64_t U64x8 __attribute__((vector_size(64)));
inline constexpr float kInvPiF = std::numbers::inv_pi_v<float>;

inline F8 splat(float x) { return F8{} + x; }
inline F8 sqrt8(F8 x) { return F8(_mm256_sqrt_ps(__m256(x))); }
inline F8 min8(F8 a, F8 b) { return a < b ? a : b; }
inline F8 max8(F8 a, F8 b) { return a > b ? a : b; }
inline F8 abs8(F8 a) { return F8(I8(a) & 0x7fffffff); }
// PathTracer's bidirectionalWeight in lanes: 1 over 1 plus the other techniques' share, 0 where that
// share is not finite.
inline F8 bidirectionalWeight8(F8 others) { return others < INFINITY ? 1.0f / (1.0f + others) : F8{}; }
// Before the renderer's scalar code (built for any x86-64, so SSE without VEX) is called from the lanes:
// after AVX code has written the upper halves of the vector registers, that code ran measurably
// slower on this machine (the lanes' fallback light samples: lamp_rooms 7 % more render time, the
// Cornell box 5 %), and GCC's own vzeroupper does not precede every such call.
inline void clearUpperHalves() { _mm256_zeroupper(); }
inline bool any(I8 m) { return _mm256_movemask_ps(__m256(m)) != 0; }
inline int count(I8 m) { return __builtin_popcount(unsigned(_mm256_movemask_ps(__m256(m)))); }

// offsetRayOrigin (accel.cpp), eight points at once; n is the side to leave by.
inline void offsetRayOrigins(F8& px, F8& py, F8& pz, F8 nx, F8 ny, F8 nz, F8 coordinateScale) {
  const F8 scale = ((coordinateScale > 0.0f) & (coordinateScale < INFINITY)) ? coordinateScale : splat(1.0f);
  offsetCoordinates<F8, I8>(px, nx, scale);
  offsetCoordinates<F8, I8>(py, ny, scale);
  offsetCoordinates<F8, I8>(pz, nz, scale);
}

}  // namespace vpl::lanes

namespace vpl {

class PathLanes::Batch {
 public:
  using F8 = lanes::F8;
  using I8 = lanes::I8;

  Batch(const PathLanes& lanes, const Camera& camera, uint64_t seed, uint64_t pass, int x0, int y0, int x1, int y1,
        Film& film, PathStats& stats, uint64_t& discarded)
      : lanes_(lanes), scene_(lanes.scene_), emitters_(lanes.scene_.emitters()), guide_(lanes.tracer_.emitterGuide()),
        settings_(lanes.tracer_.settings()), connections_(lanes.tracer_.connections()), camera_(camera), seed_(seed), pass_(pass), x0_(x0), y0_(y0), x1_(x1),
        film_(film), stats_(stats), discarded_(discarded), pixels_(uint32_t(x1 - x0) * uint32_t(y1 - y0)) {}

  void run();

 private:
  // A split's branch waiting for its lane (PathTracer::radiance's Branch, without a counterfactual's sums).
  struct Branch {
    Ray ray;
    glm::vec3 beta{0.0f}, previousPosition{0.0f};
    float previousPdf = 0.0f;
    int depth = 0;
    PixelSampler sampler;
    PathTracer::MisSums mis;
  };
  // Next-event estimation's light samples of the eight lanes, and which lanes have one (sampleLights()).
  struct LightLanes {
    I8 served, found, learned;  // learned: found in a region that learned, whose sample records its arrival
    F8 wx, wy, wz, distance, r, g, b, pdf, cosLight, emissionPdf;
    std::array<uint32_t, kLanes> slot;  // learned lanes' EmitterGuide slots
  };

  // The vertex that joins, in lanes: bounce()'s hit, its normals (geometric, shading), its albedo, and
  // the origin of the rays that leave it on the geometric normal's side.
  struct JoiningVertex {
    const F8 &px, &py, &pz, &nx, &ny, &nz, &sx, &sy, &sz, &ar, &ag, &ab, &qx, &qy, &qz;
  };

  void start(int k);
  bool stage();
  void resume(int k, const Branch& b);
  void finish(int k);
  void end(I8 lanes) { alive_ &= ~lanes; }
  void drawAhead();
  glm::vec3 beta(int k) const { return {br_[k], bg_[k], bb_[k]}; }
  PathTracer::MisSums sums(int k) const { return {dVC_[k], dVCM_[k]}; }
  glm::vec3 wo(int k) const { return -glm::vec3(dx_[k], dy_[k], dz_[k]); }  // back along lane k's ray
  void sampleLights(F8 px, F8 py, F8 pz, F8 ux, F8 uy, LightLanes& out) const;  // path_lane_lights.cpp
  void bounce();
  SurfaceHit hitSurface(int k, F8 px, F8 py, F8 pz, F8 nx, F8 ny, F8 nz, F8 sx, F8 sy, F8 sz, F8 scale, uint32_t mesh,
                        uint32_t triangle) const;
  float emitterHit(int k, const SurfaceHit& surface);
  void branch(int k, int split, const SurfaceHit& surface);
  void join(RTCScene handle, RTCIntersectContext& context, const JoiningVertex& v);  // path_lane_joins.cpp
  void escape(int k);

  const PathLanes& lanes_;
  const RenderScene& scene_;
  const EmitterSet& emitters_;
  const EmitterGuide* guide_;
  const PathTracerSettings& settings_;
  const LightVertexCache* connections_;  // null: no joins
  BsdfContinuation bsdfContinuation_;    // the strategy the tracer's weights ask about
  const Camera& camera_;
  uint64_t seed_, pass_;
  int x0_, y0_, x1_;
  Film& film_;
  PathStats& stats_;
  uint64_t& discarded_;
  uint32_t next_ = 0, pixels_;

  // The pixels stage() prepared, from staged_ on.
  std::optional<PixelSampler> stagedSamplers_[kLanes];
  int stagedX_[kLanes] = {}, stagedY_[kLanes] = {};
  F8 stagedDx_{}, stagedDy_{}, stagedDz_{};
  int staged_ = 0, stagedCount_ = 0;

  // Per lane: its sample, and its path's state (vectors where the arithmetic is shared).
  std::optional<PixelSampler> samplers_[kLanes];
  std::optional<VertexSamples> numbers_[kLanes];  // of the vertex each live lane is at (a member: no clearing per bounce)
  int x_[kLanes] = {}, y_[kLanes] = {};
  bool started_[kLanes] = {}, frontFace_[kLanes] = {};
  glm::vec3 L_[kLanes];
  float pixelEstimate_[kLanes] = {};  // the weight window's reference, set at the camera ray's hit
  int branchesLeft_[kLanes] = {};
  uint32_t nextBranchId_[kLanes] = {};
  std::vector<Branch> pending_[kLanes];  // the sample's branches still to trace, last made first
  // With joins: the lanes that join at this vertex, and the vertex and BSDF of the lanes whose light
  // sample is scalar.
  bool joinsHere_[kLanes] = {};
  const LightVertex* joinTo_[kLanes][LightVertexCache::kMaxJoinsPerVertex] = {};  // the light vertices they join
  float joinScale_[kLanes][LightVertexCache::kMaxJoinsPerVertex] = {};
  SurfaceHit surfaces_[kLanes];
  std::optional<Bsdf> bsdfs_[kLanes];
  F8 ox_{}, oy_{}, oz_{}, dx_{}, dy_{}, dz_{}, tMax_{}, br_{}, bg_{}, bb_{}, prevPdf_{}, prevX_{}, prevY_{}, prevZ_{};
  F8 dVC_{}, dVCM_{};  // with joins: the camera side's partial sums (PathTracer::MisSums)
  I8 depth_{}, alive_{};
};

}  // namespace vpl

VPL_LANES_TARGET_END
