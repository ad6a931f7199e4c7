#include "render/integrator/path_lanes.h"

#include <immintrin.h>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <embree3/rtcore.h>
#include "render/core/color.h"
#include "render/guide/emitter_guide.h"
#include "render/integrator/light_vertex_cache.h"
#include "render/sampling/fast_trig.h"
#include "render/sampling/lane_sobol.h"
#include "render/sampling/pixel_sampler.h"
#include "render/integrator/weight_window.h"
#include "render/sampling/warps.h"

namespace vpl {

std::string PathLanes::unsupported(const PathTracer& tracer) {
  if (!tracer.settings().lanes) return "--lanes off";
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) return "the CPU has no AVX2 and FMA";
  const RenderScene& scene = tracer.scene();
  const SceneData& data = scene.data();
  for (const Material& m : data.materials) {
    if (m.hasTextures()) return "a textured material";
    if (m.alphaMode != AlphaMode::Opaque) return "a material with alpha";
  }
  for (uint32_t mesh = 0; mesh < data.meshes.size(); ++mesh) {
    const MeshData& m = data.meshes[mesh];
    SurfaceHit probe;
    probe.material = m.material;
    if (!scene.bsdf(probe).lambertian()) return "a material with a specular lobe";
  }
  return "";
}

PathLanes::PathLanes(const PathTracer& tracer) : tracer_(tracer), scene_(tracer.scene()) {
  const SceneData& data = scene_.data();
  for (uint32_t mesh = 0; mesh < data.meshes.size(); ++mesh) {
    const MeshData& m = data.meshes[mesh];
    meshBase_.push_back(uint32_t(triangles_.size()));
    SurfaceHit probe;
    probe.material = m.material;
    const glm::vec3 albedo = scene_.bsdf(probe).params().diffuse;
    const glm::vec3 le = data.materials[m.material].emission;
    for (uint32_t t = 0; 3 * size_t(t) + 2 < m.indices.size(); ++t) {
      const uint32_t* idx = &m.indices[3 * size_t(t)];
      const RenderScene::TriangleFacts& facts = scene_.triangleFacts(mesh, t);
      triangles_.push_back({m.positions[idx[0]], m.positions[idx[1]], m.positions[idx[2]], facts.normal, albedo,
                            facts.coordinateScale});
      emits_.push_back(!isBlack(le));
      smooth_.push_back(m.normals.empty() ? UINT32_MAX : uint32_t(normals_.size()));
      if (!m.normals.empty())
        for (int i = 0; i < 3; ++i) normals_.push_back(m.normals[idx[i]]);
    }
  }
  const EmitterSet& emitters = scene_.emitters();
  if (!emitters.foldsChoice()) return;
  for (size_t i = 0; i < emitters.triangleCount(); ++i) {
    const EmitterSet::TriangleLight& t = emitters.triangleLight(i);
    if (t.textured) {
      lights_.clear();
      return;
    }
    const glm::vec3 le = data.materials[data.meshes[t.mesh].material].emission;
    lights_.push_back({{t.p0.x, t.p0.y, t.p0.z}, {t.p1.x, t.p1.y, t.p1.z}, {t.p2.x, t.p2.y, t.p2.z},
                       {t.normal.x, t.normal.y, t.normal.z}, {t.centre.x, t.centre.y, t.centre.z}, t.radius,
                       t.longestEdge, t.coordinateScale, t.area, t.twoSided ? 1.0f : 0.0f, {le.x, le.y, le.z},
                       emitters.emitterPmf(i), emitters.foldedChoice().pmf(i)});
  }
  const Distribution1D& choice = emitters.foldedChoice();
  for (size_t i = 0; i <= choice.size(); ++i) lightCdf_.push_back(choice.cdf(i));
}

// The vector code below is compiled for AVX2 and FMA alone; unsupported() keeps other CPUs out.
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2,fma"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2,fma")
#endif

namespace {

typedef float F8 __attribute__((vector_size(32)));
typedef int32_t I8 __attribute__((vector_size(32)));
typedef uint32_t U8 __attribute__((vector_size(32)));
typedef uint64_t U64x8 __attribute__((vector_size(64)));
constexpr float kInvPiF = std::numbers::inv_pi_v<float>;

F8 splat(float x) { return F8{} + x; }
F8 sqrt8(F8 x) { return F8(_mm256_sqrt_ps(__m256(x))); }
F8 min8(F8 a, F8 b) { return a < b ? a : b; }
F8 max8(F8 a, F8 b) { return a > b ? a : b; }
F8 abs8(F8 a) { return F8(I8(a) & 0x7fffffff); }
// PathTracer's bidirectionalWeight in lanes: 1 over 1 plus the other techniques' share, 0 where that
// share is not finite.
F8 bidirectionalWeight8(F8 others) { return others < INFINITY ? 1.0f / (1.0f + others) : F8{}; }
// Tables of up to this many entries are read by selects, not gathers: a gather costs about as much as
// a scalar lane's light sample on the machines measured (a light of two triangles: 8 % of the time).
constexpr int kSelectedEntries = 4;

// table[index] for four indices of a table of `size` entries (the masked gather: the plain one reads
// an undefined register).
__m256d lookUpDoubles(const double* table, int size, __m128i index) {
  if (size > kSelectedEntries)
    return _mm256_mask_i32gather_pd(_mm256_setzero_pd(), table, index, _mm256_castsi256_pd(_mm256_set1_epi64x(-1)), 8);
  __m256d v = _mm256_set1_pd(table[0]);
  for (int i = 1; i < size; ++i)
    v = _mm256_blendv_pd(v, _mm256_set1_pd(table[i]),
                         _mm256_castsi256_pd(_mm256_cvtepi32_epi64(_mm_cmpeq_epi32(index, _mm_set1_epi32(i)))));
  return v;
}
// Before the renderer's scalar code (built for any x86-64, so SSE without VEX) is called from the lanes:
// after AVX code has written the upper halves of the vector registers, that code ran measurably
// slower on this machine (the lanes' fallback light samples: lamp_rooms 7 % more render time, the
// Cornell box 5 %), and GCC's own vzeroupper does not precede every such call.
void clearUpperHalves() { _mm256_zeroupper(); }
bool any(I8 m) { return _mm256_movemask_ps(__m256(m)) != 0; }
int count(I8 m) { return __builtin_popcount(unsigned(_mm256_movemask_ps(__m256(m)))); }

// offsetRayOrigin (accel.cpp), eight points at once; n is the side to leave by.
void offsetRayOrigins(F8& px, F8& py, F8& pz, F8 nx, F8 ny, F8 nz, F8 coordinateScale) {
  const F8 scale = ((coordinateScale > 0.0f) & (coordinateScale < INFINITY)) ? coordinateScale : splat(1.0f);
  offsetCoordinates<F8, I8>(px, nx, scale);
  offsetCoordinates<F8, I8>(py, ny, scale);
  offsetCoordinates<F8, I8>(pz, nz, scale);
}

}  // namespace

