// brdf's eight-lane estimator (render/integrator/path_lanes.h): the same samples as radiance(), an
// analytic furnace, and the scenes it must leave to radiance().
#include <cmath>
#include <string>
#include "render/film/image_metrics.h"
#include "render/integrator/path_lanes.h"
#include "render/session/render_job.h"
#include "tests/unit/scene_builders.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

bool cpuHasLanes() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}

RenderJobSettings brdf(int width, int height, int spp) {
  RenderJobSettings s;
  s.mode = SamplingMode::Brdf;
  s.width = width;
  s.height = height;
  s.spp = spp;
  s.seed = 3;
  return s;
}

// Renders with the lanes and without; both must have taken the path they were asked to.
std::pair<RenderJobResult, RenderJobResult> withAndWithout(RenderJobSettings s, const SceneData* data = nullptr) {
  s.tracer.lanes = true;
  RenderJobResult lanes = data ? runRenderJob(s, *data) : runRenderJob(s);
  s.tracer.lanes = false;
  RenderJobResult scalar = data ? runRenderJob(s, *data) : runRenderJob(s);
  EXPECT_EQ(lanes.lanes, PathLanes::kLanes);
  EXPECT_EQ(scalar.lanes, 1);
  return {std::move(lanes), std::move(scalar)};
}

// The lanes draw the same numbers as radiance() and make the same decisions, so sample for sample
// the images agree up to float rounding (an occasional roulette or grazing hit that rounds the other
// way): far below the noise of any estimator that differs (a wrong MIS weight, continuation or
// roulette moves whole pixels).
TEST(PathLanes, CornellBoxSamplesAreRadiancesSamples) {
  if (!cpuHasLanes()) GTEST_SKIP() << "this CPU has no AVX2 and FMA: the lanes never run";
  RenderJobSettings s = brdf(48, 36, 8);
  s.scenePath = test::sourceDir() + "/scenes/cornell_box.gltf";
  s.tracer.roulette = RouletteRule::Sqrt;
  const auto [lanes, scalar] = withAndWithout(s);
  EXPECT_LT(relMse(lanes.image, scalar.image), 1e-8);
  EXPECT_NEAR(double(lanes.rays), double(scalar.rays), 1e-4 * double(scalar.rays));
  EXPECT_NEAR(double(lanes.bsdfSamples), double(scalar.bsdfSamples), 1e-4 * double(scalar.bsdfSamples));
  EXPECT_EQ(lanes.samples, scalar.samples);
  EXPECT_EQ(lanes.discarded, 0u);
}

// The parts of radiance() the Cornell box does not reach: the sky (escaped rays, its MIS weight),
// punctual lights (no MIS), shading normals, the throughput roulette rule, learned next-event
// estimation switched off.
TEST(PathLanes, SkyPointLightShadingNormalsAndThroughputRouletteAsRadiance) {
  if (!cpuHasLanes()) GTEST_SKIP() << "this CPU has no AVX2 and FMA: the lanes never run";
  SceneData scene;
  scene.materials.push_back(test::lambertian(0.6f));
  MeshData floor;
  floor.positions = {{-4, 0, -4}, {4, 0, -4}, {4, 0, 4}, {-4, 0, 4}, {-0.5f, 0.2f, 0}, {0.5f, 0.2f, 0}, {0, 1.2f, 0}};
  floor.indices = {0, 2, 1, 0, 3, 2, 4, 5, 6};
  // Shading normals that lean away from the faces' (the triangle's flipped to the other side).
  floor.normals = {glm::normalize(glm::vec3(-0.4f, 1, -0.4f)), glm::normalize(glm::vec3(0.4f, 1, -0.4f)),
                   glm::normalize(glm::vec3(0.4f, 1, 0.4f)),   glm::normalize(glm::vec3(-0.4f, 1, 0.4f)),
                   glm::normalize(glm::vec3(-0.3f, 0, -1)),    glm::normalize(glm::vec3(0.3f, 0, -1)),
                   glm::normalize(glm::vec3(0, 0.3f, -1))};
  floor.material = 0;
  scene.meshes.push_back(floor);
  PunctualLight lamp;
  lamp.position = glm::vec3(0.5f, 1.5f, 0.8f);
  lamp.intensity = glm::vec3(3.0f, 2.5f, 2.0f);
  scene.lights.push_back(lamp);
  scene.boundsMin = glm::vec3(-4, 0, -4);
  scene.boundsMax = glm::vec3(4, 1.2f, 4);
  CameraData camera;
  camera.eye = glm::vec3(0, 2.0f, 2.5f);
  camera.target = glm::vec3(0, 0.2f, 0);
  scene.camera = camera;
  RenderJobSettings s = brdf(40, 30, 8);
  s.scenePath = "floor, triangle, lamp and sky";
  s.sky.explicitSky = true;
  s.sky.radiance = glm::vec3(0.3f, 0.4f, 0.6f);
  s.tracer.roulette = RouletteRule::Throughput;
  s.tracer.rrStartDepth = 1;
  s.tracer.learnLights = false;
  const auto [lanes, scalar] = withAndWithout(s, &scene);
  EXPECT_GT(meanRgb(scalar.image).z, 0.1);
  EXPECT_GT(scalar.rays, 2 * scalar.samples);  // most samples reach the floor and bounce
  EXPECT_LT(relMse(lanes.image, scalar.image), 1e-8);
  EXPECT_NEAR(double(lanes.rays), double(scalar.rays), 1e-4 * double(scalar.rays));
}

