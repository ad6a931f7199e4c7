#include "render/scene/camera.h"

#include <algorithm>
#include <cmath>

namespace vpl {

Camera::Camera(const CameraData& data, int width, int height)
    : data_(data), width_(std::max(1, width)), height_(std::max(1, height)) {
  glm::vec3 forward = data.target - data.eye;
  if (!(glm::dot(forward, forward) > 0.0f)) forward = glm::vec3(0, 0, -1);
  forward_ = glm::normalize(forward);
  glm::vec3 right = glm::cross(forward_, data.up);
  if (!(glm::dot(right, right) > 1e-12f)) right = glm::cross(forward_, std::abs(forward_.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0));
  right_ = glm::normalize(right);
  up_ = glm::cross(right_, forward_);
  const float yfov = std::clamp(data.yfov, 1e-3f, 3.1f);
  tanHalfY_ = std::tan(0.5f * yfov);
  // The image's own aspect wins over the file's aspectRatio: pixels stay square.
  tanHalfX_ = tanHalfY_ * float(width_) / float(height_);
}

Ray Camera::generateRay(glm::vec2 pixel) const {
  Ray ray;
  ray.origin = data_.eye;
  directions(pixel.x, pixel.y, ray.direction.x, ray.direction.y, ray.direction.z,
             [](float v, float& r) { r = std::sqrt(v); });
  return ray;
}

CameraData frameBounds(const glm::vec3& boundsMin, const glm::vec3& boundsMax, float yfov) {
  CameraData c;
  const glm::vec3 centre = 0.5f * (boundsMin + boundsMax);
  float radius = 0.5f * glm::length(boundsMax - boundsMin);
  if (!(radius > 0.0f) || !std::isfinite(radius)) radius = 1.0f;
  const float distance = radius / std::sin(0.5f * yfov) * 1.05f;
  c.target = centre;
  c.eye = centre + glm::vec3(0, 0, distance);
  c.up = glm::vec3(0, 1, 0);
  // A flat scene seen edge on would be a line on a blank image (a ground plane along -Z): look along
  // its thinnest axis instead, from above for a horizontal one (-Z up, as a plan is drawn).
  const glm::vec3 extent = boundsMax - boundsMin;
  const float largest = std::max({extent.x, extent.y, extent.z});
  if (std::min(extent.x, extent.y) < 0.01f * largest) {
    if (extent.y <= extent.x) {
      c.eye = centre + glm::vec3(0, distance, 0);
      c.up = glm::vec3(0, 0, -1);
    } else {
      c.eye = centre + glm::vec3(distance, 0, 0);
    }
  }
  c.yfov = yfov;
  return c;
}

CameraData defaultCamera(const SceneData& scene) {
  return scene.camera ? *scene.camera : frameBounds(scene.boundsMin, scene.boundsMax);
}

}  // namespace vpl
