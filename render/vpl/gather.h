// Gather points: the primary hit at the centre of every pixel, the receivers that slices (and the
// guide's cache points) are built from. Camera-dependent; rebuilt when the camera moves.
#pragma once
#include <cstdint>
#include <vector>
#include "render/cluster/slice_tree.h"
#include "render/scene/camera.h"
#include "render/scene/render_scene.h"

namespace vpl {

struct CameraGather {
  std::vector<GatherPoint> points;
  std::vector<SurfaceHit> hits;      // per gather point
  std::vector<glm::vec3> wo;         // per gather point: unit direction back to the camera
  std::vector<int32_t> pixelGather;  // per pixel: gather point index, or -1 (miss or emitter)
  uint64_t rays = 0;
};

CameraGather gatherPrimaryHits(const RenderScene& scene, const Camera& camera);

}  // namespace vpl
