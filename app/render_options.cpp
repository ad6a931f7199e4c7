#include "app/render_options.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <thread>
#include "render/core/error.h"
#include "render/integrator/sampling_mode.h"

namespace vpl::app {

namespace {

glm::vec3 parseSky(const std::string& text) {
  std::vector<float> values;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    const float v = std::strtof(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(v) || v < 0.0f)
      throw InputError("--sky: '" + text + "' is not R,G,B (three non-negative numbers) or 0");
    values.push_back(v);
  }
  if (values.size() == 1) return glm::vec3(values[0]);
  if (values.size() != 3) throw InputError("--sky: '" + text + "' is not R,G,B (three non-negative numbers) or 0");
  return {values[0], values[1], values[2]};
}

}  // namespace

void RenderOptions::addTo(CLI::App& command, bool requireOut) {
  command.add_option("scene", scene, "glTF 2.0 scene (.gltf or .glb)")->required();
  auto* sppOpt = command.add_option("--spp", spp, "samples per pixel")->check(CLI::PositiveNumber);
  auto* timeOpt = command.add_option("--time", time, "seconds after loading (preprocessing included)")
                      ->check(CLI::PositiveNumber);
  sppOpt->excludes(timeOpt);
  addCommonTo(command);
  auto* outOpt = command.add_option("--out", out, "output image (render: OpenEXR, linear RGB float; capture: PNG)");
  if (requireOut) outOpt->required();
  command.add_option("--png", png, "also write an sRGB PNG");
}

void RenderOptions::addViewerOptionsTo(CLI::App& app) {
  app.add_option("scene", scene, "glTF 2.0 scene to open (default: the built-in Cornell box)");
  addCommonTo(app);
}

void RenderOptions::addConvergeTo(CLI::App& command) {
  command.add_option("scene", scene, "glTF 2.0 scene (.gltf or .glb)")->required();
  addCommonTo(command);
  // These commands take their modes from --modes: a --mode here would be accepted and ignored.
  command.remove_option(command.get_option("--mode"));
}

