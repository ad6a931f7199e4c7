// The surface BSDF: Lambertian diffuse coupled to GGX microfacet reflection (Kelemen & Szirmay-Kalos
// energy coupling), built per hit from a Material and its texture lookups.
//
// Glossary (used across render/): wo = direction towards the viewer, wi = direction towards the
// light, both unit and pointing away from the surface. eval() includes the |cos theta_i| factor.
// pdf is per unit solid angle. Reflection only: wo and wi on opposite sides give 0.
#pragma once
#include <optional>
#include <glm/glm.hpp>
#include "render/core/frame.h"

namespace vpl {

struct BsdfParams {
  glm::vec3 diffuse{0.0f};  // Lambertian albedo: baseColor x (1 - metallic)
  glm::vec3 f0{0.04f};      // Fresnel reflectance at normal incidence (Schlick)
  float f90 = 1.0f;         // Fresnel reflectance at grazing incidence (KHR_materials_specular's specularFactor)
  float alpha = 1.0f;       // GGX alpha = roughness^2, clamped to [kMinAlpha, 1]
};

struct BsdfSample {
  glm::vec3 wi{0.0f};      // world space
  glm::vec3 weight{0.0f};  // eval(wo, wi) / pdf
  float pdf = 0.0f;        // solid angle, of the whole mixture (not only the chosen lobe)
};

class Bsdf {
 public:
  static constexpr float kMinAlpha = 1e-3f;  // keeps GGX finite as roughness -> 0

  Bsdf() = default;
  Bsdf(const BsdfParams& params, const Frame& shadingFrame);
  // The same lobes in another frame: a material's BSDF made once and placed at each hit.
  Bsdf inFrame(const Frame& shadingFrame) const {
    Bsdf b = *this;
    b.frame_ = shadingFrame;
    b.bound_ = false;
    return b;
  }
  // Keeps the terms that depend on wo alone (its albedo, lobe probability, masking), so the
  // evaluations, pdfs and samples of one path vertex compute them once. Calls with any other wo
  // compute their own; a bound BSDF belongs to one thread, as a path vertex does.
  void bindOutgoing(const glm::vec3& wo) {
    bound_ = false;
    // A lone Lambertian lobe reads only wo's cosine (cosOutgoing), toLocal(wo).z.
    outgoing_ = lambertian_ ? Outgoing{glm::vec3(0.0f, 0.0f, glm::dot(wo, frame_.n))} : outgoingTerms(wo);
    boundWo_ = wo;
    bound_ = true;
  }

  // f(wo, wi) |cos theta_i|, world-space directions.
  glm::vec3 eval(const glm::vec3& wo, const glm::vec3& wi) const;
  // Density of sample() per unit solid angle.
  float pdf(const glm::vec3& wo, const glm::vec3& wi) const;
  // eval(wo, wi), pdf(wo, wi) and pdf(wi, wo) at once, equal to theirs bit for bit: one change of
  // frame, one microfacet density, and wi's terms (which f's coupling and masking need anyway) serve
  // the reverse density too. A light sample or a join needs all three (the reverse for the MIS
  // weights of the paths that bidirectional sampling makes from the other end).
  struct Evaluation {
    glm::vec3 f{0.0f};
    float pdf = 0.0f;
    float pdfReverse = 0.0f;
  };
  Evaluation evalPdf(const glm::vec3& wo, const glm::vec3& wi) const;
  // Picks a lobe with uLobe, then samples it (GGX: visible normals, Heitz 2018). Empty if no direction.
  std::optional<BsdfSample> sample(const glm::vec3& wo, glm::vec2 u, float uLobe) const;
  // The same from one 2D number: u.x picks the lobe and, rescaled within that lobe's share, serves
  // the direction too, so a stratified u stays stratified within each lobe (and costs one number less).
  std::optional<BsdfSample> sample(const glm::vec3& wo, glm::vec2 u) const;