// Lights the Cornell box lacks (and light samples the lanes serve in a small image's first passes,
// where the Cornell box's regions all still record theirs lane by lane): several triangles of
// different sizes and colours, a two-sided one seen from both sides, a one-sided panel that the floor behind it sees from the back, a strip near enough
// to the floor to be sampled by solid angle, and a low wall.
SceneData panelLeafStripRoom() {
  SceneData scene;
  scene.materials.push_back(test::lambertian(0.6f));
  Material panel = test::lambertian(0.2f);
  panel.doubleSided = false;
  panel.emission = glm::vec3(4.0f, 2.0f, 1.0f);
  scene.materials.push_back(panel);
  Material leaf = test::lambertian(0.3f);  // two-sided
  leaf.emission = glm::vec3(0.5f, 3.0f, 0.5f);
  scene.materials.push_back(leaf);
  Material strip = panel;
  strip.emission = glm::vec3(1.0f, 1.0f, 3.0f);
  scene.materials.push_back(strip);
  MeshData room;
  room.positions = {{-2, 0, -2},  {2, 0, -2},  {2, 0, 2},    {-2, 0, 2},  {-2, 2, -2},
                    {2, 2, -2},   {-2, 2, 2},  {0.3f, 0, -2}, {0.3f, 0, 2}, {0.3f, 1, 2}, {0.3f, 1, -2}};
  // Floor, back and left walls, and a low wall across the floor that hides most of the lights from
  // the floor beyond it: regions there learn where their light samples arrive.
  room.indices = {0, 2, 1, 0, 3, 2, 0, 1, 5, 0, 5, 4, 0, 4, 6, 0, 6, 3, 7, 8, 9, 7, 9, 10};
  room.material = 0;
  MeshData panelMesh;  // stands at z = -1 facing +z: the floor behind it sees its dark back
  panelMesh.positions = {{-0.5f, 0.3f, -1}, {0.5f, 0.3f, -1}, {0.5f, 1.3f, -1}, {-0.5f, 1.3f, -1}};
  panelMesh.indices = {0, 1, 2, 0, 2, 3};
  panelMesh.material = 1;
  MeshData leafMesh;  // a small tilted triangle above the floor, lit on both sides
  leafMesh.positions = {{0.8f, 0.9f, 0.2f}, {1.3f, 1.2f, 0.0f}, {1.0f, 0.8f, 0.7f}};
  leafMesh.indices = {0, 1, 2};
  leafMesh.material = 2;
  MeshData stripMesh;  // a long strip just above the floor, facing down: the floor beneath samples it by solid angle
  stripMesh.positions = {{-1.8f, 0.15f, -1.5f}, {-1.6f, 0.15f, -1.5f}, {-1.6f, 0.15f, 1.5f}, {-1.8f, 0.15f, 1.5f}};
  stripMesh.indices = {0, 2, 1, 0, 3, 2};
  stripMesh.material = 3;
  scene.meshes = {room, panelMesh, leafMesh, stripMesh};
  scene.boundsMin = glm::vec3(-2, 0, -2);
  scene.boundsMax = glm::vec3(2, 2, 2);
  CameraData camera;
  camera.eye = glm::vec3(0.3f, 1.6f, 3.0f);
  camera.target = glm::vec3(-0.2f, 0.4f, -1.2f);
  camera.yfov = 1.1f;
  scene.camera = camera;
  return scene;
}