class PathLanes::Batch {
 public:
  Batch(const PathLanes& lanes, const Camera& camera, uint64_t seed, uint64_t pass, int x0, int y0, int x1, int y1,
        Film& film, PathStats& stats, uint64_t& discarded)
      : lanes_(lanes), scene_(lanes.scene_), emitters_(lanes.scene_.emitters()), guide_(lanes.tracer_.emitterGuide()),
        settings_(lanes.tracer_.settings()), connections_(lanes.tracer_.connections()), camera_(camera), seed_(seed), pass_(pass), x0_(x0), y0_(y0), x1_(x1),
        film_(film), stats_(stats), discarded_(discarded), pixels_(uint32_t(x1 - x0) * uint32_t(y1 - y0)) {}

  void run() {
    for (int k = 0; k < kLanes; ++k) start(k);
    while (any(alive_)) {
      bounce();
      for (int k = 0; k < kLanes; ++k)
        if (!alive_[k] && started_[k]) {
          if (!pending_[k].empty()) {  // the sample's next branch, in radiance()'s order
            resume(k, pending_[k].back());
            pending_[k].pop_back();
            continue;
          }
          finish(k);
          start(k);
        }
    }
  }

 private:
  // Lane k takes the tile's next pixel, if any is left.
  void start(int k) {
    started_[k] = false;
    if (staged_ == stagedCount_ && !stage()) return;
    const int j = staged_++;
    x_[k] = stagedX_[j], y_[k] = stagedY_[j];
    samplers_[k].emplace(*stagedSamplers_[j]);
    const glm::vec3& eye = camera_.data().eye;
    ox_[k] = eye.x, oy_[k] = eye.y, oz_[k] = eye.z;
    dx_[k] = stagedDx_[j], dy_[k] = stagedDy_[j], dz_[k] = stagedDz_[j];
    tMax_[k] = INFINITY;
    br_[k] = bg_[k] = bb_[k] = 1.0f;
    L_[k] = glm::vec3(0.0f);
    depth_[k] = 0;
    prevPdf_[k] = 0.0f;
    dVC_[k] = dVCM_[k] = 0.0f;
    alive_[k] = -1;
    started_[k] = true;
    branchesLeft_[k] = settings_.window.maxBranches - 1;
    nextBranchId_[k] = 1;
  }

  // The tile's next kLanes pixels (fewer at its end; false: none left), ready for start(): their
  // samplers, and their camera rays (Camera::generateRay through the sampler's cameraJitter) in lanes.
  bool stage() {
    staged_ = stagedCount_ = 0;
    U64x8 keys{};
    U8 reversed{};
    F8 x{}, y{};
    const int width = x1_ - x0_;
    while (stagedCount_ < kLanes && next_ < pixels_) {
      const uint32_t i = next_++;
      const int j = stagedCount_++;
      stagedX_[j] = x0_ + int(i % uint32_t(width)), stagedY_[j] = y0_ + int(i / uint32_t(width));
      const uint64_t pixel = uint64_t(stagedY_[j]) * uint64_t(camera_.width()) + uint64_t(stagedX_[j]);
      const PixelSampler& sampler = stagedSamplers_[j].emplace(seed_, pixel, pass_, true);
      keys[j] = sampler.pixelKey(), reversed[j] = sampler.reversedIndex();
      x[j] = float(stagedX_[j]), y[j] = float(stagedY_[j]);
    }
    if (stagedCount_ == 0) return false;
    F8 jitterX, jitterY;
    const U8 slot = U8{} + PixelSampler::kCameraSlot;
    lane_sobol::point(keys, reversed, slot, jitterX, jitterY);
    x += jitterX, y += jitterY;
    camera_.directions(x, y, stagedDx_, stagedDy_, stagedDz_, [](const F8& v, F8& r) { r = sqrt8(v); });
    return true;
  }

  // A split's branch waiting for its lane (PathTracer::radiance's Branch, without a counterfactual's sums).
  struct Branch {
    Ray ray;
    glm::vec3 beta{0.0f}, previousPosition{0.0f};
    float previousPdf = 0.0f;
    int depth = 0;
    PixelSampler sampler;
    PathTracer::MisSums mis;
  };

  // Lane k goes on with one of its sample's branches.
  void resume(int k, const Branch& b) {
    samplers_[k].emplace(b.sampler);
    ox_[k] = b.ray.origin.x, oy_[k] = b.ray.origin.y, oz_[k] = b.ray.origin.z;
    dx_[k] = b.ray.direction.x, dy_[k] = b.ray.direction.y, dz_[k] = b.ray.direction.z;
    tMax_[k] = b.ray.tMax;
    br_[k] = b.beta.x, bg_[k] = b.beta.y, bb_[k] = b.beta.z;
    prevX_[k] = b.previousPosition.x, prevY_[k] = b.previousPosition.y, prevZ_[k] = b.previousPosition.z;
    prevPdf_[k] = b.previousPdf;
    depth_[k] = b.depth;
    dVC_[k] = b.mis.dVC, dVCM_[k] = b.mis.dVCM;
    alive_[k] = -1;
  }

  void finish(int k) {
    started_[k] = false;
    if (!isFiniteNonNegative(L_[k])) {
      ++discarded_;
      return;
    }
    clearUpperHalves();
    film_.addSample(x_[k], y_[k], L_[k]);
  }

  void end(I8 lanes) { alive_ &= ~lanes; }

  // The two numbers every vertex reads (VertexSamples::drawAhead), for the lanes whose vertex draws
  // from the stratified slots, at once; the others (a split's branches, deep vertices) draw their own.
  void drawAhead() {
    U64x8 keys{};
    U8 reversed{}, lightSlot{}, bsdfSlot{};
    I8 stratified{};
    for (int k = 0; k < kLanes; ++k) {
      if (!alive_[k] || !samplers_[k]->stratifiedAt(depth_[k])) continue;
      stratified[k] = -1;
      keys[k] = samplers_[k]->pixelKey();
      reversed[k] = samplers_[k]->reversedIndex();
      lightSlot[k] = PixelSampler::slotOf(depth_[k], VertexDimension::LightPoint);
      bsdfSlot[k] = PixelSampler::slotOf(depth_[k], VertexDimension::BsdfDirection);
    }
    if (!any(stratified)) return;
    F8 lightX, lightY, bsdfX, bsdfY;
    lane_sobol::point(keys, reversed, lightSlot, lightX, lightY);
    lane_sobol::point(keys, reversed, bsdfSlot, bsdfX, bsdfY);
    for (int k = 0; k < kLanes; ++k)
      if (stratified[k]) numbers_[k]->drawnAhead({lightX[k], lightY[k]}, {bsdfX[k], bsdfY[k]});
  }
  glm::vec3 beta(int k) const { return {br_[k], bg_[k], bb_[k]}; }
  PathTracer::MisSums sums(int k) const { return {dVC_[k], dVCM_[k]}; }
  glm::vec3 wo(int k) const { return -glm::vec3(dx_[k], dy_[k], dz_[k]); }  // back along lane k's ray

