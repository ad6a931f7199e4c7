// Embree 3 ray queries over the scene's triangle meshes: one RTCGeometry per MeshData, alpha-MASK
// cut-outs through filter functions. Thread-safe after construction.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>
#include <embree3/rtcore.h>
#include <glm/glm.hpp>
#include "render/scene/scene_data.h"

namespace vpl {

struct Ray {
  glm::vec3 origin{0.0f};
  glm::vec3 direction{0, 0, 1};  // unit length
  float tMax = INFINITY;
};

struct RayHit {
  float t = INFINITY;
  uint32_t mesh = RTC_INVALID_GEOMETRY_ID;  // index into SceneData::meshes
  uint32_t triangle = 0;
  float u = 0.0f, v = 0.0f;                 // barycentrics of vertices 1 and 2
  bool valid() const { return mesh != RTC_INVALID_GEOMETRY_ID; }
};

// Moves a ray origin off a surface by a few ULPs along the geometric normal, so that offsets scale
// with the coordinates (Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection",
// Ray Tracing Gems, ch. 6). Works for scenes of any scale.
// `coordinateScale` is the magnitude of the coordinates p was computed from (its triangle's vertices):
// near zero a coordinate's rounding error follows that scale, not the coordinate itself.
glm::vec3 offsetRayOrigin(const glm::vec3& p, const glm::vec3& geometricNormal, float coordinateScale);
// Its step, element by element, for GCC vectors F of floats and I of int32 (offsetRayOrigin takes the
// three coordinates at once, render/integrator/path_lanes one coordinate of eight points), `scale`
// the coordinate scale already made positive and finite: 256 ulps along n, and where
// |p| < scale / 32 (ulps vanish near zero) scale / 65536 n. (By reference: a 32-byte vector passed by
// value would change the ABI between code with and without AVX.)
template <class F, class I>
inline void offsetCoordinates(F& p, const F& n, const F& scale) {
  const I step = __builtin_convertvector(256.0f * n, I);
  const I negative = p < 0.0f;  // -1 where p < 0: the offset's sign flips
  const I bits = (I)p + ((step ^ negative) - negative);
  const I nearZero = (F)((I)p & 0x7fffffff) < scale / 32.0f;
  p = nearZero ? p + scale / 65536.0f * n : (F)bits;
}

struct AlphaMask;  // what the cut-out filter needs to evaluate a texel

class Accel {
 public:
  explicit Accel(const SceneData& scene);
  ~Accel();
  Accel(const Accel&) = delete;
  Accel& operator=(const Accel&) = delete;

  RayHit intersect(const Ray& ray) const;
  // True when something blocks the ray in (0, tMax).
  bool occluded(const Ray& ray) const;

  RTCScene handle() const { return scene_; }

 private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::vector<std::unique_ptr<AlphaMask>> masks_;
  std::string error_;  // first error Embree reported
};

}  // namespace vpl
