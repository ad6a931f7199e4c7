// Orbit and fly navigation over a CameraData, independent of the window system: the viewer feeds
// it mouse and key deltas, and pushes the camera to the session when changed() says so.
//   left drag: orbit around the target      right drag or scroll: dolly     middle drag: pan
//   W/S, A/D, Q/E: fly forward/back, left/right, down/up (speed follows the scene size)
//   R: back to the start camera             F: frame the whole scene
#pragma once
#include <glm/glm.hpp>
#include "render/scene/scene_data.h"

namespace vpl::ui {

class CameraController {
 public:
  CameraController(const CameraData& start, const CameraData& framed, float sceneRadius);

  void orbit(float dxPixels, float dyPixels);
  void pan(float dxPixels, float dyPixels, int viewportHeight);
  void dolly(float steps);                            // > 0 moves towards the target
  void fly(const glm::vec3& direction, float seconds);  // x right, y up, z forward, in view space
  void reset() { set(start_); }
  void frame() { set(framed_); }

  const CameraData& camera() const { return camera_; }
  bool takeChanged() {  // true once after every change
    const bool c = changed_;
    changed_ = false;
    return c;
  }

 private:
  void set(const CameraData& c);
  CameraData camera_, start_, framed_;
  float radius_;
  bool changed_ = false;
};

}  // namespace vpl::ui
