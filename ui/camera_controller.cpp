#include "ui/camera_controller.h"

#include <algorithm>
#include <cmath>

namespace vpl::ui {

namespace {
constexpr float kRadiansPerPixel = 0.005f;
constexpr float kDollyPerStep = 0.1f;   // share of the distance to the target
constexpr float kFlyPerSecond = 0.5f;   // scene radii per second
}  // namespace

CameraController::CameraController(const CameraData& start, const CameraData& framed, float sceneRadius)
    : camera_(start), start_(start), framed_(framed), radius_(std::max(sceneRadius, 1e-6f)) {}

void CameraController::set(const CameraData& c) {
  camera_ = c;
  changed_ = true;
}

void CameraController::orbit(float dx, float dy) {
  const glm::vec3 up = glm::normalize(camera_.up);
  glm::vec3 offset = camera_.eye - camera_.target;
  const float distance = glm::length(offset);
  if (!(distance > 0.0f)) return;
  // Yaw around the up axis, then pitch around the camera's right axis, short of the poles.
  const float yaw = -dx * kRadiansPerPixel;
  offset = glm::vec3(glm::dot(offset, up)) * up * (1.0f - std::cos(yaw)) + offset * std::cos(yaw) +
           glm::cross(up, offset) * std::sin(yaw);
  const glm::vec3 dir = offset / distance;
  const float elevation = std::asin(std::clamp(glm::dot(dir, up), -1.0f, 1.0f));
  const float pitch = std::clamp(elevation + dy * kRadiansPerPixel, -1.55f, 1.55f) - elevation;
  const glm::vec3 right = glm::normalize(glm::cross(up, dir));
  if (std::isfinite(right.x)) {
    const glm::vec3 rotated = dir * std::cos(pitch) + glm::cross(dir, right) * std::sin(pitch) +
                              right * glm::dot(right, dir) * (1.0f - std::cos(pitch));
    offset = glm::normalize(rotated) * distance;
  }
  CameraData c = camera_;
  c.eye = camera_.target + offset;
  set(c);
}

void CameraController::pan(float dx, float dy, int viewportHeight) {
  const glm::vec3 forward = glm::normalize(camera_.target - camera_.eye);
  const glm::vec3 right = glm::normalize(glm::cross(forward, camera_.up));
  const glm::vec3 up = glm::cross(right, forward);
  // One pixel moves the target plane by one pixel's footprint at the target's distance.
  const float perPixel = 2.0f * glm::length(camera_.target - camera_.eye) * std::tan(0.5f * camera_.yfov) /
                         float(std::max(1, viewportHeight));
  const glm::vec3 move = (-dx * right + dy * up) * perPixel;
  CameraData c = camera_;
  c.eye += move;
  c.target += move;
  set(c);
}

void CameraController::dolly(float steps) {
  const glm::vec3 offset = camera_.eye - camera_.target;
  const float scale = std::pow(1.0f - kDollyPerStep, steps);
  if (!(glm::length(offset) * scale > 1e-4f * radius_)) return;
  CameraData c = camera_;
  c.eye = camera_.target + offset * scale;
  set(c);
}

void CameraController::fly(const glm::vec3& direction, float seconds) {
  if (direction == glm::vec3(0.0f) || !(seconds > 0.0f)) return;
  const glm::vec3 forward = glm::normalize(camera_.target - camera_.eye);
  const glm::vec3 right = glm::normalize(glm::cross(forward, camera_.up));
  const glm::vec3 up = glm::cross(right, forward);
  const glm::vec3 move = (direction.x * right + direction.y * up + direction.z * forward) * (kFlyPerSecond * radius_ * seconds);
  CameraData c = camera_;
  c.eye += move;
  c.target += move;
  set(c);
}

}  // namespace vpl::ui
