// The `brdf` estimator of PathTracer::radiance, eight camera paths at a time (issue 15: samples per
// second). A tile's samples flow through eight AVX2 lanes: each bounce traces the live lanes' rays
// as one Embree packet (rtcIntersect8, rtcOccluded8), rebuilds their hits, samples their cosine
// continuations and rolls their roulette in vector arithmetic, and a lane whose path ends takes the
// tile's next sample at once (a wavefront within the tile). What differs from lane to lane in control
// flow stays scalar per lane: the stratified numbers (PixelSampler, the same slots), next-event
// estimation (EmitterSet or the learned EmitterGuide, the same calls), emitter hits and the sky.
// So each sample is radiance()'s, with the same numbers, up to float rounding.
//
// The VPL weight window's roulette and splitting are radiance()'s too: a lane keeps its sample's branches
// and traces them after the sample's first path, in radiance()'s order, so each branch gets the same
// numbers and the same share of the sample's branch budget.
//
// Joins to light vertices (VPL connections) too: the camera side's partial sums and the bidirectional
// MIS weights of emitter hits and light samples in lanes, and the joins themselves in lanes (each
// lane's light vertex gathered; both ends Lambertian, as every material is here), their shadow rays as
// one packet per join. A pass that weighs a counterfactual join depth (`--join-depth auto`'s trial)
// goes to radiance() (TileRenderer).
//
// Only where the vector form is the whole model (unsupported() says why not, and the caller keeps
// radiance()): BSDF sampling, every material Lambertian, untextured and opaque (shading normals
// interpolated as RenderScene::surface does), and a CPU with AVX2 and FMA (the vector code, in
// path_lanes_batch.h and the path_lane*.cpp files, is compiled for them alone, and chosen at run time).
// `--lanes off` keeps radiance() everywhere: the ablation, and what the tests compare against.
#pragma once
#include <cstdint>
#include <string>
#include <vector>
#include <glm/glm.hpp>
#include "render/film/film.h"
#include "render/integrator/path_tracer.h"
#include "render/scene/camera.h"

namespace vpl {

class PathLanes {
 public:
  static constexpr int kLanes = 8;

  // Empty when the lanes can render the tracer's `brdf` samples exactly, else why not.
  static std::string unsupported(const PathTracer& tracer);
  // `tracer` must outlive this and be supported.
  explicit PathLanes(const PathTracer& tracer);

  // Sample `pass` of every pixel in [x0, x1) x [y0, y1) into film, as TileRenderer would with
  // radiance() (non-finite or negative samples are dropped and counted in `discarded`).
  void renderTile(const Camera& camera, uint64_t seed, uint64_t pass, int x0, int y0, int x1, int y1, Film& film,
                  PathStats& stats, uint64_t& discarded) const;

 private:
  // What a hit needs of its triangle, one cache line each (index: meshBase_[mesh] + triangle).
  struct alignas(64) Triangle {
    glm::vec3 p0, p1, p2;
    glm::vec3 normal;       // unit winding normal, zero for a degenerate triangle
    glm::vec3 albedo;       // the Lambertian BSDF's diffuse albedo
    float coordinateScale;  // the offsets' rounding scale (SurfaceHit::coordinateScale)
  };
  // What next-event estimation in lanes reads of an emitting triangle (EmitterSet::TriangleLight, its
  // material's emission and its probabilities), gathered by index: a record of floats each.
  struct LightRecord {
    float p0[3], p1[3], p2[3], normal[3], centre[3];
    float radius, longestEdge, coordinateScale, area, twoSided;
    float emission[3];
    float pmf;        // EmitterSet's power choice, the density's factor
    float foldedPmf;  // the folded choice's (an index of weight 0 is never chosen)
  };
  static_assert(sizeof(LightRecord) % sizeof(float) == 0);
  class Batch;

  const PathTracer& tracer_;
  const RenderScene& scene_;
  std::vector<uint32_t> meshBase_;
  std::vector<Triangle> triangles_;
  std::vector<uint8_t> emits_;  // the triangle is one of EmitterSet's lights
  std::vector<uint32_t> smooth_;  // where the triangle's three vertex normals start in normals_; UINT32_MAX: none
  std::vector<glm::vec3> normals_;
  // Empty where the lanes leave next-event estimation to EmitterSet lane by lane (an emitter is
  // textured); else one record per emitting triangle, and, where EmitterSet folds its choice, the folded
  // choice's CDF (Distribution1D::cdf; without it only the regions that learned sample in lanes).
  std::vector<LightRecord> lights_;
  std::vector<double> lightCdf_;
};

}  // namespace vpl