  // EmitterSet::sampleStratified from each lane's p with its numbers u, in lanes, where it folds the
  // choice and draws an untextured triangle by area, and the guide (if any) samples as EmitterSet
  // there: the same decisions in the same order, so the same sample up to float rounding. `served`:
  // the lanes whose sample this is (`found`: those that have one); the others (a triangle sampled by
  // solid angle, a punctual light or the sky, a region that learned, or one that records its samples
  // and has one to record) call the renderer's own code.
  struct LightLanes {
    I8 served, found;
    F8 wx, wy, wz, distance, r, g, b, pdf, cosLight, emissionPdf;
  };
  void sampleLights(F8 px, F8 py, F8 pz, F8 ux, F8 uy, LightLanes& out) const {
    out.served = out.found = I8{};
    if (lanes_.lights_.empty()) return;
    I8 served = alive_, recording{};
    if (guide_) {
      I8 region;
      guide_->regionIndex<F8, I8>(px, py, pz, [](const F8& t, I8& i) { i = __builtin_convertvector(t, I8); }, region);
      const EmitterGuide::State* states = guide_->states();
      for (int k = 0; k < kLanes; ++k) {
        const EmitterGuide::State state = states[region[k]];
        if (state == EmitterGuide::State::Learned) served[k] = 0;
        if (state == EmitterGuide::State::Undecided) recording[k] = -1;
      }
      if (!any(served)) return;
    }

    // The folded choice (Distribution1D::sampleRange over every emitter), in doubles as there, four
    // lanes at a time.
    const double* cdf = lanes_.lightCdf_.data();
    const int32_t n = int32_t(lanes_.lightCdf_.size() - 1);
    const __m256d lo = _mm256_set1_pd(cdf[0]), span = _mm256_set1_pd(cdf[n] - cdf[0]);
    const __m128i bits = _mm_setr_epi32(1, 2, 4, 8);
    const auto maskOf = [&bits](__m256d m) {  // four doubles' compare mask as four ints' (0 or 1)
      const __m128i b = _mm_and_si128(_mm_set1_epi32(_mm256_movemask_pd(m)), bits);
      return _mm_srli_epi32(_mm_cmpeq_epi32(b, bits), 31);
    };
    alignas(32) int32_t chosen[kLanes];
    alignas(32) float remappedU[kLanes];
    for (int half = 0; half < 2; ++half) {
      const __m128 u4 = half ? _mm256_extractf128_ps(__m256(ux), 1) : _mm256_castps256_ps128(__m256(ux));
      const __m256d u = _mm256_min_pd(_mm256_max_pd(_mm256_cvtps_pd(u4), _mm256_setzero_pd()), _mm256_set1_pd(1.0));
      const __m256d x = _mm256_add_pd(lo, _mm256_mul_pd(u, span));
      __m128i base = _mm_set1_epi32(1);  // into cdf: the search runs over cdf[1, n]
      for (int32_t m = n; m > 1;) {
        const int32_t step = m / 2;
        const __m128i probe = _mm_add_epi32(base, _mm_set1_epi32(step));
        const __m256d below = _mm256_cmp_pd(lookUpDoubles(cdf, n + 1, probe), x, _CMP_LE_OQ);
        base = _mm_add_epi32(base, _mm_mullo_epi32(maskOf(below), _mm_set1_epi32(step)));
        m -= step;
      }
      const __m256d last = _mm256_cmp_pd(lookUpDoubles(cdf, n + 1, base), x, _CMP_LE_OQ);
      __m128i index = _mm_add_epi32(_mm_sub_epi32(base, _mm_set1_epi32(1)), maskOf(last));
      index = _mm_min_epi32(index, _mm_set1_epi32(n - 1));  // below == n: the last
      const __m256d low = lookUpDoubles(cdf, n + 1, index);
      const __m256d width = _mm256_sub_pd(lookUpDoubles(cdf, n + 1, _mm_add_epi32(index, _mm_set1_epi32(1))), low);
      __m256d r = _mm256_and_pd(_mm256_div_pd(_mm256_sub_pd(x, low), width),
                                _mm256_cmp_pd(width, _mm256_setzero_pd(), _CMP_GT_OQ));
      r = _mm256_min_pd(_mm256_max_pd(r, _mm256_setzero_pd()), _mm256_set1_pd(double(0x1.fffffep-1f)));
      _mm_store_si128(reinterpret_cast<__m128i*>(chosen + 4 * half), index);
      _mm_store_ps(remappedU + 4 * half, _mm256_cvtpd_ps(r));
    }
    const I8 index = *reinterpret_cast<const I8*>(chosen);
    const F8 u0 = *reinterpret_cast<const F8*>(remappedU);
    served &= index < int32_t(lanes_.lights_.size());
    if (!any(served)) return;

    // The chosen triangle's record, field by field.
    const I8 light = served ? index : I8{};
    const LightRecord& r0 = lanes_.lights_[0];
    const int lights = int(lanes_.lights_.size());
    const auto field = [&](const float& f) {
      constexpr int stride = int(sizeof(LightRecord) / sizeof(float));
      if (lights > kSelectedEntries) return F8(_mm256_i32gather_ps(&f, __m256i(light * stride), 4));
      F8 v = splat(f);
      for (int i = 1; i < lights; ++i) v = light == i ? splat((&f)[i * stride]) : v;
      return v;
    };
    served &= field(r0.foldedPmf) > 0.0f;
    const F8 ax = field(r0.p0[0]), ay = field(r0.p0[1]), az = field(r0.p0[2]);
    const F8 lnx = field(r0.normal[0]), lny = field(r0.normal[1]), lnz = field(r0.normal[2]);
    const I8 twoSided = field(r0.twoSided) > 0.0f;

    // EmitterSet::planeDistance, then the side: p in the plane, or behind a one-sided light, gets nothing.
    const F8 h = lnx * (px - ax) + lny * (py - ay) + lnz * (pz - az);
    const F8 extent = max8(field(r0.coordinateScale), max8(abs8(px), max8(abs8(py), abs8(pz))));
    I8 found = served & (abs8(h) > EmitterSet::kPlaneTolerance * extent) & ((h > 0.0f) | twoSided);
    // EmitterSet::solidAngleStrategy's test: a triangle that looks large goes to the scalar code.
    const F8 cx = field(r0.centre[0]) - px, cy = field(r0.centre[1]) - py, cz = field(r0.centre[2]) - pz;
    const F8 hp = abs8(lnx * (ax - px) + lny * (ay - py) + lnz * (az - pz));
    const F8 nearest = max8(hp, sqrt8(cx * cx + cy * cy + cz * cz) - field(r0.radius));
    served &= ~(found & (field(r0.longestEdge) > EmitterSet::kSolidAngleSpread * nearest));
    found &= served;
    out.served = served;
    if (!any(found)) return;

    // EmitterSet::sampleTrianglePoint: sampleUniformTriangle's point, then its direction and density.
    const I8 below0 = u0 < uy;
    const F8 b0 = below0 ? u0 / 2.0f : u0 - uy / 2.0f, b1 = below0 ? uy - u0 / 2.0f : uy / 2.0f;
    const F8 bx = b1, by = 1.0f - b0 - b1, bw = 1.0f - bx - by;
    const F8 dx = ax * bw + field(r0.p1[0]) * bx + field(r0.p2[0]) * by - px;
    const F8 dy = ay * bw + field(r0.p1[1]) * bx + field(r0.p2[1]) * by - py;
    const F8 dz = az * bw + field(r0.p1[2]) * bx + field(r0.p2[2]) * by - pz;
    const F8 dist2 = dx * dx + dy * dy + dz * dz;
    found &= dist2 > 0.0f;
    out.distance = sqrt8(dist2);
    out.wx = dx / out.distance, out.wy = dy / out.distance, out.wz = dz / out.distance;
    const F8 cosLight = -(lnx * out.wx + lny * out.wy + lnz * out.wz);
    found &= (abs8(cosLight) >= 1e-7f) & ((cosLight > 0.0f) | twoSided);
    out.r = field(r0.emission[0]), out.g = field(r0.emission[1]), out.b = field(r0.emission[2]);
    found &= (out.r > 0.0f) | (out.g > 0.0f) | (out.b > 0.0f);
    out.cosLight = abs8(cosLight);
    out.pdf = field(r0.pmf) * dist2 / (out.cosLight * field(r0.area));
    // EmitterSet::emissionPdf, for bidirectional MIS's weight.
    if (connections_)
      out.emissionPdf = field(r0.pmf) * out.cosLight / (std::numbers::pi_v<float> * field(r0.area) * (twoSided ? splat(2.0f) : splat(1.0f)));
    // A recording region's sample goes to the renderer's code, which names its slot; where there is
    // no sample there is nothing to record (a ceiling behind a one-sided light: most of such regions).
    out.served = served & ~(found & recording);
    out.found = found & out.served;
  }

