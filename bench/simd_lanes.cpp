// Where a brdf sample's time goes, and what shading eight paths at once in AVX2 lanes would save
// (issue 15: 1.5x Cycles' samples/s). A bound before any rewrite: the estimator of `--mode brdf`
// reduced to what a Lambertian, untextured scene lit by emitting triangles needs (next-event
// estimation with the power heuristic, cosine-weighted continuations, square-root roulette from
// depth 5, depth 32), written once over a lane count N, run with N = 1 (rtcIntersect1, scalar
// arithmetic) and N = 8 (rtcIntersect8 / rtcOccluded8, AVX2 arithmetic), lanes refilled with new
// samples as paths end, as a wavefront tracer would. "Lean" leaves out four parts of radiance():
// its stratified numbers (a hash per decision instead), its emitter sampling (by area instead of
// spherical triangles), its SurfaceHit and Bsdf objects (flat arrays and an inline Lambertian lobe)
// and its ray offsets (a fixed one). The 1-lane rows put them back one at a time, up to the whole
// estimator of radiance() (the same image mean, to every printed digit); the 8-lane rows are the
// lean estimator and the one with the renderer's numbers and emitter sampling (per lane: scalar).
// Single-threaded. Usage: simd_lanes SCENE [WIDTH HEIGHT PASSES ROUNDS]
#include <immintrin.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <optional>
#include <numbers>
#include <vector>
#include <embree3/rtcore.h>
#include "render/core/color.h"
#include "render/integrator/path_tracer.h"
#include "render/sampling/lane_sobol.h"
#include "render/sampling/pixel_sampler.h"
#include "render/scene/camera.h"
#include "render/scene/gltf_loader.h"

using namespace vpl;

namespace {

constexpr int kMaxDepth = 32, kRouletteStart = 5;
constexpr uint64_t kSeed = 1;
constexpr float kInvPiF = std::numbers::inv_pi_v<float>;

// What a hit needs of its triangle, flattened over all meshes (index: meshBase[mesh] + primitive).
struct FlatScene {
  std::vector<uint32_t> meshBase;
  std::vector<float> nx, ny, nz;            // unit winding normal
  std::vector<float> fr, fg, fb;            // Lambertian f = albedo / pi
  std::vector<float> er, eg, eb;            // emitted radiance
  std::vector<float> lightPdfArea;          // choice probability / area; 0 where nothing is emitted
  std::vector<uint8_t> twoSided;
  std::vector<uint32_t> lights;             // emitting triangles
  std::vector<float> lightCdf;              // by power, lights.size() + 1 entries
  std::vector<glm::vec3> v0, e1, e2;        // per light
  float offset = 1e-4f;                     // ray origins move this far along the normal

  // Null when the scene needs more than this estimator models.
  static const char* unsupported(const SceneData& d) {
    if (!d.lights.empty()) return "punctual lights";
    for (const Material& m : d.materials)
      if (m.hasTextures() || m.metallic > 0.0f || (m.specularFactor > 0.0f) || m.alphaMode != AlphaMode::Opaque)
        return "a material that is not Lambertian and untextured";
    return nullptr;
  }

