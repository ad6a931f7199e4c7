// A planar triangle as seen from a point: the solid angle it subtends and directions uniform in that
// solid angle (Arvo, "Stratified Sampling of Spherical Triangles", SIGGRAPH 1995).
//
// Everything is computed in double, and arranged so that small and thin triangles keep their digits:
// the solid angle comes from the triple product of the vertex vectors (Van Oosterom & Strackee
// 1983), not from the angle excess alpha + beta + gamma - pi, which cancels for small triangles;
// great-circle normals come from the triangle's edges; Arvo's cos(arc) = q is replaced by a form
// of 1 - q without cancellation (pbrt-v4 and Arvo's paper use q itself, which loses half the digits
// of a short arc: about 1e-8 rad in double, everything in float for an arc under 1e-3 rad). The caller decides when the triangle is too small, too thin or too
// close to a hemisphere to sample this way (see EmitterSet) and samples by area there instead.
#pragma once
#include <glm/glm.hpp>

namespace vpl {

// Solid angle of the triangle with vertices p + a, p + b, p + c, seen from p; in [0, 2 pi].
// 0 when p lies in the triangle's plane or a vertex coincides with p.
double triangleSolidAngle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

class SphericalTriangle {
 public:
  // a, b, c: the triangle's vertices minus the reference point. Computes the solid angle only (what
  // a pdf needs); sample() does the rest.
  SphericalTriangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

  // triangleSolidAngle(a, b, c); the density of sample() is 1 / solidAngle().
  double solidAngle() const { return solidAngle_; }
  // False when the triangle has no area on the sphere (seen edge-on, or a vertex at the point).
  bool valid() const { return solidAngle_ > 0.0; }

  // A unit direction uniform in the spherical triangle; u in [0,1)^2, continuous in u (stratified u
  // stay stratified). u.x chooses the sub-triangle area swept from the first vertex, u.y the
  // position along the arc from the second vertex. Must not be called unless valid().
  glm::dvec3 sample(glm::dvec2 u) const;

 private:
  glm::dvec3 a_, ab_, ac_;  // the first vertex and the two edges from it (b - a, c - a)
  double invLa_ = 0.0, invLb_ = 0.0, invLc_ = 0.0;  // 1 / |a|, 1 / |b|, 1 / |c|
  glm::dvec3 A_, B_, C_;  // unit directions to the vertices
  double triple_ = 0.0;   // |A . (B x C)|
  double solidAngle_ = 0.0;
};

// Barycentrics (b1, b2) of the point where the ray p + t w meets the plane of triangle
// (v0, v1, v2), clamped onto the triangle (so rounding never leaves it). (1/3, 1/3) when w is
// parallel to the plane.
glm::dvec2 rayTriangleBarycentrics(const glm::dvec3& p, const glm::dvec3& w, const glm::dvec3& v0,
                                   const glm::dvec3& v1, const glm::dvec3& v2);

}  // namespace vpl