void RenderOptions::addCommonTo(CLI::App& command) {
  command.add_option("--mode", mode, "brdf | metropolis | mis | mixture | preview")
      ->check(CLI::IsMember({"brdf", "metropolis", "mis", "mixture", "preview"}));
  command.add_option("--width", width, "image width in pixels")->check(CLI::Range(1, 16384));
  command.add_option("--height", height, "image height in pixels")->check(CLI::Range(1, 16384));
  command.add_option("--seed", seed, "random seed (same seed, same image)");
  command.add_option("--threads", threads, "worker threads (0: all cores)")->check(CLI::Range(0, 1024));
  command.add_option("--max-depth", tracer.maxDepth, "maximum path length in segments (1: direct light only)")
      ->check(CLI::Range(1, 1024));
  command.add_option("--rr-start", tracer.rrStartDepth, "first path depth at which Russian roulette may end a path")
      ->check(CLI::Range(1, 1024));
  command.add_option("--roulette", roulette,
                     "Russian roulette: throughput (survival min(1, max beta)) | sqrt (its square root) | "
                     "vpl (a weight window on the VPLs' estimate, with splitting) | auto (vpl where the first passes' samples "
                     "vary more than their mean, else sqrt)")
      ->check(CLI::IsMember({"throughput", "sqrt", "vpl", "auto"}));
  command.add_option("--window", tracer.window.width, "vpl roulette: weight window width (paths within [2/(1+w), 2w/(1+w)] of the pixel's estimate go on as they are)")
      ->check(CLI::Range(1.0f, 1000.0f));
  command.add_option("--max-split", tracer.window.maxSplit, "vpl roulette: most branches a vertex splits into (1: roulette only)")
      ->check(CLI::Range(1, 64));
  command.add_option("--max-branches", tracer.window.maxBranches, "vpl roulette: most paths one camera sample grows into")
      ->check(CLI::Range(1, 1024));
  command.add_option("--connect-paths", connections.paths,
                     "VPL connections: light paths traced per pass, whose vertices every camera vertex joins by "
                     "bidirectional MIS (0: none; -1: a 32nd of the pixels, 1024 to 8192, in the guided modes, none in brdf)")
      ->check(CLI::Range(-1, 1 << 24));
  command.add_option_function<std::string>(
            "--join-choice", [this](const std::string& v) { connections.learnChoice = v == "learned"; },
            "VPL connections: which light vertex a camera vertex joins: learned (cells of the scene in proportion to "
            "what their joins brought back in earlier passes, 30 % uniform) | uniform")
      ->check(CLI::IsMember({"learned", "uniform"}));
  command.add_option("--joins", connections.joinsPerVertex,
                     "VPL connections: light vertices each camera vertex joins (one number, systematic over the choice)")
      ->check(CLI::Range(1, 16));
  command.add_option_function<std::string>(
            "--join-depth",
            [this](const std::string& v) { connections.joinDepth = v == "auto" ? ConnectionSettings::kJoinDepthAuto : std::stoi(v); },
            "VPL connections: the deepest camera vertex that joins (0: the camera ray's hit; -1: every vertex; auto, "
            "the default: passes 5 to 8 join at every vertex and are weighed as depth 1 too, then depth 1 joins if its "
            "variance x rays is below 0.88 of every vertex's; a render of 8 passes or fewer never decides); the MIS weights "
            "leave out the joins it forbids")
      ->check(CLI::IsMember({"auto", "-1", "0", "1", "2"}));
  command.add_option("--join-roulette", connections.shadowRoulette,
                     "VPL connections: a join worth less than this share of what its sample holds already traces "
                     "its shadow ray with probability worth / (share x held) and weighs 1/that (0: every join traces)")
      ->check(CLI::Range(0.0f, 100.0f));
  command.add_option_function<std::string>(
            "--light-learning", [this](const std::string& v) { tracer.learnLights = v == "on"; },
            "next-event estimation: on (the default; each region of the scene picks the parts of the emitters in proportion to "
            "what its light samples brought back in earlier passes, 30 % by power; triangle lights only) | off "
            "(by power, then by solid angle or area)")
      ->check(CLI::IsMember({"on", "off"}));
  command.add_option_function<std::string>(
            "--lanes", [this](const std::string& v) { tracer.lanes = v == "auto"; },
            "brdf: auto (the default; eight paths at a time in AVX2 lanes, the same samples, where every material is "
            "Lambertian, untextured and opaque) | off (one path at a time everywhere: the ablation)")
      ->check(CLI::IsMember({"auto", "off"}));
  command.add_option("--sky", sky, "uniform sky radiance R,G,B; 0 turns it off (default: on only without lights)");
  command.add_option("--sampler", sampler,
                     "the camera paths' numbers: sobol (stratified: Owen-scrambled Sobol', one slot per decision) | "
                     "random (independent random numbers at every slot, as the paper's sampler: an ablation)")
      ->check(CLI::IsMember({"sobol", "random"}));
  command.add_option("--exposure", exposure, "PNG exposure in stops");
  command.add_option("--vpls", preview.vpl.count, "number of VPLs")->check(CLI::Range(0, 50'000'000));
  command.add_option("--slice-size", sliceSize, "largest slice, in gather points (default: 256 preview, 512 guided modes)")
      ->check(CLI::Range(1, 1 << 24));
  command.add_option("--normal-scale", preview.slices.normalScale, "6D kd-tree normal weight (0: scene diagonal / 16)")
      ->check(CLI::NonNegativeNumber);
  command.add_option("--global-clusters", preview.clustering.globalClusters, "LightSlice global clusters")->check(CLI::Range(1, 1 << 20));
  command.add_option("--refinement-rows", preview.clustering.refinementRows,
                     "LightSlice: reduced rows nearest a slice that estimate its cluster errors")->check(CLI::Range(1, 1024));
  command.add_option("--clusters", preview.clustering.clusterBudget, "VPL clusters per slice (budget)")->check(CLI::Range(1, 1 << 20));
  command.add_option("--vpl-clamp", preview.clampFraction, "geometry clamp distance as a fraction of the scene diagonal")
      ->check(CLI::Range(0.0f, 0.99f));
  command.add_option("--cone", coneDegrees, "guide cone half-angle, degrees")->check(CLI::Range(0.01f, 180.0f));
  command.add_option("--cone-spread", guide.spreadScale,
                     "a cluster's guide cone is at least atan(this x its spread / distance); 0: the fixed cone only")
      ->check(CLI::Range(0.0f, 1000.0f));
  command.add_option("--guided-vertices", guide.guidedVertices,
                     "guide only the first N vertices of every path (the authors guided 1); 0: every vertex near a cache point")
      ->check(CLI::Range(0, 1024));
  command.add_option("--defensive", guide.defensive,
                     "uniform share of the guide pdf: the VPL guide's, and the learned guides' of the guide-only modes")
      ->check(CLI::Range(1e-6f, 1.0f));
  command.add_option("--mis-defensive", guide.misDefensive,
                     "mis: uniform share of the learned guides where the BSDF probability stays at least 0.1")
      ->check(CLI::Range(1e-6f, 1.0f));
  command.add_option("--uniform-mutation", guide.uniformMutation, "Metropolis: probability of an independent direction")
      ->check(CLI::Range(0.0f, 1.0f));
  command.add_option("--perturb", perturbDegrees, "Metropolis perturbation cone, degrees")->check(CLI::Range(0.01f, 180.0f));
  command.add_option("--mutations", guide.mutations, "Metropolis steps per direction")->check(CLI::Range(1, 1000));
  command.add_option("--bsdf-prob", bsdfProb,
                     "mis: probability of sampling the BSDF: auto (default): each cache point learns its own from the "
                     "paths, starting at 0.5 | P in [0, 1] everywhere (the paper's: 0.5)")
      ->check([](const std::string& v) -> std::string {
        if (v == "auto") return {};
        try {
          size_t used = 0;
          const float p = std::stof(v, &used);
          if (used == v.size() && p >= 0.0f && p <= 1.0f) return {};
        } catch (const std::exception&) {
        }
        return "--bsdf-prob must be auto or a number in [0, 1], not '" + v + "'";
      });
  command.add_option_function<std::string>(
            "--guide-learning", [this](const std::string& v) { guide.learnDirections = v == "on"; },
            "guided modes: on (default): each cache point's guide learns from what the paths bring back between "
            "passes, starting from the VPLs' | off: the VPL guide alone (Hua & Low)")
      ->check(CLI::IsMember({"on", "off"}));
  command.add_option_function<std::string>(
            "--guide-prior", [this](const std::string& v) { guide.vplPrior = v == "vpl"; },
            "--guide-learning on: what the guide starts from: vpl | none (uniform: learned only)")
      ->check(CLI::IsMember({"vpl", "none"}));
  command.add_option_function<std::string>(
            "--guide-interpolation", [this](const std::string& v) { guide.bilinear = v == "bilinear"; },
            "guided modes: bilinear (default): the guide's density interpolated between its cells' corners | box: "
            "constant over each cell (the paper's table)")
      ->check(CLI::IsMember({"bilinear", "box"}));
  command.add_option_function<std::string>(
            "--guide-switch", [this](const std::string& v) { guide.switchToLanes = v == "auto"; },
            "mis: auto (default): after the first 8 passes, BSDF samples eight at a time in AVX2 lanes take over where "
            "the learned BSDF probabilities forecast that the guide does not pay for its one-at-a-time paths | off: "
            "the guide throughout (the paper's estimator)")
      ->check(CLI::IsMember({"auto", "off"}));
  command.add_option("--mis-guide", misGuide,
                     "mis: where guide directions come from: exact (samples of the guide from the BSDF's stratified "
                     "number) | chain (the cache point's Metropolis chain, as the paper)")
      ->check(CLI::IsMember({"exact", "chain"}));
  command.add_option("--clusters-per-pass", preview.clustersPerPass, "clusters sampled per pixel and preview pass")
      ->check(CLI::Range(1, 1 << 16));
}

