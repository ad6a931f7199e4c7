// Next-event estimation's light samples for eight lanes at once (PathLanes::Batch::sampleLights).
#include <algorithm>
#include "render/guide/emitter_guide.h"
#include "render/integrator/path_lanes_batch.h"

VPL_LANES_TARGET_BEGIN

namespace vpl {

using namespace lanes;

namespace {

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

}  // namespace

// EmitterSet::sampleStratified from each lane's p with its numbers u, in lanes, where it folds the
// choice and draws an untextured triangle by area, and the guide (if any) samples as EmitterSet
// there: the same decisions in the same order, so the same sample up to float rounding. In a region
// that learned, the guide picks the triangle and the point's square lane by lane, and the point is
// drawn here as EmitterSet::sampleTriangleByArea draws it. `served`: the lanes whose sample this is
// (`found`: those that have one); the others (a triangle sampled by solid angle, a punctual light or
// the sky, or a region that records its samples and has one to record) call the renderer's own code.
void PathLanes::Batch::sampleLights(F8 px, F8 py, F8 pz, F8 ux, F8 uy, LightLanes& out) const {
  out.served = out.found = out.learned = I8{};
  out.slot.fill(UINT32_MAX);
  if (lanes_.lights_.empty()) return;
  I8 served = alive_, recording{}, learned{}, region{};
  if (guide_) {
    guide_->regionIndex<F8, I8>(px, py, pz, [](const F8& t, I8& i) { i = __builtin_convertvector(t, I8); }, region);
    const EmitterGuide::State* states = guide_->states();
    for (int k = 0; k < kLanes; ++k) {
      const EmitterGuide::State state = states[region[k]];
      if (state == EmitterGuide::State::Learned) learned[k] = -1;
      if (state == EmitterGuide::State::Undecided) recording[k] = -1;
    }
  }

  // Without a folded choice (an emitter's power share too small to fold) the lanes serve only the
  // regions that learned; where every lane's region learned, the folded choice is not needed either.
  alignas(32) int32_t chosen[kLanes] = {};
  alignas(32) float remappedU[kLanes] = {};
  if (lanes_.lightCdf_.empty()) {
    served &= learned;
  } else if (any(served & ~learned)) {
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
  }
  // A learned region's own choice: the triangle, the point's square, the choice's probability.
  F8 u1 = uy, choice{};
  learned &= served;
  for (int k = 0; k < kLanes; ++k) {
    if (!learned[k]) continue;
    EmitterGuide::TrianglePick pick;
    if (!guide_->pickLearnedTriangle(uint32_t(region[k]), glm::vec2(ux[k], uy[k]), pick)) {
      served[k] = learned[k] = 0;
      continue;
    }
    chosen[k] = int32_t(pick.triangle), remappedU[k] = pick.square.x, u1[k] = pick.square.y, choice[k] = pick.choice;
    out.slot[k] = pick.slot;
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
  served &= learned | (field(r0.foldedPmf) > 0.0f);
  const F8 ax = field(r0.p0[0]), ay = field(r0.p0[1]), az = field(r0.p0[2]);
  const F8 lnx = field(r0.normal[0]), lny = field(r0.normal[1]), lnz = field(r0.normal[2]);
  const I8 twoSided = field(r0.twoSided) > 0.0f;

  // EmitterSet::planeDistance, then the side: p in the plane, or behind a one-sided light, gets nothing.
  const F8 h = lnx * (px - ax) + lny * (py - ay) + lnz * (pz - az);
  const F8 extent = max8(field(r0.coordinateScale), max8(abs8(px), max8(abs8(py), abs8(pz))));
  I8 found = served & (abs8(h) > EmitterSet::kPlaneTolerance * extent) & ((h > 0.0f) | twoSided);
  // EmitterSet::solidAngleStrategy's test: a triangle that looks large goes to the scalar code (a
  // learned region samples by area whatever the triangle looks like).
  const F8 cx = field(r0.centre[0]) - px, cy = field(r0.centre[1]) - py, cz = field(r0.centre[2]) - pz;
  const F8 hp = abs8(lnx * (ax - px) + lny * (ay - py) + lnz * (az - pz));
  const F8 nearest = max8(hp, sqrt8(cx * cx + cy * cy + cz * cz) - field(r0.radius));
  served &= ~(found & ~learned & (field(r0.longestEdge) > EmitterSet::kSolidAngleSpread * nearest));
  found &= served;
  out.served = served;
  if (!any(found)) return;

  // EmitterSet::sampleTrianglePoint: sampleUniformTriangle's point, then its direction and density.
  const I8 below0 = u0 < u1;
  const F8 b0 = below0 ? u0 / 2.0f : u0 - u1 / 2.0f, b1 = below0 ? u1 - u0 / 2.0f : u1 / 2.0f;
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
  out.pdf = (learned ? choice : field(r0.pmf)) * dist2 / (out.cosLight * field(r0.area));
  // EmitterSet::emissionPdf, for bidirectional MIS's weight.
  if (connections_)
    out.emissionPdf = field(r0.pmf) * out.cosLight / (std::numbers::pi_v<float> * field(r0.area) * (twoSided ? splat(2.0f) : splat(1.0f)));
  // A recording region's sample goes to the renderer's code, which names its slot; where there is
  // no sample there is nothing to record (a ceiling behind a one-sided light: most of such regions).
  out.served = served & ~(found & recording);
  out.found = found & out.served;
  out.learned = learned & out.found;
}

}  // namespace vpl

VPL_LANES_TARGET_END