  explicit FlatScene(const SceneData& d) {
    double total = 0.0;
    std::vector<double> power;
    for (const MeshData& mesh : d.meshes) {
      meshBase.push_back(uint32_t(nx.size()));
      const Material& m = d.materials[mesh.material];
      for (size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
        const glm::vec3 a = mesh.positions[mesh.indices[i]], b = mesh.positions[mesh.indices[i + 1]],
                        c = mesh.positions[mesh.indices[i + 2]];
        const glm::vec3 cr = glm::cross(b - a, c - a);
        const float len = glm::length(cr);
        const glm::vec3 n = len > 0.0f ? cr / len : glm::vec3(0, 0, 1);
        nx.push_back(n.x), ny.push_back(n.y), nz.push_back(n.z);
        fr.push_back(m.baseColor.x * kInvPiF), fg.push_back(m.baseColor.y * kInvPiF), fb.push_back(m.baseColor.z * kInvPiF);
        er.push_back(m.emission.x), eg.push_back(m.emission.y), eb.push_back(m.emission.z);
        twoSided.push_back(m.doubleSided);
        lightPdfArea.push_back(0.0f);
        const double p = double(luminance(m.emission)) * 0.5 * len * (m.doubleSided ? 2.0 : 1.0);
        if (p > 0.0) {
          lights.push_back(uint32_t(nx.size() - 1));
          power.push_back(p);
          total += p;
          v0.push_back(a), e1.push_back(b - a), e2.push_back(c - a);
        }
      }
    }
    lightCdf.push_back(0.0f);
    double sum = 0.0;
    for (size_t i = 0; i < lights.size(); ++i) {
      sum += power[i];
      lightCdf.push_back(float(sum / total));
      const float area = 0.5f * glm::length(glm::cross(e1[i], e2[i]));
      lightPdfArea[lights[i]] = float(power[i] / total) / area;
    }
    lightCdf.back() = 1.0f;
    const glm::vec3 extent = glm::max(glm::abs(d.boundsMin), glm::abs(d.boundsMax));
    offset = 2e-5f * std::max({extent.x, extent.y, extent.z, 1e-3f});
  }
};

// One 32-bit hash of a key (lowbias32, Wellons), the random numbers of this bench.
template <class U>
inline U hash32(U x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

// GCC's vector types, spelled out per lane count (a size that depends on a template parameter drops
// the attribute).
template <int N>
struct VectorTypes;
template <>
struct VectorTypes<1> {
  typedef float F __attribute__((vector_size(4)));
  typedef int32_t I __attribute__((vector_size(4)));
  typedef uint32_t U __attribute__((vector_size(4)));
  typedef uint64_t U64 __attribute__((vector_size(8)));
};
template <>
struct VectorTypes<8> {
  typedef float F __attribute__((vector_size(32)));
  typedef int32_t I __attribute__((vector_size(32)));
  typedef uint32_t U __attribute__((vector_size(32)));
  typedef uint64_t U64 __attribute__((vector_size(64)));
};

template <int N>
struct Lanes {
  using F = typename VectorTypes<N>::F;
  using I = typename VectorTypes<N>::I;
  using U = typename VectorTypes<N>::U;

  static F splat(float x) { return F{} + x; }
  static F sqrt(F x) {
    if constexpr (N == 8) {
      return F(_mm256_sqrt_ps(__m256(x)));
    } else {
      F r;
      for (int k = 0; k < N; ++k) r[k] = std::sqrt(x[k]);
      return r;
    }
  }
  static F min(F a, F b) { return a < b ? a : b; }
  static F max(F a, F b) { return a > b ? a : b; }
  static F abs(F a) { return a < 0.0f ? -a : a; }
  static F unit(U bits) { return __builtin_convertvector(bits >> 8, F) * 0x1p-24f; }
  // The random number of decision `dim` of each lane's sample.
  static F uniform(U key, uint32_t dim) { return unit(hash32(key ^ (dim * 0x9e3779b9u))); }
  static bool any(I m) {
    for (int k = 0; k < N; ++k)
      if (m[k]) return true;
    return false;
  }
  template <class T>
  static F gather(const std::vector<T>& v, U index) {
    F r;
    for (int k = 0; k < N; ++k) r[k] = float(v[index[k]]);
    return r;
  }
  // sin and cos of 2 pi u: a quarter turn's polynomial, rotated into the quadrant.
  static void sinCos2Pi(F u, F& s, F& c) {
    const F t = u * 4.0f;
    const I q = __builtin_convertvector(t, I);  // t >= 0: truncation is floor
    const F x = (t - __builtin_convertvector(q, F)) * (std::numbers::pi_v<float> / 2.0f) - std::numbers::pi_v<float> / 4.0f;
    // sin and cos of x in [-pi/4, pi/4], then of x + pi/4 by the sum formula.
    const F z = x * x;
    const F sx = x + x * z * (-0.16666659411f + z * (0.0083324080842f + z * -0.00019543791327f));
    const F cx = 1.0f - 0.5f * z + z * z * (0.041666646866f + z * (-0.0013887367487f + z * 2.4438448729e-05f));
    const float h = std::numbers::sqrt2_v<float> / 2.0f;
    const F s0 = (sx + cx) * h, c0 = (cx - sx) * h;
    const I quadrant = q & 3;
    s = quadrant == 0 ? s0 : quadrant == 1 ? c0 : quadrant == 2 ? -s0 : -c0;
    c = quadrant == 0 ? c0 : quadrant == 1 ? -s0 : quadrant == 2 ? -c0 : s0;
  }
};

// The lanes' paths and their traversal, N at a time.
template <int N>
class Wavefront {
  using L = Lanes<N>;
  using F = typename L::F;
  using I = typename L::I;
  using U = typename L::U;

 public:
  // The two parts of radiance() that the lean estimator leaves out, each switchable: `sobol`, the
  // renderer's stratified numbers (PixelSampler, per lane) instead of a hash; `solidAngle`, its
  // emitter sampling (EmitterSet::sampleStratified and pdfTriangle, per lane) instead of by area.
  // `framework`, per lane, cumulative: 1 the hit's SurfaceHit (RenderScene::surface) instead of the
  // flat arrays, 2 its Bsdf object instead of an inline Lambertian lobe, 3 the renderer's ray offsets
  // (spawnRay, spawnShadowRay) instead of a fixed one. At 3 the estimator is radiance()'s.
  // `laneSobol` (with `sobol`): the stratified numbers of the first PixelSampler::kTabulatedVertices
  // vertices drawn for all lanes at once (render/sampling/lane_sobol.h), not lane by lane.
  Wavefront(const RenderScene& scene, const FlatScene& flat, const Camera& camera, bool sobol, bool solidAngle,
            int framework = 0, bool laneSobol = false)
      : scene_(scene.accel().handle()), renderScene_(scene), emitters_(scene.emitters()), flat_(flat), camera_(camera),
        sobol_(sobol), solidAngle_(solidAngle), framework_(framework), laneSobol_(laneSobol && sobol) {}

  // Every pixel's samples [0, passes); returns the sum of the samples' luminances.
  double render(int passes) {
    const uint64_t pixels = uint64_t(camera_.width()) * uint64_t(camera_.height());
    total_ = pixels * uint64_t(passes);
    next_ = 0;
    sum_ = 0.0;
    alive_ = I{};
    for (int k = 0; k < N; ++k) start(k);
    while (L::any(alive_)) {
      bounce();
      for (int k = 0; k < N; ++k)
        if (!alive_[k]) start(k);
    }
    return sum_;
  }

 private:
  // Lane k's path ended: count it, and begin the next sample if any is left.
  void start(int k) {
    if (finished_[k]) sum_ += double(0.2126f * Lr_[k] + 0.7152f * Lg_[k] + 0.0722f * Lb_[k]);
    finished_[k] = false;
    if (next_ >= total_) return;
    const uint64_t s = next_++;
    const uint64_t pixels = uint64_t(camera_.width()) * uint64_t(camera_.height());
    const uint32_t pixel = uint32_t(s % pixels), pass = uint32_t(s / pixels);
    key_[k] = hash32(pixel * 0x632be59bu ^ hash32(pass + 0x85ebca6bu));
    glm::vec2 jitter(L::unit(U{} + hash32(key_[k] ^ 0x1u))[0], L::unit(U{} + hash32(key_[k] ^ 0x2u))[0]);
    if (sobol_) {
      PixelSampler& sampler = samplers_[k].emplace(kSeed, pixel, pass);
      jitter = sampler.cameraJitter();
      pixelKey_[k] = sampler.pixelKey();  // for lane_sobol
      reversedIndex_[k] = sampler.reversedIndex();
    }
    const Ray r = camera_.generateRay(glm::vec2(float(pixel % uint32_t(camera_.width())), float(pixel / uint32_t(camera_.width()))) + jitter);
    ox_[k] = r.origin.x, oy_[k] = r.origin.y, oz_[k] = r.origin.z;
    dx_[k] = r.direction.x, dy_[k] = r.direction.y, dz_[k] = r.direction.z;
    br_[k] = bg_[k] = bb_[k] = 1.0f;
    Lr_[k] = Lg_[k] = Lb_[k] = 0.0f;
    depth_[k] = 0;
    prevPdf_[k] = 0.0f;
    alive_[k] = -1;
  }

  // Closest hits of the live lanes: distance (INFINITY for none) and global triangle index.
  void intersect(F& t, U& tri, U& mesh, U& prim, F& bu, F& bv) {
    if constexpr (N == 1) {
      RTCRayHit rh{};
      rh.ray.org_x = ox_[0], rh.ray.org_y = oy_[0], rh.ray.org_z = oz_[0];
      rh.ray.dir_x = dx_[0], rh.ray.dir_y = dy_[0], rh.ray.dir_z = dz_[0];
      rh.ray.tnear = 0.0f, rh.ray.tfar = INFINITY, rh.ray.mask = ~0u;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      rtcIntersect1(scene_, &context, &rh);
      const bool hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      t[0] = hit ? rh.ray.tfar : INFINITY;
      tri[0] = hit ? flat_.meshBase[rh.hit.geomID] + rh.hit.primID : 0u;
      mesh[0] = hit ? rh.hit.geomID : 0u, prim[0] = rh.hit.primID, bu[0] = rh.hit.u, bv[0] = rh.hit.v;
    } else {
      alignas(32) RTCRayHit8 rh;
      alignas(32) int valid[8];
      for (int k = 0; k < 8; ++k) {
        valid[k] = alive_[k];
        rh.ray.org_x[k] = ox_[k], rh.ray.org_y[k] = oy_[k], rh.ray.org_z[k] = oz_[k];
        rh.ray.dir_x[k] = dx_[k], rh.ray.dir_y[k] = dy_[k], rh.ray.dir_z[k] = dz_[k];
        rh.ray.tnear[k] = 0.0f, rh.ray.tfar[k] = INFINITY, rh.ray.time[k] = 0.0f;
        rh.ray.mask[k] = ~0u, rh.ray.id[k] = 0, rh.ray.flags[k] = 0;
        rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      }
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      rtcIntersect8(valid, scene_, &context, &rh);
      for (int k = 0; k < 8; ++k) {
        const bool hit = alive_[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
        t[k] = hit ? rh.ray.tfar[k] : INFINITY;
        tri[k] = hit ? flat_.meshBase[rh.hit.geomID[k]] + rh.hit.primID[k] : 0u;
        mesh[k] = hit ? rh.hit.geomID[k] : 0u, prim[k] = rh.hit.primID[k], bu[k] = rh.hit.u[k], bv[k] = rh.hit.v[k];
      }
    }
  }

  // Which of the shadow rays of lanes `test` arrive (not blocked within `dist`).
  I unoccluded(I test, F px, F py, F pz, F wx, F wy, F wz, F dist) {
    I arrives{};
    if constexpr (N == 1) {
      if (!test[0]) return arrives;
      RTCRay ray{};
      ray.org_x = px[0], ray.org_y = py[0], ray.org_z = pz[0];
      ray.dir_x = wx[0], ray.dir_y = wy[0], ray.dir_z = wz[0];
      ray.tnear = 0.0f, ray.tfar = dist[0], ray.mask = ~0u;
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      rtcOccluded1(scene_, &context, &ray);
      arrives[0] = ray.tfar >= 0.0f ? -1 : 0;
    } else {
      alignas(32) RTCRay8 ray;
      alignas(32) int valid[8];
      for (int k = 0; k < 8; ++k) {
        valid[k] = test[k];
        ray.org_x[k] = px[k], ray.org_y[k] = py[k], ray.org_z[k] = pz[k];
        ray.dir_x[k] = wx[k], ray.dir_y[k] = wy[k], ray.dir_z[k] = wz[k];
        ray.tnear[k] = 0.0f, ray.tfar[k] = dist[k], ray.time[k] = 0.0f;
        ray.mask[k] = ~0u, ray.id[k] = 0, ray.flags[k] = 0;
      }
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      rtcOccluded8(valid, scene_, &context, &ray);
      for (int k = 0; k < 8; ++k) arrives[k] = test[k] && ray.tfar[k] >= 0.0f ? -1 : 0;
    }
    return arrives;
  }

  // One vertex of every live lane: its hit, emission, light sample and continuation.
  void bounce() {
    F t;
    U tri, mesh, prim;
    F bu, bv;
    intersect(t, tri, mesh, prim, bu, bv);
    end(alive_ & (t == INFINITY));
    const I live = alive_;
    F px = ox_ + dx_ * t, py = oy_ + dy_ * t, pz = oz_ + dz_ * t;
    F nx = L::gather(flat_.nx, tri), ny = L::gather(flat_.ny, tri), nz = L::gather(flat_.nz, tri);
    const F dn = nx * dx_ + ny * dy_ + nz * dz_;
    const I front = dn < 0.0f;
    nx = front ? nx : -nx, ny = front ? ny : -ny, nz = front ? nz : -nz;  // towards the ray's origin
    SurfaceHit surface[N];
    std::optional<Bsdf> bsdf[N];
    if (framework_)
      for (int k = 0; k < N; ++k)
        if (live[k]) {
          Ray ray;
          ray.origin = glm::vec3(ox_[k], oy_[k], oz_[k]), ray.direction = glm::vec3(dx_[k], dy_[k], dz_[k]);
          RayHit hit;
          hit.t = t[k], hit.mesh = mesh[k], hit.triangle = prim[k], hit.u = bu[k], hit.v = bv[k];
          surface[k] = renderScene_.surface(ray, hit);
          px[k] = surface[k].position.x, py[k] = surface[k].position.y, pz[k] = surface[k].position.z;
          nx[k] = surface[k].geometricNormal.x, ny[k] = surface[k].geometricNormal.y, nz[k] = surface[k].geometricNormal.z;
          if (framework_ >= 2) bsdf[k].emplace(renderScene_.bsdf(surface[k], -ray.direction));
        }

    // An emitter hit, weighed against next-event estimation from the previous vertex.
    const I emits = live & (L::gather(flat_.lightPdfArea, tri) > 0.0f) & (front | (L::gather(flat_.twoSided, tri) > 0.5f));
    if (L::any(emits)) {
      F lightPdf = L::gather(flat_.lightPdfArea, tri) * t * t / L::abs(dn);
      if (solidAngle_)
        for (int k = 0; k < N; ++k)
          if (emits[k] && depth_[k] > 0) {
            SurfaceHit hit;
            hit.position = glm::vec3(px[k], py[k], pz[k]);
            hit.geometricNormal = hit.shadingNormal = glm::vec3(nx[k], ny[k], nz[k]);
            hit.mesh = mesh[k], hit.triangle = prim[k], hit.frontFace = front[k] != 0;
            lightPdf[k] = emitters_.pdfTriangle(glm::vec3(prevX_[k], prevY_[k], prevZ_[k]), hit);
          }
      const F p2 = prevPdf_ * prevPdf_;
      const F w = depth_ == 0 ? L::splat(1.0f) : p2 / (p2 + lightPdf * lightPdf);
      const F s = emits ? w : F{};
      Lr_ += br_ * L::gather(flat_.er, tri) * s, Lg_ += bg_ * L::gather(flat_.eg, tri) * s, Lb_ += bb_ * L::gather(flat_.eb, tri) * s;
    }
    end(live & (depth_ + 1 > kMaxDepth));
    if (!L::any(alive_)) return;
    const F fr = L::gather(flat_.fr, tri), fg = L::gather(flat_.fg, tri), fb = L::gather(flat_.fb, tri);
    const U key = key_ + U(depth_) * 0x27d4eb2fu;
    const F ox = px + nx * flat_.offset, oy = py + ny * flat_.offset, oz = pz + nz * flat_.offset;

    // The vertex's numbers: light point (and choice), direction, roulette.
    std::optional<VertexSamples> numbers[N];
    const I vertex = depth_;
    const auto scalarNumbers = [&](int k) -> VertexSamples& {
      return numbers[k] ? *numbers[k] : numbers[k].emplace(*samplers_[k], vertex[k]);
    };
    const U firstSlot = 2u + U(depth_) * uint32_t(VertexDimension::Count);  // PixelSampler::slotOf
    F uLight0, uLight1, uDir0, uDir1;
    if (laneSobol_) {
      lane_sobol::point(pixelKey_, reversedIndex_, firstSlot + uint32_t(VertexDimension::LightPoint), uLight0, uLight1);
      lane_sobol::point(pixelKey_, reversedIndex_, firstSlot + uint32_t(VertexDimension::BsdfDirection), uDir0, uDir1);
      for (int k = 0; k < N; ++k)  // past the tabulated vertices: the sampler's hashed numbers
        if (alive_[k] && depth_[k] >= PixelSampler::kTabulatedVertices) {
          const glm::vec2 a = scalarNumbers(k).lightPoint(), b = scalarNumbers(k).bsdfDirection();
          uLight0[k] = a.x, uLight1[k] = a.y, uDir0[k] = b.x, uDir1[k] = b.y;
        }
    } else if (sobol_) {
      for (int k = 0; k < N; ++k)
        if (alive_[k]) {
          VertexSamples& v = scalarNumbers(k);
          const glm::vec2 a = v.lightPoint(), b = v.bsdfDirection();
          uLight0[k] = a.x, uLight1[k] = a.y, uDir0[k] = b.x, uDir1[k] = b.y;
        }
    } else {
      uLight0 = L::uniform(key, 0), uLight1 = L::uniform(key, 1), uDir0 = L::uniform(key, 2), uDir1 = L::uniform(key, 3);
    }

    // Next-event estimation: towards a point of an emitting triangle.
    F wx, wy, wz, dist, lightPdf, ler, leg, leb;
    I test;
    if (solidAngle_) {
      test = I{};
      for (int k = 0; k < N; ++k) {
        if (!alive_[k]) continue;
        const auto ls = emitters_.sampleStratified(glm::vec3(px[k], py[k], pz[k]), glm::vec2(uLight0[k], uLight1[k]), [&] {
          return sobol_ ? scalarNumbers(k).lightChoice() : L::uniform(key, 5)[k];
        });
        if (!ls || !(ls->pdf > 0.0f)) continue;
        wx[k] = ls->wi.x, wy[k] = ls->wi.y, wz[k] = ls->wi.z, dist[k] = ls->distance, lightPdf[k] = ls->pdf;
        ler[k] = ls->radiance.x, leg[k] = ls->radiance.y, leb[k] = ls->radiance.z;
        test[k] = -1;
      }
      test &= (wx * nx + wy * ny + wz * nz) > 0.0f;
    } else {
      // A triangle by power (u.x rescaled within its share), a point on it by area.
      U light{};
      F lo{}, hi{};
      for (int k = 0; k < N; ++k) {
        const auto it = std::upper_bound(flat_.lightCdf.begin() + 1, flat_.lightCdf.end() - 1, uLight0[k]);
        const size_t i = size_t(it - flat_.lightCdf.begin()) - 1;
        light[k] = uint32_t(i);
        lo[k] = flat_.lightCdf[i], hi[k] = flat_.lightCdf[i + 1];
      }
      const F u0 = L::min((uLight0 - lo) / (hi - lo), L::splat(0x1.fffffep-1f));
      const F su = L::sqrt(u0), b1 = 1.0f - su, b2 = uLight1 * su;
      F vx, vy, vz, ax, ay, az, cx, cy, cz;
      U lightTri;
      for (int k = 0; k < N; ++k) {
        const uint32_t i = light[k];
        vx[k] = flat_.v0[i].x, vy[k] = flat_.v0[i].y, vz[k] = flat_.v0[i].z;
        ax[k] = flat_.e1[i].x, ay[k] = flat_.e1[i].y, az[k] = flat_.e1[i].z;
        cx[k] = flat_.e2[i].x, cy[k] = flat_.e2[i].y, cz[k] = flat_.e2[i].z;
        lightTri[k] = flat_.lights[i];
      }
      const F lnx = L::gather(flat_.nx, lightTri), lny = L::gather(flat_.ny, lightTri), lnz = L::gather(flat_.nz, lightTri);
      wx = vx + ax * b1 + cx * b2 - px, wy = vy + ay * b1 + cy * b2 - py, wz = vz + az * b1 + cz * b2 - pz;
      const F d2 = wx * wx + wy * wy + wz * wz;
      dist = L::sqrt(d2);
      wx /= dist, wy /= dist, wz /= dist;
      const F cosLightSigned = -(wx * lnx + wy * lny + wz * lnz);
      const F cosLight = L::gather(flat_.twoSided, lightTri) > 0.5f ? L::abs(cosLightSigned) : cosLightSigned;
      test = alive_ & ((wx * nx + wy * ny + wz * nz) > 0.0f) & (cosLight > 0.0f) & (d2 > 0.0f);
      lightPdf = L::gather(flat_.lightPdfArea, lightTri) * d2 / cosLight;
      ler = L::gather(flat_.er, lightTri), leg = L::gather(flat_.eg, lightTri), leb = L::gather(flat_.eb, lightTri);
    }
    if (framework_ >= 2 && L::any(test)) {
      F sx{}, sy{}, sz{}, sdx{}, sdy{}, sdz{}, tMax{}, cr{}, cg{}, cb{};
      for (int k = 0; k < N; ++k) {
        if (!test[k]) continue;
        const glm::vec3 wi(wx[k], wy[k], wz[k]), wo(-dx_[k], -dy_[k], -dz_[k]);
        const glm::vec3 f = bsdf[k]->eval(wo, wi);
        const float bsdfPdf = bsdf[k]->pdf(wo, wi);
        const glm::vec3 c = f * glm::vec3(ler[k], leg[k], leb[k]) * (lightPdf[k] / (lightPdf[k] * lightPdf[k] + bsdfPdf * bsdfPdf));
        cr[k] = c.x, cg[k] = c.y, cb[k] = c.z;
        Ray shadow;
        if (framework_ >= 3) {
          shadow = spawnShadowRay(surface[k], wi, dist[k]);
        } else {
          shadow.origin = glm::vec3(ox[k], oy[k], oz[k]), shadow.direction = wi, shadow.tMax = dist[k] * (1.0f - 1e-4f);
        }
        sx[k] = shadow.origin.x, sy[k] = shadow.origin.y, sz[k] = shadow.origin.z;
        sdx[k] = shadow.direction.x, sdy[k] = shadow.direction.y, sdz[k] = shadow.direction.z, tMax[k] = shadow.tMax;
      }
      const I arrives = unoccluded(test, sx, sy, sz, sdx, sdy, sdz, tMax);
      Lr_ += arrives ? br_ * cr : F{}, Lg_ += arrives ? bg_ * cg : F{}, Lb_ += arrives ? bb_ * cb : F{};
    } else if (L::any(test)) {
      const I arrives = unoccluded(test, ox, oy, oz, wx, wy, wz, dist * (1.0f - 1e-4f));
      const F cosSurface = wx * nx + wy * ny + wz * nz;
      const F bsdfPdf = cosSurface * kInvPiF;
      const F l2 = lightPdf * lightPdf;
      const F s = arrives ? cosSurface * lightPdf / (l2 + bsdfPdf * bsdfPdf) : F{};
      Lr_ += br_ * fr * ler * s, Lg_ += bg_ * fg * leg * s, Lb_ += bb_ * fb * leb * s;
    }

    // The continuation: a cosine-weighted direction about the normal (Duff et al.'s basis).
    I scattered;
    if (framework_ >= 2) {
      scattered = I{};
      for (int k = 0; k < N; ++k) {
        if (!alive_[k]) continue;
        const auto sample = bsdf[k]->sample(glm::vec3(-dx_[k], -dy_[k], -dz_[k]), glm::vec2(uDir0[k], uDir1[k]));
        if (!sample || !(sample->pdf > 0.0f) || !(glm::dot(sample->wi, surface[k].geometricNormal) > 0.0f)) continue;
        if (framework_ >= 3) {
          const Ray next = spawnRay(surface[k], sample->wi);
          ox_[k] = next.origin.x, oy_[k] = next.origin.y, oz_[k] = next.origin.z;
        } else {
          ox_[k] = ox[k], oy_[k] = oy[k], oz_[k] = oz[k];
        }
        dx_[k] = sample->wi.x, dy_[k] = sample->wi.y, dz_[k] = sample->wi.z;
        br_[k] *= sample->weight.x, bg_[k] *= sample->weight.y, bb_[k] *= sample->weight.z;
        prevPdf_[k] = sample->pdf;
        scattered[k] = -1;
      }
    } else {
      F sinPhi, cosPhi;
      L::sinCos2Pi(uDir1, sinPhi, cosPhi);
      const F r = L::sqrt(uDir0), z = L::sqrt(1.0f - uDir0);
      const F lx = r * cosPhi, ly = r * sinPhi;
      const F sign = nz < 0.0f ? L::splat(-1.0f) : L::splat(1.0f);
      const F a = -1.0f / (sign + nz), b = nx * ny * a;
      const F tx = 1.0f + sign * nx * nx * a, ty = sign * b, tz = -sign * nx;
      const F sx = b, sy = sign + ny * ny * a, sz = -ny;
      dx_ = tx * lx + sx * ly + nx * z, dy_ = ty * lx + sy * ly + ny * z, dz_ = tz * lx + sz * ly + nz * z;
      ox_ = ox, oy_ = oy, oz_ = oz;
      br_ *= fr * std::numbers::pi_v<float>, bg_ *= fg * std::numbers::pi_v<float>, bb_ *= fb * std::numbers::pi_v<float>;
      prevPdf_ = z * kInvPiF;
      scattered = z > 0.0f;
    }
    prevX_ = px, prevY_ = py, prevZ_ = pz;
    depth_ += 1;
    end(alive_ & ~scattered);
    // Square-root roulette from depth kRouletteStart.
    const I rolls = alive_ & (depth_ >= kRouletteStart);
    if (L::any(rolls)) {
      F uRoulette = L::uniform(key, 4);
      if (laneSobol_) {
        F unused;
        lane_sobol::point(pixelKey_, reversedIndex_, firstSlot + uint32_t(VertexDimension::LightChoiceRoulette), unused, uRoulette);
      }
      if (sobol_)
        for (int k = 0; k < N; ++k)
          if (rolls[k] && (!laneSobol_ || vertex[k] >= PixelSampler::kTabulatedVertices)) uRoulette[k] = scalarNumbers(k).roulette();
      const F survive = L::min(L::splat(1.0f), L::sqrt(L::max(br_, L::max(bg_, bb_))));
      const I killed = rolls & (uRoulette >= survive);
      const F scale = rolls ? 1.0f / survive : L::splat(1.0f);
      br_ *= scale, bg_ *= scale, bb_ *= scale;
      end(killed);
    }
  }

  void end(I lanes) {
    finished_ |= lanes;
    alive_ &= ~lanes;
  }

  RTCScene scene_;
  const RenderScene& renderScene_;
  const EmitterSet& emitters_;
  const FlatScene& flat_;
  const Camera& camera_;
  bool sobol_, solidAngle_;
  int framework_;
  bool laneSobol_;
  std::optional<PixelSampler> samplers_[N];
  typename VectorTypes<N>::U64 pixelKey_{};
  U reversedIndex_{};
  F ox_{}, oy_{}, oz_{}, dx_{}, dy_{}, dz_{}, br_{}, bg_{}, bb_{}, Lr_{}, Lg_{}, Lb_{}, prevPdf_{}, prevX_{}, prevY_{}, prevZ_{};
  I depth_{}, alive_{}, finished_{};
  U key_{};
  uint64_t next_ = 0, total_ = 0;
  double sum_ = 0.0;
};

using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

// radiance() over the same pixels and passes: the renderer's own estimator.
double renderRadiance(const PathTracer& tracer, const Camera& camera, int passes) {
  BsdfContinuation continuation;
  PathStats stats;
  double sum = 0.0;
  const int width = camera.width(), pixels = width * camera.height();
  for (int pass = 0; pass < passes; ++pass)
    for (int p = 0; p < pixels; ++p) {
      PixelSampler sampler(1, uint64_t(p), uint64_t(pass));
      const Ray ray = camera.generateRay(glm::vec2(float(p % width), float(p / width)) + sampler.cameraJitter());
      const glm::vec3 L = tracer.radiance(ray, sampler, continuation, stats, uint64_t(p));
      if (isFiniteNonNegative(L)) sum += double(luminance(L));
    }
  return sum;
}

// lane_sobol against PixelSampler, number for number, over pixels, sample indices and vertices.
bool laneSobolAgrees() {
  using V = VectorTypes<8>;
  for (uint64_t pass : {0ull, 1ull, 5ull, 1000ull, 0x100000003ull})
    for (uint32_t vertex = 0; vertex < uint32_t(PixelSampler::kTabulatedVertices); ++vertex)
      for (VertexDimension d : {VertexDimension::LightPoint, VertexDimension::BsdfDirection, VertexDimension::LightChoiceRoulette}) {
        V::U64 keys;
        V::U reversed, slot;
        for (int k = 0; k < 8; ++k) {
          const PixelSampler sampler(kSeed, uint64_t(k) * 7919u + pass, pass);
          keys[k] = sampler.pixelKey();
          reversed[k] = sampler.reversedIndex();
          slot[k] = PixelSampler::slotOf(int(vertex), d);
        }
        V::F x, y;
        lane_sobol::point(keys, reversed, slot, x, y);
        for (int k = 0; k < 8; ++k) {
          PixelSampler sampler(kSeed, uint64_t(k) * 7919u + pass, pass);
          const glm::vec2 expected = sampler.get2D(int(vertex), d);
          if (x[k] != expected.x || y[k] != expected.y) return false;
        }
      }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 && argc != 6) {
    std::fprintf(stderr, "usage: simd_lanes SCENE [WIDTH HEIGHT PASSES ROUNDS]\n");
    return 2;
  }
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) {
    std::fprintf(stderr, "simd_lanes: this CPU has no AVX2 and FMA\n");
    return 2;
  }
  try {
    const RenderScene scene(loadGltf(argv[1]));
    if (const char* why = FlatScene::unsupported(scene.data())) {
      std::fprintf(stderr, "simd_lanes: the scene has %s, which this bound does not model\n", why);
      return 2;
    }
    if (!laneSobolAgrees()) {
      std::fprintf(stderr, "simd_lanes: lane_sobol disagrees with PixelSampler\n");
      return 1;
    }
    const FlatScene flat(scene.data());
    if (flat.lights.empty()) {
      std::fprintf(stderr, "simd_lanes: the scene has no emitting triangle\n");
      return 2;
    }
    const int width = argc == 6 ? std::atoi(argv[2]) : 256, height = argc == 6 ? std::atoi(argv[3]) : 256;
    const int passes = argc == 6 ? std::atoi(argv[4]) : 4, rounds = argc == 6 ? std::atoi(argv[5]) : 5;
    if (width < 1 || height < 1 || passes < 1 || rounds < 1) {
      std::fprintf(stderr, "simd_lanes: bad size, passes or rounds\n");
      return 2;
    }
    const Camera camera(defaultCamera(scene.data()), width, height);
    PathTracerSettings settings;
    settings.roulette = RouletteRule::Sqrt;
    settings.rrStartDepth = kRouletteStart;
    settings.maxDepth = kMaxDepth;
    const PathTracer tracer(scene, settings);
    struct Variant {
      const char* name;
      std::function<double()> render;
      std::vector<double> seconds;
      double mean = 0.0;
    };
    Wavefront<1> lean1(scene, flat, camera, false, false), sobol1(scene, flat, camera, true, false),
        solid1(scene, flat, camera, false, true), both1(scene, flat, camera, true, true);
    Wavefront<1> surface1(scene, flat, camera, true, true, 1), bsdf1(scene, flat, camera, true, true, 2),
        offsets1(scene, flat, camera, true, true, 3);
    Wavefront<8> lean8(scene, flat, camera, false, false), both8(scene, flat, camera, true, true),
        laneNumbers8(scene, flat, camera, true, false, 0, true), laneBoth8(scene, flat, camera, true, true, 0, true);
    std::vector<Variant> variants;
    variants.push_back({"radiance()", [&] { return renderRadiance(tracer, camera, passes); }, {}});
    variants.push_back({"1 lane, lean", [&] { return lean1.render(passes); }, {}});
    variants.push_back({"1 lane, Sobol'", [&] { return sobol1.render(passes); }, {}});
    variants.push_back({"1 lane, solid angle", [&] { return solid1.render(passes); }, {}});
    variants.push_back({"1 lane, both", [&] { return both1.render(passes); }, {}});
    variants.push_back({"1 lane, + surface()", [&] { return surface1.render(passes); }, {}});
    variants.push_back({"1 lane, + Bsdf", [&] { return bsdf1.render(passes); }, {}});
    variants.push_back({"1 lane, + offsets", [&] { return offsets1.render(passes); }, {}});
    variants.push_back({"8 lanes, lean", [&] { return lean8.render(passes); }, {}});
    variants.push_back({"8 lanes, both", [&] { return both8.render(passes); }, {}});
    variants.push_back({"8 lanes, lane Sobol'", [&] { return laneNumbers8.render(passes); }, {}});
    variants.push_back({"8 lanes, lane Sobol', solid angle", [&] { return laneBoth8.render(passes); }, {}});
    const double samples = double(width) * height * passes;
    for (int round = 0; round < rounds; ++round)
      for (Variant& v : variants) {
        const auto start = Clock::now();
        v.mean = v.render() / samples;
        v.seconds.push_back(seconds(start));
      }
    for (Variant& v : variants) std::sort(v.seconds.begin(), v.seconds.end());
    const double base = variants[0].seconds[variants[0].seconds.size() / 2];
    for (const Variant& v : variants) {
      const double median = v.seconds[v.seconds.size() / 2];
      std::printf("%-20s %7.1f ns/sample (median of %d)  x%.3f of radiance()  mean %.6f\n", v.name, median / samples * 1e9,
                  rounds, median / base, v.mean);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "simd_lanes: %s\n", e.what());
    return 2;
  }
  return 0;
}