  // One vertex of every live lane: radiance()'s loop body for BSDF sampling without joins.
  void bounce() {
    const RTCScene handle = scene_.accel().handle();
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    alignas(32) int valid[kLanes];
    alignas(32) RTCRayHit8 rh;
    for (int k = 0; k < kLanes; ++k) {
      valid[k] = alive_[k];
      rh.ray.org_x[k] = ox_[k], rh.ray.org_y[k] = oy_[k], rh.ray.org_z[k] = oz_[k];
      rh.ray.dir_x[k] = dx_[k], rh.ray.dir_y[k] = dy_[k], rh.ray.dir_z[k] = dz_[k];
      rh.ray.tnear[k] = 0.0f, rh.ray.tfar[k] = tMax_[k], rh.ray.time[k] = 0.0f;
      rh.ray.mask[k] = ~0u, rh.ray.id[k] = 0, rh.ray.flags[k] = 0;
      rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID, rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, handle, &context, &rh);
    stats_.rays += uint64_t(count(alive_));

    // The hits, lane by lane: position, the normal facing the ray, the triangle's facts.
    F8 px{}, py{}, pz{}, nx{}, ny{}, nz{}, sx{}, sy{}, sz{}, ar{}, ag{}, ab{}, scale{};
    I8 hitEmitter{};
    for (int k = 0; k < kLanes; ++k) {
      if (!alive_[k]) continue;
      if (rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) {
        clearUpperHalves();
        escape(k);
        alive_[k] = 0;
        continue;
      }
      const uint32_t g = lanes_.meshBase_[rh.hit.geomID[k]] + rh.hit.primID[k];
      const Triangle& t = lanes_.triangles_[g];
      const float u = rh.hit.u[k], v = rh.hit.v[k], b0 = 1.0f - u - v;
      const glm::vec3 p = t.p0 * b0 + t.p1 * u + t.p2 * v;
      const glm::vec3 d(dx_[k], dy_[k], dz_[k]);
      glm::vec3 n = t.normal;
      if (n == glm::vec3(0.0f)) n = -d;  // degenerate, as surface() does
      const bool front = glm::dot(n, d) < 0.0f;
      if (!front) n = -n;
      if (connections_) {  // the camera side's sums arrive here (radiance(): a grazing hit ends the path)
        const float cosHit = std::abs(glm::dot(n, d));
        if (!(cosHit > 0.0f)) {
          alive_[k] = 0;
          continue;
        }
        PathTracer::MisSums sums = this->sums(k);
        sums.arrive(rh.ray.tfar[k], cosHit);
        dVC_[k] = sums.dVC, dVCM_[k] = sums.dVCM;
      }
      glm::vec3 ns = n;  // the shading normal, interpolated as surface() does, on n's side
      if (const uint32_t first = lanes_.smooth_[g]; first != UINT32_MAX) {
        const glm::vec3* vn = &lanes_.normals_[first];
        const glm::vec3 interpolated = vn[0] * b0 + vn[1] * u + vn[2] * v;
        const float length = glm::length(interpolated);
        if (length > 1e-8f && std::isfinite(length)) {
          ns = interpolated / length;
          if (glm::dot(ns, n) < 0.0f) ns = -ns;
        }
      }
      px[k] = p.x, py[k] = p.y, pz[k] = p.z, nx[k] = n.x, ny[k] = n.y, nz[k] = n.z, sx[k] = ns.x, sy[k] = ns.y, sz[k] = ns.z;
      ar[k] = t.albedo.x, ag[k] = t.albedo.y, ab[k] = t.albedo.z, scale[k] = t.coordinateScale;
      frontFace_[k] = front;
      if (lanes_.emits_[g]) hitEmitter[k] = -1;
    }
    float emitted[kLanes] = {};
    for (int k = 0; k < kLanes; ++k)
      if (hitEmitter[k]) {
        clearUpperHalves();
        emitted[k] = emitterHit(k, hitSurface(k, px, py, pz, nx, ny, nz, sx, sy, sz, scale, rh.hit.geomID[k], rh.hit.primID[k]));
      }
    // From here on dVCM stands for a join with its light end at this vertex (radiance()).
    if (connections_)
      for (int k = 0; k < kLanes; ++k)
        if (alive_[k])
          dVCM_[k] *= connections_->joinsAt(depth_[k] - 1) ? connections_->misFactor(glm::vec3(px[k], py[k], pz[k])) : 0.0f;
    end(depth_ + 1 > settings_.maxDepth);
    if (!any(alive_)) return;

    // The vertex's numbers, from each lane's sampler (the same slots as radiance()).
    for (int k = 0; k < kLanes; ++k)
      if (alive_[k]) numbers_[k].emplace(*samplers_[k], int(depth_[k]));
    drawAhead();

    // The VPL weight window: roulette for paths worth little against the pixel, splitting for those
    // worth much; the camera ray's hit sets the pixel's estimate.
    I8 windowed{};
    int split[kLanes];
    std::fill(split, split + kLanes, 1);
    if (lanes_.tracer_.usesWeightWindow())
      for (int k = 0; k < kLanes; ++k) {
        if (!alive_[k]) continue;
        clearUpperHalves();
        const float predicted = lanes_.tracer_.predictedRadiance(glm::vec3(px[k], py[k], pz[k]), glm::vec3(nx[k], ny[k], nz[k]),
                                                                 glm::vec3(ar[k], ag[k], ab[k]));
        if (depth_[k] == 0) {
          pixelEstimate_[k] = emitted[k] + predicted;
        } else if (pixelEstimate_[k] > 0.0f && predicted > 0.0f) {
          windowed[k] = -1;
          const WindowDecision d = weightWindow(luminance(beta(k)) * predicted / pixelEstimate_[k], settings_.window);
          if (d.survival < 1.0f) {
            if (numbers_[k]->roulette() >= d.survival) {
              alive_[k] = 0;
              continue;
            }
            br_[k] /= d.survival, bg_[k] /= d.survival, bb_[k] /= d.survival;
          }
          split[k] = std::min(d.split, branchesLeft_[k] + 1);
        }
      }
    if (!any(alive_)) return;
    F8 uDir0 = splat(0.5f), uDir1 = splat(0.5f);
    for (int k = 0; k < kLanes; ++k)
      if (alive_[k]) {
        const glm::vec2 u = numbers_[k]->bsdfDirection();
        uDir0[k] = u.x, uDir1[k] = u.y;
      }

    // Next-event estimation: in lanes where sampleLights() serves, else lane by lane; the shadow rays
    // as one packet. Both leave from the continuation's origin: the light and the continuation are on
    // n's side (spawnShadowRay, spawnRay).
    F8 qx = px, qy = py, qz = pz;
    offsetRayOrigins(qx, qy, qz, nx, ny, nz, scale);
    F8 ulx{}, uly{};
    for (int k = 0; k < kLanes; ++k)
      if (alive_[k]) {
        const glm::vec2 u = numbers_[k]->lightPoint();
        ulx[k] = u.x, uly[k] = u.y;
      }
    LightLanes lights;
    sampleLights(px, py, pz, ulx, uly, lights);
    // With joins, the lanes that sample their light lane by lane weigh through the tracer's own code,
    // at their vertex's SurfaceHit and BSDF.
    if (connections_)
      for (int k = 0; k < kLanes; ++k) {
        joinsHere_[k] = alive_[k] && !connections_->empty() && depth_[k] + 2 <= settings_.maxDepth &&
                        connections_->joinsAt(depth_[k]);
        if (joinsHere_[k]) {  // picked now: next-event estimation's shadow rays hide their fetch (radiance())
          const int joins = connections_->joinsPerVertex();
          const float uJoin = numbers_[k]->connectionChoice();
          for (int j = 0; j < joins; ++j) {
            joinTo_[k][j] = &connections_->pick((float(j) + uJoin) / float(joins), joinScale_[k][j]);
            for (size_t line = 0; line < sizeof(LightVertex); line += 64)
              __builtin_prefetch(reinterpret_cast<const char*>(joinTo_[k][j]) + line);
          }
        }
        if (alive_[k] && !lights.served[k]) {
          clearUpperHalves();
          surfaces_[k] = hitSurface(k, px, py, pz, nx, ny, nz, sx, sy, sz, scale, rh.hit.geomID[k], rh.hit.primID[k]);
          bsdfs_[k].emplace(scene_.bsdf(surfaces_[k], wo(k)));
        }
      }
    alignas(32) RTCRay8 shadow;
    alignas(32) int tested[kLanes];
    glm::vec3 contribution[kLanes];
    float arrival[kLanes];
    uint32_t slot[kLanes];
    int shadows = 0;
    for (int k = 0; k < kLanes; ++k) {
      tested[k] = 0;
      if (!alive_[k] || lights.served[k]) continue;
      clearUpperHalves();
      const glm::vec3 p(px[k], py[k], pz[k]), n(nx[k], ny[k], nz[k]), ns(sx[k], sy[k], sz[k]);
      VertexSamples& u = *numbers_[k];
      const auto lightChoice = [&] { return u.lightChoice(); };
      const glm::vec2 uLight(ulx[k], uly[k]);
      const auto ls = guide_ ? guide_->sample(p, uLight, lightChoice) : emitters_.sampleStratified(p, uLight, lightChoice);
      if (!ls) continue;
      // The light must be above the surface; the Lambertian lobe's eval and pdf (Bsdf::eval, Bsdf::pdf)
      // take the cosines with its frame's normal, the shading normal.
      const float cosReceiver = glm::dot(ls->wi, n);
      if (!(cosReceiver > 0.0f)) continue;
      const float cosIn = glm::dot(ls->wi, ns), cosOutgoing = -(dx_[k] * ns.x + dy_[k] * ns.y + dz_[k] * ns.z);
      if (cosOutgoing <= 0.0f || cosIn <= 0.0f) continue;
      const glm::vec3 f = glm::vec3(ar[k], ag[k], ab[k]) * kInvPiF * cosIn;
      if (isBlack(f)) continue;
      if (guide_) guide_->attempted(ls->guideSlot);
      SurfaceHit from;
      from.position = p, from.geometricNormal = n, from.coordinateScale = scale[k];
      const Ray r = spawnShadowRay(from, ls->wi, ls->distance);
      shadow.org_x[k] = r.origin.x, shadow.org_y[k] = r.origin.y, shadow.org_z[k] = r.origin.z;
      shadow.dir_x[k] = r.direction.x, shadow.dir_y[k] = r.direction.y, shadow.dir_z[k] = r.direction.z;
      shadow.tfar[k] = r.tMax;
      const float w = connections_ ? lanes_.tracer_.nextEventWeight(*ls, surfaces_[k], *bsdfs_[k], wo(k),
                                                                    depth_[k], sums(k), bsdfContinuation_)
                    : ls->delta ? 1.0f : powerHeuristic(ls->pdf, cosineHemispherePdf(cosIn));
      contribution[k] = f * ls->radiance * (w / ls->pdf);
      arrival[k] = luminance(ls->radiance) * cosReceiver / ls->pdf;
      slot[k] = ls->guideSlot;
      tested[k] = -1;
    }
    if (any(lights.found)) {
      // The same as above, in lanes: the receiver's side and cosines, the lobe, the shadow ray
      // (spawnShadowRay: aimed at the light point, stopped short by its margin), the MIS weight.
      const F8 wx = lights.wx, wy = lights.wy, wz = lights.wz;
      const F8 cosIn = wx * sx + wy * sy + wz * sz, cosOutgoing = -(dx_ * sx + dy_ * sy + dz_ * sz);
      const F8 fr = ar * kInvPiF * cosIn, fg = ag * kInvPiF * cosIn, fb = ab * kInvPiF * cosIn;
      const I8 lit = lights.found & (wx * nx + wy * ny + wz * nz > 0.0f) & (cosOutgoing > 0.0f) & (cosIn > 0.0f) &
                     ((fr > 0.0f) | (fg > 0.0f) | (fb > 0.0f));
      F8 sdx, sdy, sdz, tMax;
      aimShadowRay(px, py, pz, qx, qy, qz, wx, wy, wz, lights.distance, sdx, sdy, sdz, tMax,
                   [](const F8& v, F8& root) { root = sqrt8(v); });
      const F8 bsdfPdf = cosIn * kInvPi, a = lights.pdf * lights.pdf, b = bsdfPdf * bsdfPdf;
      F8 weight = a + b > 0.0f ? a / (a + b) : F8{};
      if (connections_) {
        // PathTracer::nextEventWeight: against the continuation (the BSDF's density) and against the
        // light paths that start at the light point and shift along the camera side (the partial sums).
        const F8 toLight = bsdfPdf / lights.pdf;
        const F8 reverse = cosOutgoing * kInvPiF;  // Bsdf::pdf(wi, wo): both cosines are positive here
        const F8 cameraSide = dVCM_ + (dVC_ > 0.0f ? dVC_ * (reverse * reverse) : F8{});
        const F8 cosCamera = abs8(wx * nx + wy * ny + wz * nz);
        const F8 shift = lights.emissionPdf * cosCamera / (lights.pdf * lights.cosLight);
        const F8 others = toLight * toLight + (cameraSide > 0.0f ? shift * shift * cameraSide : F8{});
        weight = bidirectionalWeight8(others);
      }
      const F8 share = weight / lights.pdf;
      for (int k = 0; k < kLanes; ++k) {
        if (!lit[k]) continue;
        shadow.org_x[k] = qx[k], shadow.org_y[k] = qy[k], shadow.org_z[k] = qz[k];
        shadow.dir_x[k] = sdx[k], shadow.dir_y[k] = sdy[k], shadow.dir_z[k] = sdz[k];
        shadow.tfar[k] = tMax[k];
        contribution[k] = glm::vec3(fr[k], fg[k], fb[k]) * glm::vec3(lights.r[k], lights.g[k], lights.b[k]) * share[k];
        slot[k] = UINT32_MAX;
        tested[k] = -1;
      }
    }
    for (int k = 0; k < kLanes; ++k)
      if (tested[k]) {
        shadow.tnear[k] = 0.0f, shadow.time[k] = 0.0f;
        shadow.mask[k] = ~0u, shadow.id[k] = 0, shadow.flags[k] = 0;
        ++shadows;
      }
    stats_.rays += uint64_t(shadows);
    if (shadows > 0) {
      rtcOccluded8(tested, handle, &context, &shadow);
      for (int k = 0; k < kLanes; ++k) {
        if (!tested[k] || !(shadow.tfar[k] >= 0.0f)) continue;  // Embree sets tfar to -inf on a hit
        if (guide_ && slot[k] != UINT32_MAX) guide_->arrived(slot[k], arrival[k]);
        L_[k] += beta(k) * contribution[k];
      }
    }
    if (connections_) join(handle, context, {px, py, pz, nx, ny, nz, sx, sy, sz, ar, ag, ab, qx, qy, qz});

    // A split's other branches, each with its own numbers, traced after this path in radiance()'s order.
    for (int k = 0; k < kLanes; ++k)
      if (alive_[k] && split[k] > 1) {
        clearUpperHalves();
        branch(k, split[k], hitSurface(k, px, py, pz, nx, ny, nz, sx, sy, sz, scale, rh.hit.geomID[k], rh.hit.primID[k]));
      }

    // The continuation: Bsdf::sampleLambertian (sampleCosineHemisphere in the frame of n) in lanes.
    const F8 u0 = min8(uDir0, splat(0x1.fffffep-1f));
    const F8 ox = 2.0f * u0 - 1.0f, oy = 2.0f * uDir1 - 1.0f;
    const I8 centre = (ox == 0.0f) & (oy == 0.0f);
    const I8 aboutX = abs8(ox) > abs8(oy);
    const F8 radius = aboutX ? ox : oy;
    const F8 safeRadius = centre ? splat(1.0f) : radius;
    F8 s, c;
    fast::sinCosOctant(0.25f * std::numbers::pi_v<float> * ((aboutX ? oy : ox) / safeRadius), s, c);
    const F8 lx = centre ? F8{} : radius * (aboutX ? c : s), ly = centre ? F8{} : radius * (aboutX ? s : c);
    const F8 z = sqrt8(max8(F8{}, 1.0f - lx * lx - ly * ly));
    const I8 sampled = alive_ & (z > 0.0f) & (dx_ * sx + dy_ * sy + dz_ * sz < 0.0f);  // and wo above the lobe
    stats_.bsdfSamples += uint64_t(count(sampled));
    // Frame::fromNormal of the shading normal (Duff et al.): the sign is copysign(1, n.z).
    const F8 sign = F8((I8(sz) & int32_t(0x80000000)) | I8(splat(1.0f)));
    const F8 a = -1.0f / (sign + sz), b = sx * sy * a;
    const F8 ux = 1.0f + sign * sx * sx * a, uy = sign * b, uz = -sign * sx;
    const F8 vx = b, vy = sign + sy * sy * a, vz = -sy;
    F8 wx = ux * lx + vx * ly + sx * z, wy = uy * lx + vy * ly + sy * z, wz = uz * lx + vz * ly + sz * z;
    const F8 inverseLength = 1.0f / sqrt8(wx * wx + wy * wy + wz * wz);
    wx *= inverseLength, wy *= inverseLength, wz *= inverseLength;
    const I8 reflects = (max8(ar, max8(ag, ab)) > 0.0f) & (wx * nx + wy * ny + wz * nz > 0.0f);
    br_ *= ar, bg_ *= ag, bb_ *= ab;
    const F8 largest = max8(br_, max8(bg_, bb_));
    const I8 finite = (br_ >= 0.0f) & (bg_ >= 0.0f) & (bb_ >= 0.0f) & (largest < INFINITY);
    end(alive_ & ~(sampled & reflects & finite));

    // Russian roulette on the throughput, by radiance()'s rule.
    const I8 rolls = alive_ & ~windowed & (depth_ + 1 >= settings_.rrStartDepth);
    if (any(rolls)) {
      const F8 survive = min8(splat(1.0f), settings_.roulette == RouletteRule::Throughput ? largest : sqrt8(largest));
      I8 killed{};
      for (int k = 0; k < kLanes; ++k)
        if (rolls[k] && numbers_[k]->roulette() >= survive[k]) killed[k] = -1;
      const F8 divisor = rolls ? survive : splat(1.0f);
      br_ /= divisor, bg_ /= divisor, bb_ /= divisor;
      end(killed);
    }

    if (connections_) {
      // PathTracer::MisSums::advance for the Lambertian lobe: the sample's density, and the reverse
      // one (Bsdf::pdf(wi, wo), wo's cosine with the shading normal).
      const F8 pdf = z * kInvPiF, reverse = -(dx_ * sx + dy_ * sy + dz_ * sz) * kInvPiF;
      const F8 cosOut = abs8(wx * nx + wy * ny + wz * nz) / pdf, inverse = 1.0f / pdf;
      dVC_ = alive_ ? cosOut * cosOut * (dVC_ * (reverse * reverse) + dVCM_) : dVC_;
      dVCM_ = alive_ ? inverse * inverse : dVCM_;
    }

    // spawnRay: leave by the side the direction points to (the normal's: it was tested above).
    prevX_ = px, prevY_ = py, prevZ_ = pz;
    prevPdf_ = alive_ ? z * kInvPiF : prevPdf_;
    ox_ = alive_ ? qx : ox_, oy_ = alive_ ? qy : oy_, oz_ = alive_ ? qz : oz_;
    dx_ = alive_ ? wx : dx_, dy_ = alive_ ? wy : dy_, dz_ = alive_ ? wz : dz_;
    tMax_ = alive_ ? splat(INFINITY) : tMax_;
    depth_ += alive_ & 1;
  }

