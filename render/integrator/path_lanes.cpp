#include "render/integrator/path_lanes.h"

#include <algorithm>
#include "render/core/color.h"
#include "render/guide/emitter_guide.h"
#include "render/integrator/path_lanes_batch.h"
#include "render/integrator/weight_window.h"
#include "render/sampling/fast_trig.h"
#include "render/sampling/lane_sobol.h"
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
  const bool folds = emitters.foldsChoice();
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
                       emitters.emitterPmf(i), folds ? emitters.foldedChoice().pmf(i) : 0.0f});
  }
  if (!folds) return;
  const Distribution1D& choice = emitters.foldedChoice();
  for (size_t i = 0; i <= choice.size(); ++i) lightCdf_.push_back(choice.cdf(i));
}

}  // namespace vpl

VPL_LANES_TARGET_BEGIN

namespace vpl {

using namespace lanes;

void PathLanes::Batch::run() {
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

// Lane k takes the tile's next pixel, if any is left.
void PathLanes::Batch::start(int k) {
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
bool PathLanes::Batch::stage() {
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

// Lane k goes on with one of its sample's branches.
void PathLanes::Batch::resume(int k, const Branch& b) {
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

void PathLanes::Batch::finish(int k) {
  started_[k] = false;
  if (!isFiniteNonNegative(L_[k])) {
    ++discarded_;
    return;
  }
  clearUpperHalves();
  film_.addSample(x_[k], y_[k], L_[k]);
}

// The two numbers every vertex reads (VertexSamples::drawAhead), for the lanes whose vertex draws
// from the stratified slots, at once; the others (a split's branches, deep vertices) draw their own.
void PathLanes::Batch::drawAhead() {
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

// One vertex of every live lane: radiance()'s loop body for BSDF sampling.
void PathLanes::Batch::bounce() {
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
                                                                  bsdfs_[k]->evalPdf(wo(k), ls->wi), depth_[k], sums(k),
                                                                  bsdfContinuation_)
                  : ls->delta ? 1.0f : powerHeuristic(ls->pdf, cosineHemispherePdf(cosIn));
    contribution[k] = f * ls->radiance * (w / ls->pdf);
    arrival[k] = EmitterGuide::arrivalValue(ls->radiance, cosReceiver, ls->pdf);
    slot[k] = ls->guideSlot;
    tested[k] = -1;
  }
  if (any(lights.found)) {
    // The same as above, in lanes: the receiver's side and cosines, the lobe, the shadow ray
    // (spawnShadowRay: aimed at the light point, stopped short by its margin), the MIS weight.
    const F8 wx = lights.wx, wy = lights.wy, wz = lights.wz;
    const F8 cosIn = wx * sx + wy * sy + wz * sz, cosOutgoing = -(dx_ * sx + dy_ * sy + dz_ * sz);
    const F8 fr = ar * kInvPiF * cosIn, fg = ag * kInvPiF * cosIn, fb = ab * kInvPiF * cosIn;
    const F8 cosReceiver = wx * nx + wy * ny + wz * nz;
    const I8 lit = lights.found & (cosReceiver > 0.0f) & (cosOutgoing > 0.0f) & (cosIn > 0.0f) &
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
      const glm::vec3 emitted(lights.r[k], lights.g[k], lights.b[k]);
      contribution[k] = glm::vec3(fr[k], fg[k], fb[k]) * emitted * share[k];
      slot[k] = lights.slot[k];  // a learned region's: its sample's arrival is recorded
      if (lights.learned[k]) {
        guide_->attempted(slot[k]);
        arrival[k] = EmitterGuide::arrivalValue(emitted, cosReceiver[k], lights.pdf[k]);
      }
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
SurfaceHit PathLanes::Batch::hitSurface(int k, F8 px, F8 py, F8 pz, F8 nx, F8 ny, F8 nz, F8 sx, F8 sy, F8 sz, F8 scale,
                                        uint32_t mesh, uint32_t triangle) const {
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
float PathLanes::Batch::emitterHit(int k, const SurfaceHit& surface) {
  const glm::vec3 le = emitters_.emitted(surface, wo(k));
  if (isBlack(le)) return 0.0f;
  const PathTracer::PathPoint at{int(depth_[k]), glm::vec3(prevX_[k], prevY_[k], prevZ_[k]), prevPdf_[k]};
  L_[k] += beta(k) * le * lanes_.tracer_.emitterHitWeight(surface, wo(k), at, sums(k));
  return luminance(le);
}

// Splits lane k's path at `surface` into `split` branches: the split - 1 others are drawn and kept
// for later (sampleContinuation of radiance(), with the branch's own numbers), the lane's own weight
// shrinks to its share.
void PathLanes::Batch::branch(int k, int split, const SurfaceHit& surface) {
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

// Lane k's ray left the scene: the sky, weighed against next-event estimation of the sky.
void PathLanes::Batch::escape(int k) {
  if (!emitters_.hasSky()) return;
  float w = 1.0f;
  if (depth_[k] > 0) {
    const glm::vec3 previous(prevX_[k], prevY_[k], prevZ_[k]), d(dx_[k], dy_[k], dz_[k]);
    w = powerHeuristic(prevPdf_[k], guide_ ? guide_->pdfSky(previous, d) : emitters_.pdfSky(d));
  }
  L_[k] += beta(k) * emitters_.sky() * w;
}

void PathLanes::renderTile(const Camera& camera, uint64_t seed, uint64_t pass, int x0, int y0, int x1, int y1, Film& film,
                           PathStats& stats, uint64_t& discarded) const {
  Batch(*this, camera, seed, pass, x0, y0, x1, y1, film, stats, discarded).run();
}

}  // namespace vpl

VPL_LANES_TARGET_END