// Next-event estimation in lanes (sampleLights: the folded choice, the plane and side tests, the point
// by area, the shadow ray's margin, the MIS weight) against EmitterSet's, on lights the Cornell box
// lacks: several triangles of different sizes and colours, a two-sided one seen from both sides, a
// one-sided panel that the floor behind it sees from the back, and points close enough to a light
// that it is sampled by solid angle (left to EmitterSet). With the learned light sampling too: its
// plain regions the lanes serve as EmitterSet, its learned ones from the guide's pick of triangle and
// square; and with joins, whose MIS weights take the learned density.
TEST(PathLanes, LightsSampledInLanesAsEmitterSet) {
  if (!cpuHasLanes()) GTEST_SKIP() << "this CPU has no AVX2 and FMA: the lanes never run";
  const SceneData scene = panelLeafStripRoom();
  // Five emitting triangles: the lanes gather their records; without the strip, three: they select them.
  SceneData fewer = scene;
  fewer.meshes.pop_back();
  RenderJobSettings s = brdf(48, 36, 32);
  s.scenePath = "panel, leaf and strip";
  s.tracer.roulette = RouletteRule::Sqrt;
  for (const SceneData* lit : {&scene, static_cast<const SceneData*>(&fewer)})
    for (const bool learn : {false, true})
      for (const bool joins : {false, true}) {
        if (joins && !learn) continue;  // JoinsAsRadiance has those
        SCOPED_TRACE(std::string(lit == &scene ? "five" : "three") + " emitting triangles, " +
                     (learn ? "learned light sampling" : "no learning") + (joins ? ", with joins (their MIS weights)" : ""));
        s.tracer.learnLights = learn;
        s.connections.paths = joins ? 512 : 0;
        s.spp = joins ? 96 : 32;  // with joins, enough passes after the regions learned to weigh their samples
        s.connections.learnChoice = false;
        const auto [lanes, scalar] = withAndWithout(s, lit);
        EXPECT_GT(meanRgb(scalar.image).x, 0.05);
        EXPECT_LT(relMse(lanes.image, scalar.image), 1e-8);
        EXPECT_NEAR(double(lanes.rays), double(scalar.rays), 1e-4 * double(scalar.rays));
        if (learn) {  // some regions behind the low wall learned, the same ones with and without lanes
          EXPECT_GT(scalar.learnedLightRegions, 0.0);
          EXPECT_EQ(lanes.learnedLightRegions, scalar.learnedLightRegions);
        }
      }
}

// The VPL weight window: roulette by the VPLs' estimate, and splits whose branches a lane traces after
// its sample's first path, with radiance()'s numbers and branch budget. (Rounding that sends one of
// the rare paths through the door's slit another way shows more here than in the Cornell box.)
TEST(PathLanes, WeightWindowSplitsAsRadiance) {
  if (!cpuHasLanes()) GTEST_SKIP() << "this CPU has no AVX2 and FMA: the lanes never run";
  RenderJobSettings s = brdf(64, 48, 4);
  s.scenePath = test::sourceDir() + "/scenes/door_ajar.gltf";
  s.tracer.roulette = RouletteRule::Vpl;
  const auto [lanes, scalar] = withAndWithout(s);
  EXPECT_GT(scalar.branches, scalar.samples / 4);
  EXPECT_NEAR(double(lanes.branches), double(scalar.branches), 1e-3 * double(scalar.branches));
  EXPECT_NEAR(double(lanes.rays), double(scalar.rays), 1e-3 * double(scalar.rays));
  EXPECT_LT(relMse(lanes.image, scalar.image), 1e-4);
}

