// Directional albedo of the GGX lobe with Schlick Fresnel, E(mu) = f0 A(mu, alpha) + f90 B(mu, alpha),
// tabulated (specular_albedo_integral.h; Kelemen & Szirmay-Kalos 2001 couple the diffuse lobe to 1 - E).
#pragma once
#include <glm/glm.hpp>

namespace vpl {

struct AlbedoTerms {
  float a = 0.0f, b = 0.0f;  // E = f0 * a + f90 * b
};

// Bilinear lookup in (cos theta, alpha); mu in [0, 1], alpha in [Bsdf::kMinAlpha, 1].
AlbedoTerms specularAlbedo(float mu, float alpha);
// Cosine-weighted hemispherical average 2 * integral E(mu) mu dmu.
AlbedoTerms averageSpecularAlbedo(float alpha);

}  // namespace vpl
