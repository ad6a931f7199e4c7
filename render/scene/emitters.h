// Every light of a scene in one power-weighted distribution (an alias table: O(1) per choice):
// emissive triangles, KHR punctual lights and the uniform sky. Next-event estimation samples it;
// emitter hits ask it for the pdf. A triangle is sampled uniformly in the solid angle it subtends
// when it looks large from the reference point and by area when it looks small (see
// solidAngleStrategy in emitters.cpp); the choice depends on the point and the triangle only, so
// pdfTriangle returns the density of the strategy sample() used.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>
#include <glm/glm.hpp>
#include "render/sampling/alias_table.h"
#include "render/sampling/distribution_1d.h"
#include "render/sampling/spherical_triangle.h"
#include "render/scene/scene_data.h"
#include "render/scene/surface.h"

namespace vpl {

struct LightSample {
  glm::vec3 wi{0.0f};         // unit, from the reference point towards the light
  float distance = INFINITY;  // to the light point (INFINITY for sky and directional)
  glm::vec3 radiance{0.0f};   // Li arriving at the reference point (irradiance for delta lights)
  float pdf = 0.0f;           // solid angle density incl. the light choice; for delta lights the choice pmf
  bool delta = false;         // punctual light: no MIS with BSDF sampling
  // What bidirectional MIS weights need (render/integrator/light_vertex_cache.h): the density with
  // which sampleEmission() starts a light path at the sampled point towards the reference point
  // (area x solid angle, light choice included), and the cosine at the light (1 for punctual lights).
  float emissionPdf = 0.0f;
  float cosLight = 1.0f;
  int32_t emitter = -1;  // which light of the set (triangles first, then punctual lights, then the sky)
  // EmitterGuide: the part of the emitters the sample came from (its region and cell), for learning.
  uint32_t guideSlot = UINT32_MAX;
};

// Where a light path starts (instant radiosity): a point and direction drawn from the emission.
struct EmissionSample {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f};     // emitter surface normal, 0 for point-like and sky
  glm::vec3 direction{0.0f};  // unit, direction of travel
  glm::vec3 weight{0.0f};     // Le cos / (pdf_pos pdf_dir): the flux the path carries, summed over N paths / N
  float pdf = 0.0f;           // pdf_pos pdf_dir, light choice included (area x solid angle; sky and
                              // directional: disk area x direction)
  uint32_t emitter = 0;       // which light of the set (for nextEventPdf)
  glm::vec2 square{0.0f};     // triangles: the point of the unit square that sampleUniformTriangle mapped
  bool deltaPosition = false; // punctual: no ray can hit where the path starts
};

class EmitterSet {
 public:
  EmitterSet() = default;
  // sceneCentre/sceneRadius bound the scene (the sky and the sun are sampled from outside it).
  EmitterSet(const SceneData& scene, const glm::vec3& sky, const glm::vec3& sceneCentre, float sceneRadius);

  bool empty() const { return distribution_.empty(); }
  size_t triangleCount() const { return triangles_.size(); }

  // Next-event estimation from point p; u = three uniforms.
  std::optional<LightSample> sample(const glm::vec3& p, float uLight, glm::vec2 u) const;
  // The same density, with the emitter's choice folded into u.x: each emitter owns one interval of
  // x (a CDF, not the alias table, which splits an emitter's share over several bins), and x
  // rescaled within it serves the point (as Bsdf::sample(wo, u) picks its lobe). A stratified u then
  // stays stratified over each emitter's points, where a choice of its own hands each emitter a
  // random subset of them (the Cornell box's two-triangle light, brdf at 64 spp: relMSE 0.97x).
  // An emitter whose share is below kMinFoldedShare would keep too few of x's 24 bits for its
  // points (a share of 1e-6: 17 values, a biased quadrature), so where any is, uSpare makes the
  // choice as sample() does.
  // spareNumber() (a float in [0, 1)) is asked only then: callers need not draw it ahead.
  template <class SpareNumber>
  std::optional<LightSample> sampleStratified(const glm::vec3& p, glm::vec2 u, SpareNumber&& spareNumber) const {
    return foldsChoice() ? sampleFolded(p, u) : sample(p, spareNumber(), u);
  }
  std::optional<LightSample> sampleStratified(const glm::vec3& p, glm::vec2 u, float uSpare) const {
    return sampleStratified(p, u, [uSpare] { return uSpare; });
  }
  static constexpr float kMinFoldedShare = 1.0f / 256.0f;  // 16 bits or more left for the point
  // Whether the sampleStratified functions fold the choice (and leave uSpare unread).
  bool foldsChoice() const { return !foldedChoice_.empty(); }
  // Density (solid angle, at p) with which sample() picks the emitting triangle point x of a hit.
  float pdfTriangle(const glm::vec3& p, const SurfaceHit& hit) const;
  // Whether sample() draws the emitting triangle (mesh, triangle) by solid angle from p (else by
  // area); false for a triangle that does not emit.
  bool sampledBySolidAngle(const glm::vec3& p, uint32_t mesh, uint32_t triangle) const;
  // Density with which sample() picks direction wi towards the sky.
  float pdfSky(const glm::vec3& wi) const;

