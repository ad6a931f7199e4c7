// Learned next-event estimation (render/guide/emitter_guide.h) in a closed room lit through one
// square opening in its roof: by an emitting quad above the roof, or by the uniform sky. What it must
// keep: the density a sample reports is the one pdf() (pdfSky()) gives an emitter hit (an escaped
// ray) and the one its histogram shows, before and after a region learns; a learned region's samples
// arrive more often; and the path tracer converges to the same image with learning on and off, in
// brdf and, with the quad, in mis (whose joins weigh the learned density too).
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include "render/guide/emitter_guide.h"
#include "render/scene/render_scene.h"
#include "tests/unit/pixel_agreement.h"
#include "tests/unit/scene_builders.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

constexpr float kRoof = 1.0f, kLight = 1.5f, kHalf = 2.0f, kHole = 0.3f;

// Where the light's tiles end along x and y: widening (so that its triangles differ in area).
float tileEdge(int i, int tiles) { return -kHalf + 2.0f * kHalf * std::pow(float(i) / float(tiles), 1.5f); }

// Floor at z = 0, four walls and a roof at z = kRoof over [-kHalf, kHalf]^2, the roof open over
// [-kHole, kHole]^2; with `panel`, an emitting quad of [-kHalf, kHalf]^2 at z = kLight facing down
// (else no light: the renderer's default sky), cut into tiles x tiles quads (tileEdge). Everything
// else is grey Lambertian.
SceneData skylightScene(bool panel = true, int tiles = 1) {
  SceneData s;
  s.materials.push_back(test::lambertian(0.5f));
  Material light;
  light.baseColor = glm::vec3(0.0f);
  light.emission = glm::vec3(4.0f, 3.0f, 2.0f);
  s.materials.push_back(light);
  const auto quad = [&](glm::vec2 lo, glm::vec2 hi, float z, uint32_t material, bool down) {
    MeshData m;
    m.positions = {{lo.x, lo.y, z}, {hi.x, lo.y, z}, {hi.x, hi.y, z}, {lo.x, hi.y, z}};
    m.indices = down ? std::vector<uint32_t>{0, 2, 1, 0, 3, 2} : std::vector<uint32_t>{0, 1, 2, 0, 2, 3};
    m.material = material;
    s.meshes.push_back(m);
  };
  if (panel) {  // mesh 0: the light, facing down; quad (i, j) holds triangles 2 (j tiles + i) and the next
    MeshData m;
    for (int j = 0; j < tiles; ++j)
      for (int i = 0; i < tiles; ++i) {
        const glm::vec2 lo(tileEdge(i, tiles), tileEdge(j, tiles)), hi(tileEdge(i + 1, tiles), tileEdge(j + 1, tiles));
        const auto first = uint32_t(m.positions.size());
        for (const glm::vec2 corner : {lo, glm::vec2(hi.x, lo.y), hi, glm::vec2(lo.x, hi.y)})
          m.positions.push_back(glm::vec3(corner, kLight));
        for (uint32_t k : {0u, 2u, 1u, 0u, 3u, 2u}) m.indices.push_back(first + k);
      }
    m.material = 1;
    s.meshes.push_back(m);
  }
  quad({-kHalf, -kHalf}, {kHalf, kHalf}, 0.0f, 0, false);             // the floor
  const auto wall = [&](glm::vec3 a, glm::vec3 b) {  // a vertical rectangle from edge a-b up to the roof
    MeshData m;
    m.positions = {a, b, b + glm::vec3(0, 0, kRoof), a + glm::vec3(0, 0, kRoof)};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.material = 0;
    s.meshes.push_back(m);
  };
  wall({-kHalf, -kHalf, 0}, {kHalf, -kHalf, 0});
  wall({kHalf, -kHalf, 0}, {kHalf, kHalf, 0});
  wall({kHalf, kHalf, 0}, {-kHalf, kHalf, 0});
  wall({-kHalf, kHalf, 0}, {-kHalf, -kHalf, 0});
  // The roof around the opening, in four strips.
  quad({-kHalf, -kHalf}, {kHalf, -kHole}, kRoof, 0, true);
  quad({-kHalf, kHole}, {kHalf, kHalf}, kRoof, 0, true);
  quad({-kHalf, -kHole}, {-kHole, kHole}, kRoof, 0, true);
  quad({kHole, -kHole}, {kHalf, kHole}, kRoof, 0, true);
  s.boundsMin = glm::vec3(-kHalf, -kHalf, 0.0f);
  s.boundsMax = glm::vec3(kHalf, kHalf, panel ? kLight : kRoof);
  CameraData camera;
  camera.eye = glm::vec3(0.0f, -1.9f, 0.9f);
  camera.target = glm::vec3(0.0f, 0.0f, 0.0f);
  camera.yfov = 1.2f;
  s.camera = camera;
  return s;
}

