#include "render/sampling/spherical_triangle.h"

#include <algorithm>
#include <cmath>

namespace vpl {

namespace {

double solidAngleOfUnit(const glm::dvec3& A, const glm::dvec3& B, const glm::dvec3& C, double tripleUnit) {
  // tan(omega / 2) = |A . (B x C)| / (1 + A.B + B.C + C.A) for unit A, B, C; atan2 keeps the
  // quadrant, so a triangle over more than a quarter of the sphere (denominator < 0) is right too.
  const double denominator = 1.0 + glm::dot(A, B) + glm::dot(B, C) + glm::dot(C, A);
  return 2.0 * std::atan2(std::abs(tripleUnit), denominator);
}

}  // namespace

double triangleSolidAngle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  return SphericalTriangle(a, b, c).solidAngle();
}

SphericalTriangle::SphericalTriangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
    : a_(a), ab_(b - a), ac_(c - a) {
  const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  if (!(la > 0.0 && lb > 0.0 && lc > 0.0)) return;
  invLa_ = 1.0 / la;
  invLb_ = 1.0 / lb;
  invLc_ = 1.0 / lc;
  A_ = a * invLa_;
  B_ = b * invLb_;
  C_ = c * invLc_;
  // a . (b x c) = a . ((b - a) x (c - a)): from the edges it keeps its digits for a small or
  // distant triangle, where the cross product of two long, nearly parallel vectors would cancel.
  triple_ = std::abs(glm::dot(a, glm::cross(ab_, ac_))) * (invLa_ * invLb_ * invLc_);
  const double omega = solidAngleOfUnit(A_, B_, C_, triple_);
  if (omega > 0.0 && std::isfinite(omega)) solidAngle_ = omega;
}

glm::dvec3 SphericalTriangle::sample(glm::dvec2 u) const {
  // The normals of the great circles through A and B, and through A and C, from the edges (b - a
  // is an edge of the triangle, exact, where B - A of the unit vectors would cancel for a small one):
  // a x b = a x (b - a).
  const glm::dvec3 nAB = glm::cross(a_, ab_) * (invLa_ * invLb_), nAC = glm::cross(a_, ac_) * (invLa_ * invLc_);
  // Interior angle alpha at A, between the two great circles: |nAB x nAC| = |A . (B x C)| =
  // sin(alpha) sin(b) sin(c) and nAB . nAC = cos(alpha) sin(b) sin(c).
  const double cosScaled = glm::dot(nAB, nAC);
  const double r2 = triple_ * triple_ + cosScaled * cosScaled;
  // The unit tangent at A towards C: (A x C) x A, of length |A x C| since A x C is normal to A.
  const double sinB2 = glm::dot(nAC, nAC);
  if (!(r2 > 0.0) || !(sinB2 > 0.0)) return A_;  // only for a triangle with (almost) no area
  const double invR = 1.0 / std::sqrt(r2);
  const double sinAlpha = triple_ * invR, cosAlpha = cosScaled * invR;
  const glm::dvec3 towardsC = glm::cross(nAC, A_) * (1.0 / std::sqrt(sinB2));
  // Arc AB: cos c, and 1 - cos c = sin^2 c / (1 + cos c) without cancellation for a short arc.
  const double cosC = glm::dot(A_, B_);
  const double oneMinusCosC = cosC > 0.0 ? glm::dot(nAB, nAB) / (1.0 + cosC) : 1.0 - cosC;

  // Step 1 (Arvo 1995): the sub-triangle A B C' of area A' = u.x * omega, with C' on the arc AC at
  // arc length b' from A. Arvo gives cos b' = q as a ratio whose numerator and denominator cancel
  // for a small triangle (and sqrt(1 - q^2) then keeps only half the digits); rewritten with
  // half-angle identities, 1 - q has no cancellation:
  //   1 - q = 2 sin^2(A'/2) (1 + cos c) / (2 sin^2(A'/2) + sin(alpha) sin(alpha - A') (1 - cos c)).
  const double halfArea = 0.5 * std::clamp(u.x, 0.0, 1.0) * solidAngle_;
  const double sinHalf = std::sin(halfArea), cosHalf = std::cos(halfArea);
  const double versine = 2.0 * sinHalf * sinHalf;                   // 1 - cos A'
  const double sinArea = 2.0 * sinHalf * cosHalf;                   // sin A'
  const double cosArea = (cosHalf - sinHalf) * (cosHalf + sinHalf);  // cos A'
  const double sinAlphaMinusArea = sinAlpha * cosArea - cosAlpha * sinArea;
  const double denominator = versine + sinAlpha * sinAlphaMinusArea * oneMinusCosC;
  double oneMinusQ = denominator > 0.0 ? versine * (1.0 + cosC) / denominator : 0.0;
  if (!std::isfinite(oneMinusQ)) oneMinusQ = 0.0;
  oneMinusQ = std::clamp(oneMinusQ, 0.0, 2.0);
  // C' is unit up to rounding: A and towardsC are orthonormal and (1 - q)^2 + (1 - q^2) = 1.
  const glm::dvec3 cPrime = (1.0 - oneMinusQ) * A_ + std::sqrt(oneMinusQ * (2.0 - oneMinusQ)) * towardsC;

  // Step 2: along the arc from B to C', 1 - cos(theta) uniform in [0, 1 - B.C'], which is uniform
  // in area within the sub-triangle's thin slice. 1 - B.C' = |C' - B|^2 / 2 keeps short arcs exact,
  // and so does the tangent at B towards C', (C' - B) + (1 - B.C') B.
  const glm::dvec3 d = cPrime - B_;
  const double arcOneMinusCos = 0.5 * glm::dot(d, d);
  const double oneMinusCos = std::clamp(u.y, 0.0, 1.0) * arcOneMinusCos;
  const double sinTheta = std::sqrt(std::max(0.0, oneMinusCos * (2.0 - oneMinusCos)));
  const glm::dvec3 tangent = d + arcOneMinusCos * B_;
  const double tangent2 = glm::dot(tangent, tangent);
  if (!(tangent2 > 0.0)) return B_;
  return (1.0 - oneMinusCos) * B_ + (sinTheta / std::sqrt(tangent2)) * tangent;
}

glm::dvec2 rayTriangleBarycentrics(const glm::dvec3& p, const glm::dvec3& w, const glm::dvec3& v0,
                                   const glm::dvec3& v1, const glm::dvec3& v2) {
  // Cramer's rule for p + t w = v0 + b1 e1 + b2 e2 (Moller & Trumbore's arrangement).
  const glm::dvec3 e1 = v1 - v0, e2 = v2 - v0;
  const glm::dvec3 s1 = glm::cross(w, e2);
  const double det = glm::dot(s1, e1);
  if (!(std::abs(det) > 0.0)) return {1.0 / 3.0, 1.0 / 3.0};
  const double invDet = 1.0 / det;
  const glm::dvec3 s = p - v0;
  double b1 = glm::dot(s, s1) * invDet;
  double b2 = glm::dot(w, glm::cross(s, e1)) * invDet;
  if (!std::isfinite(b1) || !std::isfinite(b2)) return {1.0 / 3.0, 1.0 / 3.0};
  b1 = std::clamp(b1, 0.0, 1.0);
  b2 = std::clamp(b2, 0.0, 1.0);
  const double sum = b1 + b2;
  if (sum > 1.0) {
    b1 /= sum;
    b2 /= sum;
  }
  return {b1, b2};
}

}  // namespace vpl
