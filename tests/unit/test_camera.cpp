// The default camera of a file without one (frameBounds): it must see the whole scene, and see a
// flat scene face on.
#include <gtest/gtest.h>

#include <cmath>
#include "render/scene/camera.h"
#include "render/scene/gltf_loader.h"
#include "render/scene/render_scene.h"
#include "support.h"

namespace vpl {
namespace {

glm::vec3 forwardOf(const CameraData& c) { return glm::normalize(c.target - c.eye); }

// Every corner of the bounds lies in front of the camera and inside its square-pixel frustum.
void expectFramed(const CameraData& c, const glm::vec3& lo, const glm::vec3& hi, float aspect) {
  const glm::vec3 forward = forwardOf(c);
  const glm::vec3 right = glm::normalize(glm::cross(forward, c.up));
  const glm::vec3 up = glm::cross(right, forward);
  const float tanY = std::tan(0.5f * c.yfov), tanX = tanY * aspect;
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 corner(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    const glm::vec3 v = corner - c.eye;
    const float depth = glm::dot(v, forward);
    ASSERT_GT(depth, 0.0f) << "corner " << i;
    EXPECT_LE(std::abs(glm::dot(v, right)) / depth, tanX) << "corner " << i;
    EXPECT_LE(std::abs(glm::dot(v, up)) / depth, tanY) << "corner " << i;
  }
}

TEST(FrameBounds, LooksAlongMinusZAtAnOrdinaryScene) {
  const glm::vec3 lo(-1.0f, 0.0f, -2.0f), hi(3.0f, 2.0f, 1.0f);
  const CameraData c = frameBounds(lo, hi);
  EXPECT_NEAR(forwardOf(c).z, -1.0f, 1e-6f);
  expectFramed(c, lo, hi, 1.0f);
}

TEST(FrameBounds, SeesAHorizontalPlaneFromAbove) {
  const glm::vec3 lo(-1.0f, 0.5f, -1.0f), hi(1.0f, 0.5f, 1.0f);
  const CameraData c = frameBounds(lo, hi);
  EXPECT_NEAR(forwardOf(c).y, -1.0f, 1e-6f);
  EXPECT_NEAR(glm::dot(glm::normalize(c.up), glm::vec3(0, 0, -1)), 1.0f, 1e-6f);  // a plan's orientation
  expectFramed(c, lo, hi, 4.0f / 3.0f);
}

TEST(FrameBounds, SeesAVerticalPlaneAlongXFaceOn) {
  const glm::vec3 lo(2.0f, -1.0f, -3.0f), hi(2.001f, 1.0f, 3.0f);
  const CameraData c = frameBounds(lo, hi);
  EXPECT_NEAR(std::abs(forwardOf(c).x), 1.0f, 1e-6f);
  expectFramed(c, lo, hi, 4.0f / 3.0f);
}

// The glTF sample TwoSidedPlane (a plane at y = 0, no camera): the default camera's central ray hits it
// (along -Z it saw only the sky).
TEST(FrameBounds, DefaultCameraSeesTheSharedTwoSidedPlane) {
  VPL_REQUIRE_SHARED_SCENE(path, "TwoSidedPlane/glTF/TwoSidedPlane.gltf");
  const RenderScene scene(loadGltf(path));
  ASSERT_FALSE(scene.data().camera.has_value());
  const Camera camera(defaultCamera(scene.data()), 64, 48);
  const RayHit hit = scene.accel().intersect(camera.generateRay(glm::vec2(32.0f, 24.0f)));
  EXPECT_TRUE(hit.valid());
}

}  // namespace
}  // namespace vpl