  const BsdfParams& params() const { return params_; }
  const Frame& frame() const { return frame_; }
  // A lone Lambertian lobe (no specular one): f = diffuse / pi, sampled by the cosine.
  bool lambertian() const { return lambertian_; }
  // True when nearly all reflection is a narrow lobe, so a light path should not store a VPL here.
  bool isNearSpecular() const;

 private:
  BsdfParams params_;
  Frame frame_;
  glm::vec3 diffuseScale_{0.0f};  // diffuse / (pi (1 - E_avg)): the coupled diffuse lobe's constant
  bool lambertian_ = false;       // no specular lobe: evaluations, densities and samples need only the cosines

  // What eval, pdf and sample need of wo besides wo itself (local frame).
  struct Outgoing {
    glm::vec3 local{0.0f};
    glm::vec3 albedo{0.0f};         // E(wo.z) per channel: the specular lobe's share of the coupling
    float specularProbability = 0;  // chance of sampling the specular lobe
    float lambda = 0;               // Smith Lambda(wo)
  };
  bool bound_ = false;
  glm::vec3 boundWo_{0.0f};
  Outgoing outgoing_;

  // E(mu) per channel; 0 without a specular lobe. A table lookup: cheaper than any cache shared
  // between the threads that read one BSDF at once (LightSlice's rows); bindOutgoing() keeps wo's.
  glm::vec3 specularAlbedo(float mu) const;
  bool hasSpecular() const { return params_.f90 > 0.0f || params_.f0.x > 0.0f || params_.f0.y > 0.0f || params_.f0.z > 0.0f; }
  float specularProbability(const glm::vec3& albedo) const;
  Outgoing outgoingTerms(const glm::vec3& woWorld) const;
  Outgoing outgoing(const glm::vec3& woWorld) const { return bound_ && woWorld == boundWo_ ? outgoing_ : outgoingTerms(woWorld); }
  // wo's cosine with the shading normal: all a Lambertian lobe needs of wo.
  float cosOutgoing(const glm::vec3& woWorld) const {
    return bound_ && woWorld == boundWo_ ? outgoing_.local.z : glm::dot(woWorld, frame_.n);
  }
  std::optional<BsdfSample> sampleLambertian(glm::vec2 u) const;
  std::optional<BsdfSample> sampleLobe(const Outgoing& wo, glm::vec2 u, bool specular) const;
  // The Kelemen-coupled diffuse lobe, given both directions' specular albedos (a lone Lambertian lobe
  // ignores them), and the microfacet lobe, given the half vector, D there and both Smith Lambdas:
  // eval and evalPdf share them.
  // (Defined in bsdf.cpp, its only user, and inlined: as calls they cost a glossy render 0.5 % more
  // instructions than the formulas written out.)
  [[gnu::always_inline]] inline glm::vec3 coupledDiffuse(const glm::vec3& albedoOut, const glm::vec3& albedoIn,
                                                         float cosIn) const;
  [[gnu::always_inline]] inline glm::vec3 microfacetF(const glm::vec3& wo, const glm::vec3& h, float d, float lambdaOut,
                                                      float lambdaIn) const;
  glm::vec3 evalLocal(const Outgoing& wo, const glm::vec3& wi) const;
  float pdfLocal(const Outgoing& wo, const glm::vec3& wi) const;
  Evaluation evalPdfLocal(const Outgoing& wo, const glm::vec3& wi) const;
};

// f0 of the glTF metallic-roughness model with KHR_materials_specular / KHR_materials_ior.
glm::vec3 fresnelF0(const glm::vec3& baseColor, float metallic, float ior, float specularFactor,
                    const glm::vec3& specularColor);
// f90: specularFactor for dielectrics, 1 for metals (KHR_materials_specular), mixed by metallic.
inline float fresnelF90(float metallic, float specularFactor) {
  const float m = glm::clamp(metallic, 0.0f, 1.0f);
  return glm::clamp(specularFactor, 0.0f, 1.0f) * (1.0f - m) + m;
}

}  // namespace vpl
