// Turns the preview's slices into cache points: each slice representative gets the directions to
// its VPL cluster representatives, weighted by their estimated incoming contribution (flux, VPL
// BSDF, receiver cosine, clamped 1/d^2, visibility). Indirect light only: VPLs have bounce >= 1.
#pragma once
#include "render/guide/guide_field.h"
#include "render/scene/render_scene.h"
#include "render/vpl/vpl_preview.h"

namespace vpl {

GuideField buildGuideField(const RenderScene& scene, const VplField& field, const GuideSettings& settings);

}  // namespace vpl
