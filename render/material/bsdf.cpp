#include "render/material/bsdf.h"

#include <algorithm>
#include <cmath>
#include "render/core/color.h"
#include "render/material/ggx.h"
#include "render/material/specular_albedo.h"
#include "render/sampling/warps.h"

namespace vpl {

glm::vec3 fresnelF0(const glm::vec3& baseColor, float metallic, float ior, float specularFactor,
                    const glm::vec3& specularColor) {
  const float r = (ior - 1.0f) / (ior + 1.0f);
  const float f0Ior = std::isfinite(r) ? r * r : 0.04f;
  const glm::vec3 dielectric = glm::min(glm::vec3(f0Ior) * specularColor, glm::vec3(1.0f)) * specularFactor;
  const float m = glm::clamp(metallic, 0.0f, 1.0f);
  return glm::clamp(dielectric * (1.0f - m) + baseColor * m, glm::vec3(0.0f), glm::vec3(1.0f));
}

Bsdf::Bsdf(const BsdfParams& params, const Frame& shadingFrame) : params_(params), frame_(shadingFrame) {
  params_.alpha = std::clamp(params_.alpha, kMinAlpha, 1.0f);
  params_.diffuse = glm::clamp(params_.diffuse, glm::vec3(0.0f), glm::vec3(1.0f));
  params_.f0 = glm::clamp(params_.f0, glm::vec3(0.0f), glm::vec3(1.0f));
  params_.f90 = std::clamp(params_.f90, 0.0f, 1.0f);
  lambertian_ = !hasSpecular();
  if (!isBlack(params_.diffuse) && lambertian_) {
    diffuseScale_ = params_.diffuse * kInvPi;  // pure Lambertian: no coupling needed
  } else if (!isBlack(params_.diffuse)) {
    const AlbedoTerms avg = averageSpecularAlbedo(params_.alpha);
    const glm::vec3 eAvg = params_.f0 * avg.a + params_.f90 * avg.b;
    // Kelemen & Szirmay-Kalos (2001): the diffuse lobe gets what the specular lobe leaves, reciprocally.
    diffuseScale_ = params_.diffuse * kInvPi / glm::max(glm::vec3(1.0f) - eAvg, glm::vec3(1e-4f));
  }
}

glm::vec3 Bsdf::specularAlbedo(float mu) const {
  if (!hasSpecular()) return glm::vec3(0.0f);
  const AlbedoTerms e = vpl::specularAlbedo(mu, params_.alpha);
  return glm::clamp(params_.f0 * e.a + params_.f90 * e.b, glm::vec3(0.0f), glm::vec3(1.0f));
}

// Probability of sampling the specular lobe: its share of the albedo seen from wo.
float Bsdf::specularProbability(const glm::vec3& albedo) const {
  if (!hasSpecular()) return 0.0f;
  const float spec = luminance(albedo);
  const float diff = luminance(params_.diffuse * (glm::vec3(1.0f) - albedo));
  if (spec + diff <= 0.0f) return 0.5f;
  return spec / (spec + diff);
}

Bsdf::Outgoing Bsdf::outgoingTerms(const glm::vec3& woWorld) const {
  Outgoing o;
  o.local = frame_.toLocal(woWorld);
  if (hasSpecular() && o.local.z > 0.0f) {
    o.albedo = specularAlbedo(o.local.z);
    o.specularProbability = specularProbability(o.albedo);
    o.lambda = ggx::lambda(o.local, params_.alpha);
  }
  return o;
}

namespace {

// wo + wi normalised into h; false where they are opposite.
bool halfVector(const glm::vec3& wo, const glm::vec3& wi, glm::vec3& h) {
  h = wo + wi;
  const float len = glm::length(h);
  if (!(len > 1e-8f)) return false;
  h /= len;
  return true;
}

}  // namespace

glm::vec3 Bsdf::coupledDiffuse(const glm::vec3& albedoOut, const glm::vec3& albedoIn, float cosIn) const {
  return hasSpecular() ? diffuseScale_ * (glm::vec3(1.0f) - albedoOut) * (glm::vec3(1.0f) - albedoIn) * cosIn
                       : diffuseScale_ * cosIn;
}

// F D G2 / (4 cos_o cos_i), times cos_i; G2 is height-correlated Smith, 1 / (1 + Lambda_o + Lambda_i).
glm::vec3 Bsdf::microfacetF(const glm::vec3& wo, const glm::vec3& h, float d, float lambdaOut, float lambdaIn) const {
  const float g2 = 1.0f / (1.0f + lambdaOut + lambdaIn);
  return ggx::schlick(params_.f0, params_.f90, glm::dot(wo, h)) * (d * g2 / (4.0f * wo.z));
}

glm::vec3 Bsdf::evalLocal(const Outgoing& o, const glm::vec3& wi) const {
  const glm::vec3& wo = o.local;
  if (wo.z <= 0.0f || wi.z <= 0.0f) return glm::vec3(0.0f);
  glm::vec3 f(0.0f);
  if (!isBlack(diffuseScale_)) f += coupledDiffuse(o.albedo, specularAlbedo(wi.z), wi.z);
  if (glm::vec3 h; hasSpecular() && halfVector(wo, wi, h))
    f += microfacetF(wo, h, ggx::D(h, params_.alpha), o.lambda, ggx::lambda(wi, params_.alpha));
  return f;
}

float Bsdf::pdfLocal(const Outgoing& o, const glm::vec3& wi) const {
  const glm::vec3& wo = o.local;
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  const float pSpec = o.specularProbability;
  float pdf = (1.0f - pSpec) * cosineHemispherePdf(wi.z);
  if (glm::vec3 h; pSpec > 0.0f && halfVector(wo, wi, h))
    pdf += pSpec * ggx::reflectionPdf(o.lambda, ggx::D(h, params_.alpha), wo.z);
  return pdf;
}

// The Lambertian shortcuts below compute what evalLocal, pdfLocal and sampleLobe give without a
// specular lobe, with the same arithmetic (images are bit-identical), from the cosines alone.
glm::vec3 Bsdf::eval(const glm::vec3& wo, const glm::vec3& wi) const {
  if (lambertian_) {
    const float cosIn = glm::dot(wi, frame_.n);
    return cosOutgoing(wo) <= 0.0f || cosIn <= 0.0f ? glm::vec3(0.0f) : diffuseScale_ * cosIn;
  }
  return evalLocal(outgoing(wo), frame_.toLocal(wi));
}

float Bsdf::pdf(const glm::vec3& wo, const glm::vec3& wi) const {
  if (lambertian_) {
    const float cosIn = glm::dot(wi, frame_.n);
    return cosOutgoing(wo) <= 0.0f || cosIn <= 0.0f ? 0.0f : cosineHemispherePdf(cosIn);
  }
  return pdfLocal(outgoing(wo), frame_.toLocal(wi));
}

Bsdf::Evaluation Bsdf::evalPdf(const glm::vec3& wo, const glm::vec3& wi) const {
  if (lambertian_) {
    const float cosIn = glm::dot(wi, frame_.n);
    if (cosOutgoing(wo) <= 0.0f || cosIn <= 0.0f) return {};
    // pdf(wi, wo) takes wo's cosine as pdf() takes wi's (a bound one may differ in its last bit).
    return {diffuseScale_ * cosIn, cosineHemispherePdf(cosIn), cosineHemispherePdf(glm::dot(wo, frame_.n))};
  }
  return evalPdfLocal(outgoing(wo), frame_.toLocal(wi));
}

// evalLocal, pdfLocal and pdfLocal with the directions swapped, in their own arithmetic: wi's albedo,
// lobe probability and Smith Lambda are what outgoingTerms(wi) would give, the half vector and D are
// the same both ways.
Bsdf::Evaluation Bsdf::evalPdfLocal(const Outgoing& o, const glm::vec3& wi) const {
  const glm::vec3& wo = o.local;
  if (wo.z <= 0.0f || wi.z <= 0.0f) return {};
  glm::vec3 albedoIn(0.0f);
  float lambdaIn = 0.0f, specularIn = 0.0f;
  if (hasSpecular()) {
    albedoIn = specularAlbedo(wi.z);
    lambdaIn = ggx::lambda(wi, params_.alpha);
    specularIn = specularProbability(albedoIn);
  }
  Evaluation e;
  if (!isBlack(diffuseScale_)) e.f += coupledDiffuse(o.albedo, albedoIn, wi.z);
  e.pdf = (1.0f - o.specularProbability) * cosineHemispherePdf(wi.z);
  e.pdfReverse = (1.0f - specularIn) * cosineHemispherePdf(wo.z);
  if (glm::vec3 h; hasSpecular() && halfVector(wo, wi, h)) {
    const float d = ggx::D(h, params_.alpha);
    e.f += microfacetF(wo, h, d, o.lambda, lambdaIn);
    if (o.specularProbability > 0.0f) e.pdf += o.specularProbability * ggx::reflectionPdf(o.lambda, d, wo.z);
    if (specularIn > 0.0f) e.pdfReverse += specularIn * ggx::reflectionPdf(lambdaIn, d, wi.z);
  }
  return e;
}

std::optional<BsdfSample> Bsdf::sample(const glm::vec3& woWorld, glm::vec2 u, float uLobe) const {
  if (lambertian_) return cosOutgoing(woWorld) <= 0.0f ? std::nullopt : sampleLambertian(u);
  const Outgoing o = outgoing(woWorld);
  if (o.local.z <= 0.0f) return std::nullopt;
  return sampleLobe(o, u, uLobe < o.specularProbability);
}

std::optional<BsdfSample> Bsdf::sample(const glm::vec3& woWorld, glm::vec2 u) const {
  if (lambertian_) return cosOutgoing(woWorld) <= 0.0f ? std::nullopt : sampleLambertian(glm::vec2(std::min(u.x, 0x1.fffffep-1f), u.y));
  const Outgoing o = outgoing(woWorld);
  if (o.local.z <= 0.0f) return std::nullopt;
  const float pSpec = o.specularProbability;
  const bool specular = u.x < pSpec;  // never true when pSpec is 0, always when it is 1
  u.x = std::min(specular ? u.x / pSpec : (u.x - pSpec) / (1.0f - pSpec), 0x1.fffffep-1f);
  return sampleLobe(o, u, specular);
}

std::optional<BsdfSample> Bsdf::sampleLobe(const Outgoing& o, glm::vec2 u, bool specular) const {
  const glm::vec3& wo = o.local;
  glm::vec3 wi;
  if (specular) {
    const glm::vec3 h = ggx::sampleVisibleNormal(wo, u, params_.alpha);
    wi = 2.0f * glm::dot(wo, h) * h - wo;
  } else {
    wi = sampleCosineHemisphere(u);  // the diffuse lobe beside a specular one (a lone one: sampleLambertian)
  }
  if (wi.z <= 0.0f) return std::nullopt;
  const Evaluation e = evalPdfLocal(o, wi);
  if (!(e.pdf > 0.0f) || !std::isfinite(e.pdf)) return std::nullopt;
  BsdfSample s;
  s.wi = glm::normalize(frame_.toWorld(wi));
  s.pdf = e.pdf;
  s.weight = e.f / e.pdf;
  if (!isFiniteNonNegative(s.weight)) return std::nullopt;
  return s;
}

// A lone Lambertian lobe sampled by its cosine: f cos / pdf is its albedo, no evaluation needed.
std::optional<BsdfSample> Bsdf::sampleLambertian(glm::vec2 u) const {
  const glm::vec3 wi = sampleCosineHemisphere(u);
  if (!(wi.z > 0.0f)) return std::nullopt;
  return BsdfSample{glm::normalize(frame_.toWorld(wi)), params_.diffuse, wi.z * kInvPi};
}

bool Bsdf::isNearSpecular() const {
  // Below alpha 0.01 (roughness 0.1) the lobe is a few degrees wide: a VPL there would light the
  // scene in sharp spikes, so light paths pass through it without storing one.
  return params_.alpha < 0.01f && specularProbability(specularAlbedo(1.0f)) > 0.9f;
}

}  // namespace vpl