  // The SurfaceHit of lane k's hit, for the scalar calls that take one.
  SurfaceHit hitSurface(int k, F8 px, F8 py, F8 pz, F8 nx, F8 ny, F8 nz, F8 sx, F8 sy, F8 sz, F8 scale, uint32_t mesh,
                        uint32_t triangle) const {
    SurfaceHit s;
    s.position = glm::vec3(px[k], py[k], pz[k]);
    s.geometricNormal = glm::vec3(nx[k], ny[k], nz[k]);
    s.shadingNormal = glm::vec3(sx[k], sy[k], sz[k]);
    s.mesh = mesh, s.triangle = triangle, s.material = scene_.data().meshes[mesh].material;
    s.frontFace = frontFace_[k];
    s.coordinateScale = scale[k];
    return s;
  }

  // An emitter hit, weighed against next-event estimation from the previous vertex; returns what the
  // emitter sends (luminance), before the weight.
  float emitterHit(int k, const SurfaceHit& surface) {
    const glm::vec3 le = emitters_.emitted(surface, wo(k));
    if (isBlack(le)) return 0.0f;
    const PathTracer::PathPoint at{int(depth_[k]), glm::vec3(prevX_[k], prevY_[k], prevZ_[k]), prevPdf_[k]};
    L_[k] += beta(k) * le * lanes_.tracer_.emitterHitWeight(surface, wo(k), at, sums(k));
    return luminance(le);
  }

