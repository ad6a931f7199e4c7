#!/usr/bin/env python3
"""The mutation check: each mutant breaks the renderer in one way a user would see; the unit suite
must fail for every one. Usage: mutants.py list | apply NAME REPO | names.
A mutant is (name, file, the exact text it replaces, its replacement, what it breaks)."""
import sys

MUTANTS = [
    ("no-srgb-decode", "render/scene/gltf_image.cpp",
     "lut[i] = srgb ? srgbToLinear(i / 255.0f) : i / 255.0f;",
     "lut[i] = i / 255.0f;",
     "colour textures read as linear"),
    ("ggx-x0.8", "render/material/bsdf.cpp",
     "(ggx::D(h, params_.alpha) * g2 / (4.0f * wo.z));",
     "(0.8f * ggx::D(h, params_.alpha) * g2 / (4.0f * wo.z));",
     "the GGX lobe 20 % too dark"),
    ("guide-pdf-x1.05", "render/guide/guide_distribution.cpp",
     "return cellDensity_ * choice_.pmf(size_t(cellOf(w))) + defensive_ * uniformSpherePdf();",
     "return 1.05f * (cellDensity_ * choice_.pmf(size_t(cellOf(w))) + defensive_ * uniformSpherePdf());",
     "the guide's pdf 5 % too large"),
    ("no-lambert-cosine", "render/material/bsdf.cpp",
     "      f += diffuseScale_ * wi.z;",
     "      f += diffuseScale_;",
     "the Lambertian lobe without its cosine"),
    ("no-emitter-cosine", "render/scene/emitters.cpp",
     "s.pdf = pmf * dist2 / (std::abs(cosLight) * light.area);",
     "s.pdf = pmf * dist2 / light.area;",
     "area-light sampling pdf without the emitter's cosine"),
    ("no-roulette-weight", "render/integrator/path_tracer.cpp",
     "        beta /= survive;",
     "",
     "Russian roulette survivors not reweighted"),
    ("join-roulette-unweighted", "render/integrator/path_tracer.cpp",
     "            joined /= survival;",
     "",
     "a join that survives its shadow-ray roulette not reweighted"),
    ("mixture-guide-two-slots", "render/integrator/guided_continuation.cpp",
     "const bool shared = (mode_ == SamplingMode::Mis && !field_.settings().misChain) || mode_ == SamplingMode::Mixture;",
     "const bool shared = mode_ == SamplingMode::Mis && !field_.settings().misChain;",
     "mixture's guide draws its cell and the point in it from two slots, not stratified together"),
    ("selection-least-moment", "render/guide/selection_learner.cpp",
     "for (size_t k = kCount - 1; k > best; --k)",
     "for (size_t k = kCount - 1; k > kCount; --k)",
     "the learned BSDF probability takes the least second moment, without the stratification margin"),
    ("emitter-choice-unfolded", "render/scene/emitters.cpp",
     "const size_t index = distribution_.sample(u.x, &pmf, &u.x);",
     "const size_t index = distribution_.sample(uSpare, &pmf);",
     "next-event estimation chooses its emitter with a number of its own: each emitter gets a random subset of the stratified points"),
    ("light-path-emitter-unfolded", "render/scene/emitters.cpp",
     "const size_t index = distribution_.sample(uPos.x, &pmf, &uPos.x);",
     "const size_t index = distribution_.sample(uSpare, &pmf);",
     "a pass's light paths choose their emitter with a number of their own: the starts on each emitter are a random subset of the stratified points"),
    ("metropolis-always-accepts", "render/guide/metropolis_sampler.cpp",
     "if (rng.uniform() * statePdf_ < proposalPdf) {",
     "if (true) {",
     "every Metropolis proposal accepted"),
    ("no-point-light-falloff", "render/scene/emitters.cpp",
     "rangeWindow(light, s.distance) / dist2);",
     "rangeWindow(light, s.distance));",
     "point and spot lights without 1/r^2"),
    ("preview-cluster-pmf-ignored", "render/vpl/vpl_preview.cpp",
     "L += contribution / (float(m) * p);",
     "L += contribution * (float(clusters.size()) / float(m));",
     "the preview weights a sampled VPL cluster as if chosen uniformly"),
    ("preview-pixel-pmf-mismatch", "render/vpl/vpl_preview.cpp",
     "if (pmf[c] > 0.0f) pick(c, pmf[c]);",
     "if (pmf[c] > 0.0f) pick(c, 0.5f * pmf[c] + 0.5f * choice.pmf(c));",
     "the preview divides by a cluster probability other than the one it sampled by"),
    ("vpl-depth-capped-at-8", "render/vpl/vpl_tracer.cpp",
     "base.maxDepth = std::clamp(pathDepth - 1, 0, 256);",
     "base.maxDepth = std::clamp(std::min(pathDepth - 1, 8), 0, 256);",
     "VPL light paths stop at 8 bounces whatever the path tracer's depth (the preview misses long paths)"),
    ("preview-slices-not-blended", "render/vpl/vpl_preview.cpp",
     "  if (!(total > 0.0f)) return own;",
     "  return own;",
     "each preview pixel uses its own slice's clusters only (a mosaic of blocks)"),
    ("no-window-survival-weight", "render/integrator/path_tracer.cpp",
     "            beta /= d.survival;",
     "",
     "the VPL weight window's survivors not reweighted"),
    ("split-branches-keep-full-weight", "render/integrator/path_tracer.cpp",
     "const glm::vec3 branchBeta = beta / float(split);",
     "const glm::vec3 branchBeta = beta;",
     "a split path's branches each carry the whole weight"),
    ("connection-weights-miss-light-side", "render/integrator/path_tracer.cpp",
     "(y.dVCM + y.dVC * connectionMis(light.pdf));",
     "(y.dVCM);",
     "VPL connections' MIS weights forget the strategies that join further along the light path"),
    ("connection-one-segment-too-long", "render/integrator/path_tracer.cpp",
     "if (path.depth + 1 + y.length > settings_.maxDepth) return glm::vec3(0.0f);",
     "if (path.depth + 1 + y.length > settings_.maxDepth + 1) return glm::vec3(0.0f);",
     "VPL connections make paths one segment longer than --max-depth"),
    ("join-scale-of-uniform-choice", "render/integrator/light_vertex_cache.cpp",
     "cellScale_.push_back(width > 0.0 ? float(double(cellCount_[c]) / (width * double(paths) * double(joinsPerVertex_))) : 0.0f);",
     "cellScale_.push_back(float(count / (double(paths) * double(joinsPerVertex_))));",
     "learned joins divide by uniform choice's probability, not the one they were picked with"),
    ("join-mis-count-only-on-light-side", "render/integrator/path_tracer.cpp",
     "      if (connections_) path.dVCM *= connections_->misFactor(surface.position);",
     "",
     "the camera side's MIS sums leave out the joins' counts that the light side and the join put in"),
    ("learned-guide-pdf-of-the-prior", "render/integrator/guided_continuation.cpp",
     "  d.guide = pBsdf < 1.0f ? guideAt(c).pdf(wi) : 0.0f;",
     "  d.guide = pBsdf < 1.0f ? field_.point(c).distribution.pdf(wi) : 0.0f;",
     "directions drawn from the learned guide weighted by the VPL guide's pdf"),
    ("learned-guide-records-in-the-wrong-cell", "render/guide/guide_learner.cpp",
     "      sums_[size_t(r.cachePoint)][r.cell] += double(r.value);",
     "      sums_[size_t(r.cachePoint)][kCells - 1 - r.cell] += double(r.value);",
     "the learned guide puts what a direction brought back on the opposite side of the sphere"),
    ("concentric-disk-wedge-unswapped", "render/sampling/warps.h",
     "  return radius * glm::vec2(aboutX ? a.cos : a.sin, aboutX ? a.sin : a.cos);",
     "  return radius * glm::vec2(a.cos, a.sin);",
     "the concentric disk folds its y wedges onto the x ones: cosine-weighted directions miss half the hemisphere"),
    ("lazy-second-number-unmixed", "render/sampling/pixel_sampler.h",
     "      if (y_ < 0.0f) y_ = sobol::toUnitFloat(sobol::scrambledSobolSecond(index_, uint32_t(mix64(slotHash_))));",
     "      if (y_ < 0.0f) y_ = sobol::toUnitFloat(sobol::scrambledSobolSecond(index_, uint32_t(slotHash_)));",
     "a shared slot's second number, computed when asked, is scrambled with the shuffle's own seed: roulette and guide cell tied to the light choice and joins"),
    ("joins-weigh-one-each", "render/integrator/light_vertex_cache.cpp",
     "    cellScale_.push_back(width > 0.0 ? float(double(cellCount_[c]) / (width * double(paths) * double(joinsPerVertex_))) : 0.0f);",
     "    cellScale_.push_back(width > 0.0 ? float(double(cellCount_[c]) / (width * double(paths))) : 0.0f);",
     "each of a vertex's joins weighs as much as a lone join, so light carried by joins counts twice"),
]


def main():
    if sys.argv[1] == "names":
        print(" ".join(m[0] for m in MUTANTS))
    elif sys.argv[1] == "list":
        for name, path, _, _, what in MUTANTS:
            print(f"{name}\t{path}\t{what}")
    elif sys.argv[1] == "apply":
        name, repo = sys.argv[2], sys.argv[3]
        (_, path, old, new, _), = [m for m in MUTANTS if m[0] == name]
        full = f"{repo}/{path}"
        text = open(full).read()
        if text.count(old) != 1:
            sys.exit(f"{name}: the text to mutate is not in {path} exactly once (the code moved: update the mutant)")
        open(full, "w").write(text.replace(old, new))


if __name__ == "__main__":
    main()