// Joins to light vertices (VPL connections, `brdf --connect-paths N`): bidirectional MIS weights of
// emitter hits and light samples (in lanes where sampleLights serves, lane by lane where not), the
// partial sums through splits, the shadow roulette of joins, every join depth, as radiance(). With
// the uniform choice of light vertex both draw the same joins; the learned choice sums what joins
// brought back, which rounding moves by a unit here and there, so its images agree within noise.
TEST(PathLanes, JoinsAsRadiance) {
  if (!cpuHasLanes()) GTEST_SKIP() << "this CPU has no AVX2 and FMA: the lanes never run";
  struct Case {
    const char* scene;
    int joinDepth;
    RouletteRule roulette;
    float shadowRoulette;
    double tolerance;
    int joinsPerVertex = 2;
  };
  const SceneData room = panelLeafStripRoom();
  // The same room with shading normals that lean away from its faces': a join's cosines at the camera
  // vertex and at the light vertex are the shading normals', its geometry terms the faces'.
  SceneData leaning = room;
  for (int i = 0; i < int(leaning.meshes[0].positions.size()); ++i)
    leaning.meshes[0].normals.push_back(glm::normalize(glm::vec3(0.5f * std::sin(1.7f * float(i)), 1.0f, 0.5f * std::cos(1.3f * float(i)))));
  for (const Case& c : {Case{"cornell_box", -1, RouletteRule::Sqrt, 0.0f, 1e-10},
                        Case{"cornell_box", 1, RouletteRule::Sqrt, 1.0f, 1e-10},
                        Case{"door_ajar", 0, RouletteRule::Sqrt, 0.0f, 1e-6},
                        Case{"door_ajar", -1, RouletteRule::Vpl, 1.0f, 1e-6},
                        Case{"room", -1, RouletteRule::Sqrt, 0.0f, 1e-7},
                        Case{"room", 1, RouletteRule::Sqrt, 1.0f, 1e-7},
                        Case{"leaning", -1, RouletteRule::Sqrt, 0.0f, 1e-7},
                        Case{"room", 2, RouletteRule::Sqrt, 0.0f, 1e-7, 3}}) {
    SCOPED_TRACE(std::string(c.scene) + " join depth " + std::to_string(c.joinDepth) + ", " +
                 std::to_string(c.joinsPerVertex) + " joins per vertex");
    const bool built = std::string(c.scene) == "room" || std::string(c.scene) == "leaning";
    RenderJobSettings s = brdf(48, 36, 6);
    s.scenePath = built ? "panel, leaf and strip" : test::sourceDir() + "/scenes/" + c.scene + ".gltf";
    s.tracer.roulette = c.roulette;
    s.connections.paths = 512;
    s.connections.learnChoice = false;
    s.connections.joinDepth = c.joinDepth;
    s.connections.joinsPerVertex = c.joinsPerVertex;
    s.connections.shadowRoulette = c.shadowRoulette;
    // The room's light samples in lanes: learned light sampling's first passes record every sample
    // lane by lane.
    s.tracer.learnLights = !built;
    const auto [lanes, scalar] = withAndWithout(s, !built ? nullptr : std::string(c.scene) == "room" ? &room : &leaning);
    ASSERT_GT(scalar.connectionPaths, 0);
    EXPECT_GT(meanRgb(scalar.image).y, 0.001);
    EXPECT_LT(relMse(lanes.image, scalar.image), c.tolerance);
    EXPECT_NEAR(double(lanes.rays), double(scalar.rays), 1e-3 * double(scalar.rays));
    EXPECT_EQ(lanes.branches, scalar.branches);
  }
  // The learned choice, and --join-depth auto, whose trial passes (4 to 7) the lanes leave to
  // radiance() (they weigh no counterfactual).
  RenderJobSettings s = brdf(48, 36, 12);
  s.scenePath = test::sourceDir() + "/scenes/cornell_box.gltf";
  s.connections.paths = 512;
  const auto [lanes, scalar] = withAndWithout(s);
  EXPECT_NEAR(meanRgb(lanes.image).y, meanRgb(scalar.image).y, 0.01 * meanRgb(scalar.image).y);
  EXPECT_LT(relMse(lanes.image, scalar.image), 0.01);
  EXPECT_EQ(lanes.joinDepthChosen, scalar.joinDepthChosen);
}

// Against an answer of its own: inside a closed box of albedo rho whose walls all emit le, radiance is
// le / (1 - rho) everywhere (to 32 segments, within rho^32).
TEST(PathLanes, WhiteFurnaceConverges) {
  if (!cpuHasLanes()) GTEST_SKIP() << "this CPU has no AVX2 and FMA: the lanes never run";
  const float rho = 0.5f, le = 1.0f;
  const SceneData furnace = test::furnaceScene(rho, le);
  RenderJobSettings s = brdf(24, 24, 32);
  s.scenePath = "furnace";
  s.tracer.roulette = RouletteRule::Sqrt;
  const RenderJobResult r = runRenderJob(s, furnace);
  ASSERT_EQ(r.lanes, PathLanes::kLanes);
  const double expected = le / (1.0 - rho);
  EXPECT_NEAR(meanRgb(r.image).y, expected, 0.01 * expected);
}

// What the lanes do not model goes to radiance(), never through a wrong estimator.
TEST(PathLanes, LeavesToRadianceWhatTheyDoNotModel) {
  const auto reason = [](SceneData scene, bool lanes = true) {
    const RenderScene rs(std::move(scene));
    PathTracerSettings settings;
    settings.lanes = lanes;
    return PathLanes::unsupported(PathTracer(rs, settings));
  };
  const SceneData furnace = test::furnaceScene(0.5f, 1.0f);
  if (cpuHasLanes()) {
    EXPECT_EQ(reason(furnace), "");
  } else {
    EXPECT_EQ(reason(furnace), "the CPU has no AVX2 and FMA");
    return;
  }
  EXPECT_EQ(reason(furnace, false), "--lanes off");
  SceneData glossy = furnace;
  glossy.materials[0].specularFactor = 1.0f;
  EXPECT_EQ(reason(glossy), "a material with a specular lobe");
  SceneData metal = furnace;
  metal.materials[0].metallic = 1.0f;
  EXPECT_EQ(reason(metal), "a material with a specular lobe");
  SceneData masked = furnace;
  masked.materials[0].alphaMode = AlphaMode::Mask;
  EXPECT_EQ(reason(masked), "a material with alpha");
  SceneData textured = furnace;
  textured.materials[0].baseColorTexture = 0;
  EXPECT_EQ(reason(textured), "a textured material");
}

}  // namespace
}  // namespace vpl