  // Splits lane k's path at `surface` into `split` branches: the split - 1 others are drawn and kept
  // for later (sampleContinuation of radiance(), with the branch's own numbers), the lane's own weight
  // shrinks to its share.
  void branch(int k, int split, const SurfaceHit& surface) {
    const glm::vec3 wo = this->wo(k);
    const Bsdf bsdf = scene_.bsdf(surface, wo);
    const glm::vec3 share = beta(k) / float(split);
    for (int b = 1; b < split; ++b) {
      Branch next{Ray{}, glm::vec3(0.0f), surface.position, 0.0f, depth_[k] + 1, samplers_[k]->branch(nextBranchId_[k]++), sums(k)};
      VertexSamples u(next.sampler, depth_[k]);
      const auto s = bsdf.sample(wo, u.bsdfDirection());
      if (!s || !(s->pdf > 0.0f)) continue;
      ++stats_.bsdfSamples;
      if (isBlack(s->weight) || !(glm::dot(s->wi, surface.geometricNormal) > 0.0f)) continue;
      next.beta = share * s->weight;
      if (!isFiniteNonNegative(next.beta)) continue;
      if (connections_) next.mis.advance(depth_[k], surface, bsdf, wo, DirectionSample{s->wi, s->pdf, s->weight});
      next.ray = spawnRay(surface, s->wi);
      next.previousPdf = s->pdf;
      pending_[k].push_back(next);
      --branchesLeft_[k];
      ++stats_.branches;
    }
    br_[k] = share.x, bg_[k] = share.y, bb_[k] = share.z;
  }

