#include "render/scene/accel.h"

#include <cmath>

#include <cstring>
#include <stdexcept>
#include <string>

namespace vpl {

// Alpha MASK cut-outs (glTF 2.0 §3.9.4): a hit whose alpha is below the cutoff does not exist.
struct AlphaMask {
  const MeshData* mesh = nullptr;
  const Texture* texture = nullptr;
  const std::vector<glm::vec2>* uvs = nullptr;
  float baseAlpha = 1.0f, cutoff = 0.5f;

  bool opaqueAt(uint32_t prim, float u, float v) const {
    float alpha = baseAlpha;
    if (texture && uvs && !uvs->empty()) {
      const uint32_t* idx = &mesh->indices[3 * size_t(prim)];
      const glm::vec2 uv = (*uvs)[idx[0]] * (1.0f - u - v) + (*uvs)[idx[1]] * u + (*uvs)[idx[2]] * v;
      alpha *= texture->sample(uv).w;  // alpha
    }
    return alpha >= cutoff;
  }
};

namespace {

// Embree reports out-of-memory and API misuse here; the message is kept and raised after the build
// (throwing through Embree's C API would not be safe).
void embreeError(void* user, RTCError code, const char* message) {
  auto* first = static_cast<std::string*>(user);
  if (first->empty()) *first = "Embree error " + std::to_string(int(code)) + ": " + (message ? message : "");
}

void alphaFilter(const RTCFilterFunctionNArguments* args) {
  const auto* mask = static_cast<const AlphaMask*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
    if (!mask->opaqueAt(prim, RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i)))
      args->valid[i] = 0;
  }
}

RTCRay toRtcRay(const Ray& ray) {
  RTCRay r;
  r.org_x = ray.origin.x; r.org_y = ray.origin.y; r.org_z = ray.origin.z;
  r.dir_x = ray.direction.x; r.dir_y = ray.direction.y; r.dir_z = ray.direction.z;
  r.tnear = 0.0f;
  r.tfar = ray.tMax;
  r.time = 0.0f;
  r.mask = 0xffffffffu;
  r.id = 0;
  r.flags = 0;
  return r;
}

}  // namespace

glm::vec3 offsetRayOrigin(const glm::vec3& p, const glm::vec3& n, float coordinateScale) {
  // Wächter and Binder's offset (Ray Tracing Gems, ch. 6): 256 ulps away from the surface, and near
  // zero, where ulps vanish, a fixed share of the coordinate scale (their constants assume a scale of 1:
  // the Cornell box scaled by 1e-4 lost 16 % of its light with them).
  // The three coordinates at once in 4-wide vectors: one shadow ray and one continuation a vertex
  // each pay this (2.7 % of a mis render's instructions as a loop over the coordinates).
  typedef float Float4 __attribute__((vector_size(16)));
  typedef int32_t Int4 __attribute__((vector_size(16)));
  const float scale = coordinateScale > 0.0f && std::isfinite(coordinateScale) ? coordinateScale : 1.0f;
  Float4 out = {p.x, p.y, p.z, 0.0f};
  offsetCoordinates<Float4, Int4>(out, Float4{n.x, n.y, n.z, 0.0f}, Float4{} + scale);
  return {out[0], out[1], out[2]};
}

Accel::Accel(const SceneData& scene) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw std::runtime_error("Embree: cannot create a device");
  // Register the error callback first, as the Embree tutorials do, so nothing later fails silently.
  rtcSetDeviceErrorFunction(device_, embreeError, &error_);
  scene_ = rtcNewScene(device_);
  // Embree's default (medium) quality, not high: high's spatial splits traced no faster on any scene here, and on the
  // million-triangle spheres they cost the first image (whole process at 1 spp 0.53-0.62x the time with medium, at 48
  // spp 0.74x; paired runs, docs/measurements/first_image.md).
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_MEDIUM);

  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const MeshData& mesh = scene.meshes[m];
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Copy into Embree-owned buffers: they carry the padding Embree's SIMD loads need.
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.positions.size()));
    std::memcpy(vertices, mesh.positions.data(), mesh.positions.size() * sizeof(glm::vec3));
    auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), mesh.indices.size() / 3));
    std::memcpy(indices, mesh.indices.data(), mesh.indices.size() * sizeof(uint32_t));

    const Material& material = scene.materials[mesh.material];
    if (material.alphaMode == AlphaMode::Mask) {
      auto mask = std::make_unique<AlphaMask>();
      mask->mesh = &mesh;
      mask->baseAlpha = material.baseAlpha;
      mask->cutoff = material.alphaCutoff;
      if (material.baseColorTexture >= 0) {
        mask->texture = &scene.textures[size_t(material.baseColorTexture)];
        mask->uvs = material.texcoordBaseColor == 1 ? &mesh.uvs1 : &mesh.uvs0;
      }
      rtcSetGeometryUserData(geom, mask.get());
      rtcSetGeometryIntersectFilterFunction(geom, alphaFilter);
      rtcSetGeometryOccludedFilterFunction(geom, alphaFilter);
      masks_.push_back(std::move(mask));
    }
    rtcCommitGeometry(geom);
    // Geometry IDs equal mesh indices: the hit maps straight back to SceneData::meshes.
    rtcAttachGeometryByID(scene_, geom, unsigned(m));
    rtcReleaseGeometry(geom);
  }
  rtcCommitScene(scene_);
  if (!error_.empty()) throw std::runtime_error(error_);
}

Accel::~Accel() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

RayHit Accel::intersect(const Ray& ray) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray = toRtcRay(ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &context, &rh);
  RayHit hit;
  if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
    hit.t = rh.ray.tfar;
    hit.mesh = rh.hit.geomID;
    hit.triangle = rh.hit.primID;
    hit.u = rh.hit.u;
    hit.v = rh.hit.v;
  }
  return hit;
}

bool Accel::occluded(const Ray& ray) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r = toRtcRay(ray);
  rtcOccluded1(scene_, &context, &r);
  return r.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
}

}  // namespace vpl