struct Uniforms {
  std::mt19937_64 engine;
  explicit Uniforms(uint64_t seed) : engine(seed) {}
  float next() { return float(engine() >> 40) * 0x1p-24f; }
  glm::vec2 next2() {
    const float a = next();
    return {a, next()};
  }
};

// The light's point along p + t w (mesh 0, cut into `tiles` x `tiles` quads), as the surface hit a
// BSDF ray would make.
std::optional<SurfaceHit> lightHit(const RenderScene& scene, const glm::vec3& p, const glm::vec3& w, int tiles = 1) {
  if (!(w.z > 0.0f)) return std::nullopt;
  const float t = (kLight - p.z) / w.z;
  const glm::vec3 x = p + t * w;
  if (std::abs(x.x) > kHalf || std::abs(x.y) > kHalf) return std::nullopt;
  // A quad's diagonal runs from its (lo, lo) corner to (hi, hi): its first triangle (vertices 0, 2, 1)
  // lies below it.
  glm::ivec2 tile(0);
  for (int axis = 0; axis < 2; ++axis)
    while (tile[axis] + 1 < tiles && x[axis] >= tileEdge(tile[axis] + 1, tiles)) ++tile[axis];
  const glm::vec2 lo(tileEdge(tile.x, tiles), tileEdge(tile.y, tiles));
  const glm::vec2 within = (glm::vec2(x) - lo) / (glm::vec2(tileEdge(tile.x + 1, tiles), tileEdge(tile.y + 1, tiles)) - lo);
  SurfaceHit hit;
  hit.position = x;
  hit.geometricNormal = glm::vec3(0.0f, 0.0f, -1.0f);
  hit.mesh = 0;
  hit.triangle = 2u * uint32_t(tile.y * tiles + tile.x) + (within.y <= within.x ? 0u : 1u);
  hit.frontFace = true;
  hit.coordinateScale = kHalf;
  (void)scene;
  return hit;
}

// Light samples from points near `centre`, their shadow rays traced, for `passes` passes.
void learn(const RenderScene& scene, EmitterGuide& guide, const glm::vec3& centre, int passes, uint64_t seed) {
  Uniforms u(seed);
  for (int pass = 0; pass < passes; ++pass) {
    for (int i = 0; i < 2000; ++i) {
      const glm::vec3 p = centre + glm::vec3(0.2f * (u.next() - 0.5f), 0.2f * (u.next() - 0.5f), 0.0f);
      const float spare = u.next();
      const auto ls = guide.sample(p, u.next2(), [&] { return spare; });
      if (!ls) continue;
      guide.attempted(ls->guideSlot);
      Ray shadow{p, ls->wi, ls->distance * (1.0f - 1e-4f)};
      if (!scene.accel().occluded(shadow)) guide.arrived(ls->guideSlot, 1.0f / ls->pdf);
    }
    guide.learnFromLastPass();
  }
}

double arrivalRate(const RenderScene& scene, const EmitterGuide& guide, const glm::vec3& p, uint64_t seed) {
  Uniforms u(seed);
  int arrived = 0, drawn = 0;
  for (int i = 0; i < 4000; ++i) {
    const float spare = u.next();
    const auto ls = guide.sample(p, u.next2(), [&] { return spare; });
    if (!ls) continue;
    ++drawn;
    if (!scene.accel().occluded(Ray{p, ls->wi, ls->distance * (1.0f - 1e-4f)})) ++arrived;
  }
  return drawn > 0 ? double(arrived) / double(drawn) : 0.0;
}

// Learns from points under the opening at p; the share of samples from p that arrive must rise from
// at most maxBefore to at least minAfter.
void expectLearningRaisesArrivals(const RenderScene& scene, EmitterGuide& guide, const glm::vec3& p, uint64_t seed,
                                  double maxBefore, double minAfter, const char* what) {
  const double before = arrivalRate(scene, guide, p, seed);
  learn(scene, guide, p, 4, seed + 1);
  EXPECT_GT(guide.learnedRegionShare(), 0.0f);
  const double after = arrivalRate(scene, guide, p, seed);
  EXPECT_LT(before, maxBefore) << what;
  EXPECT_GT(after, minAfter) << what << ", before learning " << before;
  std::printf("%s: %.3f of the samples arrive before learning, %.3f after\n", what, before, after);
}