  // The vertex that joins, in lanes: bounce()'s hit, its normals (geometric, shading), its albedo, and
  // the origin of the rays that leave it on the geometric normal's side.
  struct JoiningVertex {
    const F8 &px, &py, &pz, &nx, &ny, &nz, &sx, &sy, &sz, &ar, &ag, &ab, &qx, &qy, &qz;
  };

  // Joins of every live lane's vertex to light vertices (radiance()'s, with its numbers and order): the
  // n-th join of each lane in one packet of shadow rays, the packets in turn, as the shadow roulette
  // weighs a join against what its sample holds after the joins before it. PathTracer::unoccludedJoin
  // in vector form, for Lambertian lobes at both ends (every material is, where the lanes apply): each
  // end's f and densities are its albedo and cosines (Bsdf::evalPdf, Bsdf::pdf).
  void join(RTCScene handle, RTCIntersectContext& context, const JoiningVertex& v) {
    if (connections_->empty()) return;
    const int joins = connections_->joinsPerVertex(), limit = connections_->joinDepth();
    // What every join from here shares: wo's cosine with the shading normal, the camera side's sum
    // with its reverse density (Bsdf::pdf(w, wo)).
    const F8 cosOutgoing = -(dx_ * v.sx + dy_ * v.sy + dz_ * v.sz);
    const F8 reverseCamera = cosOutgoing * kInvPiF;
    const F8 cameraSide = dVCM_ + (dVC_ > 0.0f ? dVC_ * (reverseCamera * reverseCamera) : F8{});
    for (int j = 0; j < joins; ++j) {
      // Light vertex j of each joining lane, gathered: position, normals, its f towards the light path
      // (its albedo over pi by wIn's cosine, times alpha), the light side's sum at its density.
      F8 yx{}, yy{}, yz{}, gx{}, gy{}, gz{}, tx{}, ty{}, tz{}, lr{}, lg{}, lb{}, lightSide{}, factor = splat(1.0f), scale{};
      I8 candidate{};
      for (int k = 0; k < kLanes; ++k) {
        if (!alive_[k] || !joinsHere_[k]) continue;
        const LightVertex& y = *joinTo_[k][j];
        if (depth_[k] + 1 + y.length > settings_.maxDepth) continue;
        const glm::vec3& ns = y.bsdf.frame().n;
        const float cosIn = glm::dot(y.wIn, ns);
        if (!(cosIn > 0.0f)) continue;
        const glm::vec3 f = y.bsdf.params().diffuse * kInvPiF * cosIn * y.alpha;
        candidate[k] = -1;
        yx[k] = y.position.x, yy[k] = y.position.y, yz[k] = y.position.z;
        gx[k] = y.normal.x, gy[k] = y.normal.y, gz[k] = y.normal.z;
        tx[k] = ns.x, ty[k] = ns.y, tz[k] = ns.z;
        lr[k] = f.x, lg[k] = f.y, lb[k] = f.z;
        lightSide[k] = LightVertexCache::lightSideSum(y, int(depth_[k]), cosIn * kInvPiF, limit);
        factor[k] = connections_->misFactor(y);
        scale[k] = joinScale_[k][j];
      }
      if (!any(candidate)) continue;
      const F8 ex = yx - v.px, ey = yy - v.py, ez = yz - v.pz;
      const F8 dist2 = ex * ex + ey * ey + ez * ez, dist = sqrt8(dist2);
      const F8 wx = ex / dist, wy = ey / dist, wz = ez / dist;
      const F8 cosCamera = wx * v.nx + wy * v.ny + wz * v.nz, cosLight = -(wx * gx + wy * gy + wz * gz);
      const F8 cosIn = wx * v.sx + wy * v.sy + wz * v.sz, cosLightOut = -(wx * tx + wy * ty + wz * tz);
      const F8 fr = v.ar * kInvPiF * cosIn, fg = v.ag * kInvPiF * cosIn, fb = v.ab * kInvPiF * cosIn;
      // Both lobes' densities: the camera's towards y (the continuation's, BSDF sampling's), y's
      // reverse one towards the camera vertex (Bsdf::pdf(wIn, -w)), each in area measure at the other end.
      const F8 toLight = cosIn * kInvPiF * cosLight / dist2, toCamera = cosLightOut * kInvPiF * cosCamera / dist2;
      const F8 others = (toLight * toLight * lightSide + (cameraSide > 0.0f ? toCamera * toCamera * cameraSide : F8{})) / factor;
      const F8 weight = bidirectionalWeight8(others);
      const I8 joinable = candidate & (dist2 > 0.0f) & (cosCamera > 0.0f) & (cosLight > 0.0f) & (cosOutgoing > 0.0f) &
                          (cosIn > 0.0f) & (cosLightOut > 0.0f) & ((fr > 0.0f) | (fg > 0.0f) | (fb > 0.0f)) &
                          ((lr > 0.0f) | (lg > 0.0f) | (lb > 0.0f)) & (weight > 0.0f);
      if (!any(joinable)) continue;
      const F8 amount = cosLight / dist2 * scale * weight;
      const F8 jr = br_ * (fr * lr * amount), jg = bg_ * (fg * lg * amount), jb = bb_ * (fb * lb * amount);
      F8 sdx, sdy, sdz, tMax;
      aimShadowRay(v.px, v.py, v.pz, v.qx, v.qy, v.qz, wx, wy, wz, dist, sdx, sdy, sdz, tMax,
                   [](const F8& x, F8& root) { root = sqrt8(x); });
      alignas(32) RTCRay8 shadow;
      alignas(32) int tested[kLanes];
      glm::vec3 joined[kLanes];
      int rays = 0;
      for (int k = 0; k < kLanes; ++k) {
        tested[k] = 0;
        if (!joinable[k]) continue;
        joined[k] = glm::vec3(jr[k], jg[k], jb[k]);
        if (isBlack(joined[k])) continue;
        if (const float share = connections_->shadowRoulette(); share > 0.0f) {
          const float c = luminance(joined[k]), threshold = share * luminance(L_[k]);
          if (c < threshold) {
            const float survival = std::max(c / threshold, ConnectionSettings::kMinShadowSurvival);
            if (numbers_[k]->random().uniform() >= survival) continue;
            joined[k] /= survival;
          }
        }
        shadow.org_x[k] = v.qx[k], shadow.org_y[k] = v.qy[k], shadow.org_z[k] = v.qz[k];
        shadow.dir_x[k] = sdx[k], shadow.dir_y[k] = sdy[k], shadow.dir_z[k] = sdz[k];
        shadow.tnear[k] = 0.0f, shadow.tfar[k] = tMax[k], shadow.time[k] = 0.0f;
        shadow.mask[k] = ~0u, shadow.id[k] = 0, shadow.flags[k] = 0;
        tested[k] = -1;
        ++rays;
      }
      if (rays == 0) continue;
      stats_.rays += uint64_t(rays);
      rtcOccluded8(tested, handle, &context, &shadow);
      for (int k = 0; k < kLanes; ++k) {
        if (!tested[k] || !(shadow.tfar[k] >= 0.0f)) continue;
        connections_->record(*joinTo_[k][j], luminance(joined[k]));
        L_[k] += joined[k];
      }
    }
  }

  // Lane k's ray left the scene: the sky, weighed against next-event estimation of the sky.
  void escape(int k) {
    if (!emitters_.hasSky()) return;
    float w = 1.0f;
    if (depth_[k] > 0) {
      const glm::vec3 previous(prevX_[k], prevY_[k], prevZ_[k]), d(dx_[k], dy_[k], dz_[k]);
      w = powerHeuristic(prevPdf_[k], guide_ ? guide_->pdfSky(previous, d) : emitters_.pdfSky(d));
    }
    L_[k] += beta(k) * emitters_.sky() * w;
  }

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

void PathLanes::renderTile(const Camera& camera, uint64_t seed, uint64_t pass, int x0, int y0, int x1, int y1, Film& film,
                           PathStats& stats, uint64_t& discarded) const {
  Batch(*this, camera, seed, pass, x0, y0, x1, y1, film, stats, discarded).run();
}

#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

}  // namespace vpl