  // Starting vertex of a light path, for VPL tracing.
  std::optional<EmissionSample> sampleEmission(float uLight, glm::vec2 uPos, glm::vec2 uDir) const;
  // The same with the emitter's choice folded into uPos.x, as sampleStratified() folds it; uSpare
  // picks the side of a two-sided emitter, and the emitter too where the choice is not folded.
  // sampleEmission()'s densities hold for it.
  std::optional<EmissionSample> sampleEmissionStratified(glm::vec2 uPos, glm::vec2 uDir, float uSpare) const;
  // Density with which sampleEmission() starts at the emitting point of a hit and leaves along
  // `direction` (area x solid angle, light choice included): the light-tracing side of a camera
  // path's emitter hit in bidirectional MIS.
  float pdfEmission(const SurfaceHit& hit, const glm::vec3& direction) const;
  // Next-event estimation's density of picking a light path's start e from p, times the cosine at
  // the light: solid angle x cos for triangles, pmf x distance^2 for point-like lights (their
  // delta density cancels in the ratios it serves), pmf for directional lights.
  float nextEventPdfTimesCos(const glm::vec3& p, const EmissionSample& e) const;
  // Whether every light here is one that bidirectional connections weight exactly: triangles and
  // point, spot and directional lights without a range window; not the sky.
  bool supportsConnections() const;

  // What EmitterGuide (render/guide/emitter_guide.h), which learns which part of which emitter
  // each region of the scene sees, builds on: it cuts each triangle's unit square (the domain of
  // sampleUniformTriangle, whose map preserves area) into cells and samples a cell's points by area.
  size_t punctualCount() const { return punctual_.size(); }
  // The set's index of the sky (after the triangles and punctual lights), or -1.
  int skyIndex() const { return skyIndex_; }
  // The power-proportional probability of choosing light `index` of the set.
  float emitterPmf(size_t index) const { return distribution_.pmf(index); }
  // Next-event estimation from p towards punctual light `index` of the set, chosen with probability
  // pmf (its density: the light is a delta).
  std::optional<LightSample> samplePunctual(const glm::vec3& p, size_t index, float pmf) const;
  glm::vec3 triangleNormal(size_t index) const { return triangles_[index].normal; }
  float triangleArea(size_t index) const { return triangles_[index].area; }
  glm::vec3 triangleCentroid(size_t index) const { return triangles_[index].centre; }
  // The emitter index of a hit's triangle, or -1 where it does not emit.
  int32_t emitterOf(const SurfaceHit& hit) const;
  // The unit square's point that sampleUniformTriangle maps to x, a point of triangle `index`.
  glm::vec2 squareOf(size_t index, const glm::vec3& x) const;
  // Next-event estimation from p towards the point of triangle `index` at `square`, a point drawn
  // with density choice / area (per unit area of the triangle: as if the triangle were chosen with
  // probability `choice` and its point uniformly, which is what sample() does by area).
  std::optional<LightSample> sampleTriangleByArea(const glm::vec3& p, size_t index, glm::vec2 square, float choice) const;
  // The solid-angle density at p of that density at point x of triangle `index` (facing `normal`,
  // hit on side `front`): 0 where sampleTriangleByArea would send nothing.
  float solidAnglePdfOfArea(const glm::vec3& p, size_t index, const glm::vec3& x, const glm::vec3& normal, bool front,
                            float choice) const;

  // Emitted radiance of a surface hit towards wo (0 unless the material emits on that side).
  glm::vec3 emitted(const SurfaceHit& hit, const glm::vec3& wo) const;
  glm::vec3 sky() const { return sky_; }
  bool hasSky() const { return skyIndex_ >= 0; }