// Per sample the reported density equals pdf() at the hit, and the histogram of directions follows it.
void expectDensityIsPdf(const RenderScene& scene, const EmitterGuide& guide, const glm::vec3& p, uint64_t seed,
                        const std::string& what, int tiles = 1) {
  Uniforms u(seed);
  int compared = 0;
  for (int i = 0; i < 20000; ++i) {
    const float spare = u.next();
    const auto ls = guide.sample(p, u.next2(), [&] { return spare; });
    if (!ls) continue;
    const auto hit = lightHit(scene, p, ls->wi, tiles);
    ASSERT_TRUE(hit.has_value()) << what;
    ASSERT_NEAR(guide.pdf(p, *hit) / ls->pdf, 1.0, 2e-3) << what << ", sample " << i;
    ++compared;
  }
  EXPECT_GT(compared, 19000) << what;
  Uniforms h(seed + 1);
  const auto chi = test::chiSquareSphere(
      [&] {
        const float spare = h.next();
        const auto ls = guide.sample(p, h.next2(), [&] { return spare; });
        return ls ? ls->wi : glm::vec3(0.0f);
      },
      [&](const glm::vec3& w) {
        const auto hit = lightHit(scene, p, w, tiles);
        return hit ? double(guide.pdf(p, *hit)) : 0.0;
      },
      300000, 64, 128, 16);
  EXPECT_GT(chi.pValue, 1e-3) << what << ": " << chi.report;
}

// The panel cut into tiles x tiles quads: its cells are a grid on each triangle up to kMaxCells
// triangles, groups of triangles beyond. At least minArrivals of the samples from under the opening
// arrive once it has learned.
void expectLearnsWhatAnOpeningShows(int tiles, double minArrivals) {
  const RenderScene scene(skylightScene(true, tiles));
  EmitterGuide guide(scene, true);
  ASSERT_TRUE(guide.active());
  EXPECT_EQ(guide.cells(), EmitterGuide::kMaxCells) << tiles << " x " << tiles << " quads";
  const glm::vec3 underHole(0.05f, 0.05f, 0.01f);
  expectDensityIsPdf(scene, guide, underHole, 3, "before learning", tiles);
  // The opening shows about (2 x 0.6)^2 / 4^2 = 9 % of the light from under it; with 70 % of the
  // choice learned, most samples should arrive.
  expectLearningRaisesArrivals(scene, guide, underHole, 5, 0.2, minArrivals, "the light through the opening");
  expectDensityIsPdf(scene, guide, underHole, 11, "after learning", tiles);
  // A light path's start, as the joins' weights ask for it: the same density times the light's cosine.
  Uniforms u(13);
  for (int i = 0; i < 1000; ++i) {
    const auto e = scene.emitters().sampleEmission(u.next(), u.next2(), u.next2());
    ASSERT_TRUE(e.has_value());
    const glm::vec3 d = e->position - underHole;
    const auto hit = lightHit(scene, underHole, glm::normalize(d), tiles);
    ASSERT_TRUE(hit.has_value());
    const float cosLight = std::abs(d.z) / glm::length(d);
    ASSERT_NEAR(guide.nextEventPdfTimesCos(underHole, *e) / (guide.pdf(underHole, *hit) * cosLight), 1.0, 2e-3);
  }
}

TEST(EmitterGuide, LearnsWhatAnOpeningShowsAndKeepsItsDensityExact) { expectLearnsWhatAnOpeningShows(1, 0.5); }

// 512 triangles of different areas: 128 groups of four, whose edges do not follow the opening's (0.49
// arrive after learning, 0.05 before).
TEST(EmitterGuide, GroupsTheTrianglesOfATessellatedLightAndKeepsItsDensityExact) {
  expectLearnsWhatAnOpeningShows(16, 0.4);
}

// The sky's version: per sample the density equals pdfSky() in its direction, and the histogram over
// the equal-area map's cells (on which the learned density is constant) follows it.
void expectSkyDensityIsPdf(const EmitterGuide& guide, const glm::vec3& p, uint64_t seed, const std::string& what) {
  Uniforms u(seed);
  for (int i = 0; i < 20000; ++i) {
    const float spare = u.next();
    const auto ls = guide.sample(p, u.next2(), [&] { return spare; });
    ASSERT_TRUE(ls.has_value()) << what;
    ASSERT_NEAR(guide.pdfSky(p, ls->wi) / ls->pdf, 1.0, 2e-3) << what << ", sample " << i;
  }
  Uniforms h(seed + 1);
  const auto chi = test::chiSquareEqualArea(
      [&] {
        const float spare = h.next();
        const auto ls = guide.sample(p, h.next2(), [&] { return spare; });
        return ls ? ls->wi : glm::vec3(0.0f);
      },
      [&](const glm::vec3& w) { return double(guide.pdfSky(p, w)); }, 300000, EmitterGuide::kSkyResolution);
  EXPECT_GT(chi.pValue, 1e-3) << what << ": " << chi.report;
}

