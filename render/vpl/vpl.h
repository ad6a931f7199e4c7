// A virtual point light: one non-specular vertex of a light path (instant radiosity, Keller 1997).
#pragma once
#include <cstdint>
#include <glm/glm.hpp>
#include "render/material/bsdf.h"

namespace vpl {

struct Vpl {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0, 0, 1};     // shading normal, facing the side the light arrived from
  glm::vec3 flux{0.0f};          // power carried by the light path to this vertex (W), before its BSDF
  glm::vec3 incident{0, 0, 1};   // unit direction back towards where the light came from (the VPL's "wi")
  Bsdf bsdf;                     // surface response in the VPL's shading frame (glossy VPLs reflect correctly),
                                 // built once: LightSlice evaluates every VPL at every slice
  uint32_t material = 0;
  uint16_t bounce = 0;           // 0: on an emitter (direct light), >= 1: indirect

  // Radiant intensity scale used by clustering: flux luminance (Rec. 709 weights).
  float power() const { return 0.2126f * flux.x + 0.7152f * flux.y + 0.0722f * flux.z; }
};

}  // namespace vpl
