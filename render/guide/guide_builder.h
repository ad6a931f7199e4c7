// Turns the preview's slices into cache points: each slice representative gets the directions to
// its VPL cluster representatives, weighted by their estimated incoming contribution (flux, VPL
// BSDF, receiver cosine, clamped 1/d^2, visibility). Indirect light only: VPLs have bounce >= 1.
#pragma once
#include <optional>
#include "render/guide/guide_field.h"
#include "render/scene/render_scene.h"
#include "render/vpl/vpl_preview.h"

namespace vpl {

// One VPL as a receiver at `at` sees it: the direction and distance to it, and its weight (the
// luminance it sends towards `at`, times the receiver cosine, over d^2 clamped at minDistance), with
// visibility untested. Empty behind the receiver or when the VPL sends nothing that way.
struct VplArrival {
  glm::vec3 direction{0.0f};
  float distance = 0.0f, weight = 0.0f;
};
std::optional<VplArrival> vplArrival(const Vpl& light, const SurfaceHit& at, float minDistance);

GuideField buildGuideField(const RenderScene& scene, const VplField& field, const GuideSettings& settings);

}  // namespace vpl