TEST(EmitterGuide, LearnsWhereTheSkyShowsAndKeepsItsDensityExact) {
  const RenderScene scene(skylightScene(false));
  ASSERT_GE(scene.emitters().skyIndex(), 0) << "a scene without lights gets the default sky";
  EmitterGuide guide(scene, true);
  ASSERT_TRUE(guide.active());
  const glm::vec3 underHole(0.05f, 0.05f, 0.01f);
  expectSkyDensityIsPdf(guide, underHole, 23, "before learning");
  // The opening is about 0.33 sr of the sphere's 4 pi: 3 % of uniform directions leave through it.
  expectLearningRaisesArrivals(scene, guide, underHole, 29, 0.05, 0.3, "the sky through the opening");
  expectSkyDensityIsPdf(guide, underHole, 37, "after learning");
}

TEST(EmitterGuide, RegionsThatSeeTheirLightKeepEmitterSetSampling) {
  const RenderScene scene(skylightScene());
  EmitterGuide guide(scene, true);
  // Just under the roof beside the opening: the light is hidden, nothing arrives, nothing to learn.
  // On the roof's light side... (there is no such receiver in the room); so the light's own region:
  // points between the roof and the light see all of it.
  const glm::vec3 above(1.2f, 1.2f, 0.5f * (kRoof + kLight));
  learn(scene, guide, above, 4, 17);
  EXPECT_EQ(guide.learnedRegionShare(), 0.0f);
  Uniforms u(19);
  for (int i = 0; i < 1000; ++i) {
    const glm::vec2 uPoint = u.next2();
    const float spare = u.next();
    const auto a = guide.sample(above, uPoint, [&] { return spare; });
    const auto b = scene.emitters().sampleStratified(above, uPoint, spare);
    ASSERT_EQ(a.has_value(), b.has_value());
    if (a) EXPECT_EQ(a->wi, b->wi);
  }
}

// brdf with learning off is the reference; brdf and mis with it on must converge to its image.
RenderJobSettings renderSettings(SamplingMode mode, bool learnLights) {
  RenderJobSettings s;
  s.scenePath = "skylight (built in code)";
  s.mode = mode;
  s.width = 16;
  s.height = 12;
  s.spp = 512;
  s.tracer.maxDepth = 6;
  s.tracer.roulette = RouletteRule::Sqrt;
  s.tracer.learnLights = learnLights;
  s.preview.vpl.count = 1024;
  s.connections.paths = isGuided(mode) ? 64 : 0;
  return s;
}

test::BatchEstimate batches(const SceneData& data, const RenderJobSettings& base, uint64_t firstSeed, int* learned) {
  std::vector<Image> images;
  for (int b = 0; b < 12; ++b) {
    RenderJobSettings s = base;
    s.seed = firstSeed + uint64_t(b);
    const RenderJobResult r = runRenderJob(s, data);
    if (r.learnedLightRegions > 0.0) ++*learned;
    images.push_back(r.image);
  }
  return test::estimateFromBatches(images);
}

// `mode` with learning converges to brdf without it, pixel by pixel; every batch learned some region.
void expectLearningConvergesToBrdf(const SceneData& data, SamplingMode mode, uint64_t seed, const std::string& what) {
  int unused = 0, learned = 0;
  const auto reference = batches(data, renderSettings(SamplingMode::Brdf, false), seed, &unused);
  const auto learning = batches(data, renderSettings(mode, true), seed + 100, &learned);
  EXPECT_EQ(learned, 12) << what << ": every batch should have learned some region";
  test::expectAgreement(test::compareEstimates(learning, reference), what);
}

TEST(EmitterGuide, BrdfConvergesToTheSameImageWithLearning) {
  expectLearningConvergesToBrdf(skylightScene(), SamplingMode::Brdf, 100, "brdf, learning on against off");
}

// The joins weigh the learned density at their light paths' first vertices.
TEST(EmitterGuide, MisConvergesToBrdfWithLearning) {
  expectLearningConvergesToBrdf(skylightScene(), SamplingMode::Mis, 300, "mis, learning on against brdf off");
}

TEST(EmitterGuide, BrdfConvergesToTheSameImageWithLearningOnATessellatedLight) {
  expectLearningConvergesToBrdf(skylightScene(true, 16), SamplingMode::Brdf, 700, "brdf, 512 light triangles, learning on against off");
}

TEST(EmitterGuide, MisConvergesToBrdfWithLearningOnATessellatedLight) {
  expectLearningConvergesToBrdf(skylightScene(true, 16), SamplingMode::Mis, 900, "mis, 512 light triangles, learning on against brdf off");
}

TEST(EmitterGuide, BrdfUnderTheSkyConvergesToTheSameImageWithLearning) {
  expectLearningConvergesToBrdf(skylightScene(false), SamplingMode::Brdf, 500, "brdf under the sky, learning on against off");
}

}  // namespace
}  // namespace vpl
