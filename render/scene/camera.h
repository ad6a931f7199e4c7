// Pinhole camera: primary rays through jittered pixel positions.
#pragma once
#include <glm/glm.hpp>
#include "render/scene/accel.h"
#include "render/scene/scene_data.h"

namespace vpl {

class Camera {
 public:
  Camera() = default;
  Camera(const CameraData& data, int width, int height);

  // Ray through image position (x, y) in pixels, (0, 0) the top-left corner of the image.
  Ray generateRay(glm::vec2 pixel) const;
  // Its direction (d) for positions (x, y) given as floats or as vectors of floats (F: the path lanes'
  // eight at once; squareRoot(v, r) sets r to v's square root); its origin is the eye. By reference:
  // vectors cross no call by value.
  template <class F, class SquareRoot>
  void directions(const F& x, const F& y, F& dx, F& dy, F& dz, SquareRoot squareRoot) const {
    const F sx = (2.0f * x / float(width_) - 1.0f) * tanHalfX_;
    const F sy = (1.0f - 2.0f * y / float(height_)) * tanHalfY_;
    dx = forward_.x + sx * right_.x + sy * up_.x;
    dy = forward_.y + sx * right_.y + sy * up_.y;
    dz = forward_.z + sx * right_.z + sy * up_.z;
    F length;
    squareRoot(dx * dx + dy * dy + dz * dz, length);
    const F inverseLength = 1.0f / length;  // glm::normalize's
    dx = dx * inverseLength, dy = dy * inverseLength, dz = dz * inverseLength;
  }

  const CameraData& data() const { return data_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  CameraData data_;
  int width_ = 1, height_ = 1;
  glm::vec3 forward_{0, 0, -1}, right_{1, 0, 0}, up_{0, 1, 0};
  float tanHalfY_ = 0.4f, tanHalfX_ = 0.4f;
};

// A camera that sees the whole scene: looking at the bounds' centre along -Z from outside the
// bounding sphere (the usual viewer default when a file has no camera), or along the thinnest axis
// where the scene is flat and -Z would see it edge on.
CameraData frameBounds(const glm::vec3& boundsMin, const glm::vec3& boundsMax, float yfov = 0.7f);

// The file's camera if it has one, else frameBounds.
CameraData defaultCamera(const SceneData& scene);

}  // namespace vpl
