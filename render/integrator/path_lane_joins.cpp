// The joins of camera vertices to light vertices for eight lanes at once (PathLanes::Batch::join).
#include "render/core/color.h"
#include "render/integrator/path_lanes_batch.h"
#include "render/sampling/warps.h"

VPL_LANES_TARGET_BEGIN

namespace vpl {

using namespace lanes;

// Joins of every live lane's vertex to light vertices (radiance()'s, with its numbers and order): the
// n-th join of each lane in one packet of shadow rays, the packets in turn, as the shadow roulette
// weighs a join against what its sample holds after the joins before it. PathTracer::unoccludedJoin
// in vector form, for Lambertian lobes at both ends (every material is, where the lanes apply): each
// end's f and densities are its albedo and cosines (Bsdf::evalPdf, Bsdf::pdf).
void PathLanes::Batch::join(RTCScene handle, RTCIntersectContext& context, const JoiningVertex& v) {
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

}  // namespace vpl

VPL_LANES_TARGET_END