  // What sample() reads of an emitting triangle. Public for the eight-lane form of sampleStratified()
  // (render/integrator/lane_lights.h), which must decide as sample() does.
  struct TriangleLight {
    uint32_t mesh, triangle;
    float area;
    bool twoSided;
    glm::vec3 p0, p1, p2;  // vertices
    glm::vec3 normal;      // unit, from the winding (the front side)
    glm::vec3 centre;      // of the bounding sphere (the centroid) ...
    float radius;          // ... and its radius (the farthest vertex)
    float longestEdge;     // the triangle's diameter
    float coordinateScale; // largest |coordinate| of the vertices
    bool textured;         // the emission has a texture (radiance varies over the triangle)
  };
  const TriangleLight& triangleLight(size_t index) const { return triangles_[index]; }
  // The folded samplers' choice (empty unless foldsChoice()).
  const Distribution1D& foldedChoice() const { return foldedChoice_; }
  // A triangle looks large from p, and is sampled by solid angle, where its longest edge exceeds this
  // share of a lower bound on its distance (emitters.cpp says why this value) ...
  static constexpr float kSolidAngleSpread = 0.75f;
  // ... and p lies in its plane, and gets no light from it, within this share of the coordinate scale.
  static constexpr float kPlaneTolerance = 1e-4f;

 private:
  const SceneData* scene_ = nullptr;
  std::vector<TriangleLight> triangles_;
  std::vector<PunctualLight> punctual_;
  // For each mesh, the emitter index of each triangle (empty for non-emissive meshes).
  std::vector<std::vector<int32_t>> triangleIndex_;
  AliasTable distribution_;  // over [triangles..., punctual..., sky]
  // The same choice as a CDF for the folded samplers; empty where some emitter's share is below
  // kMinFoldedShare (or there are none).
  Distribution1D foldedChoice_;
  int skyIndex_ = -1;
  glm::vec3 sky_{0.0f};
  glm::vec3 centre_{0.0f};
  float radius_ = 1.0f;

  glm::vec3 triangleRadiance(const TriangleLight& light, glm::vec2 barycentric, bool frontSide) const;
  struct TrianglePoint {
    glm::vec3 position, normal;  // normal from the winding (the front side)
  };
  TrianglePoint trianglePoint(const TriangleLight& light, glm::vec2 barycentric) const;
  // sampleEmission() once the emitter `index` is chosen with probability pmf.
  std::optional<EmissionSample> sampleEmissionChosen(size_t index, float pmf, float uSide, glm::vec2 uPos, glm::vec2 uDir) const;
  // sampleStratified() where foldsChoice().
  std::optional<LightSample> sampleFolded(const glm::vec3& p, glm::vec2 u) const;
  // sampleTriangleByArea() and solidAnglePdfOfArea() once p is known to see the triangle's lit side.
  std::optional<LightSample> sampleTrianglePoint(const glm::vec3& p, size_t index, glm::vec2 square, float choice) const;
  float areaToSolidAngle(const glm::vec3& p, size_t index, const glm::vec3& x, const glm::vec3& normal, float choice) const;
  // sample() once the emitter `index` is chosen with probability pmf.
  std::optional<LightSample> sampleChosen(const glm::vec3& p, size_t index, float pmf, glm::vec2 u) const;
  // The spherical triangle of `light` seen from p when sample() samples it by solid angle from
  // there; nullopt when it samples by area.
  static std::optional<SphericalTriangle> solidAngleStrategy(const glm::vec3& p, const TriangleLight& light);
  // Signed distance from p to the triangle's plane (positive on the front side), or NaN when p lies
  // in that plane as far as the renderer can tell: no light from the triangle reaches p then.
  static float planeDistance(const glm::vec3& p, const TriangleLight& light);
  // sampleEmission()'s density for a triangle chosen with `pmf`: a uniform point and side, then a
  // cosine-distributed direction (cosLight: its cosine to the side's normal).
  static float emissionPdf(const TriangleLight& light, float pmf, float cosLight);
  // pdfTriangle for a point x of light `index`, facing `normal`, on side `front`.
  float pdfTrianglePoint(const glm::vec3& p, size_t index, const glm::vec3& x, const glm::vec3& normal, bool front) const;
};

}  // namespace vpl