RenderJobSettings RenderOptions::toSettings() const {
  RenderJobSettings s;
  s.scenePath = scene;
  s.mode = *parseMode(mode);
  s.width = width;
  s.height = height;
  s.seed = seed;
  s.spp = spp > 0 ? spp : 16;
  s.timeBudget = time;
  s.tracer = tracer;
  s.tracer.roulette = roulette == "sqrt"  ? RouletteRule::Sqrt
                      : roulette == "vpl" ? RouletteRule::Vpl
                      : roulette == "auto" ? RouletteRule::Auto
                                           : RouletteRule::Throughput;
  s.connections = connections;
  s.stratifiedSampler = sampler != "random";
  s.preview = preview;
  if (sliceSize > 0)
    s.preview.slices.maxSliceSize = sliceSize;
  else if (isGuided(s.mode))
    s.preview.slices.maxSliceSize = kGuidedSliceSize;
  s.guide = guide;
  s.guide.learnSelection = bsdfProb == "auto";
  s.guide.misChain = misGuide == "chain";
  if (!s.guide.learnSelection) s.guide.bsdfProbability = std::stof(bsdfProb);
  s.guide.coneAngle = coneDegrees * 3.14159265f / 180.0f;
  s.guide.perturbationAngle = perturbDegrees * 3.14159265f / 180.0f;
  if (!sky.empty()) {
    s.sky.explicitSky = true;
    s.sky.radiance = parseSky(sky);
  }
  return s;
}

int RenderOptions::threadCount() const {
  return threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
}

void checkWritable(const std::string& path, const char* format) {
  const std::filesystem::path p(path);
  if (format) {
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    for (const char* image : {".exr", ".png", ".jpg", ".jpeg", ".hdr", ".tif", ".tiff", ".bmp", ".ppm"})
      if (ext == image && ext != std::string(".") + format)
        throw InputError(path + ": this file is written as " + (std::string(format) == "exr" ? "OpenEXR" : "PNG") +
                         ", not " + ext.substr(1) + ": name it ." + format);
  }
  const std::filesystem::path dir = p.has_parent_path() ? p.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) throw InputError(path + ": folder " + dir.string() + " does not exist");
  const bool existed = std::filesystem::exists(p, ec);
  std::FILE* f = std::fopen(path.c_str(), "ab");
  if (!f) throw InputError(path + ": cannot write here");
  std::fclose(f);
  if (!existed) std::filesystem::remove(p, ec);
}

}  // namespace vpl::app
