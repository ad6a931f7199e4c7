#include "ui/viewer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#define GLFW_INCLUDE_NONE  // the display loads its own GL entry points (ui/gl_api.h)
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include "render/core/error.h"
#include "render/core/stopwatch.h"
#include "render/film/image_io.h"
#include "render/integrator/light_vertex_cache.h"
#include "render/scene/camera.h"
#include "render/scene/gltf_loader.h"
#include "ui/camera_controller.h"
#include "ui/display_pipeline.h"

namespace vpl::ui {

namespace {

using Clock = SteadyClock;

constexpr double kFrameSeconds = 1.0 / 60.0;

constexpr SamplingMode kModes[] = {SamplingMode::Brdf, SamplingMode::Metropolis, SamplingMode::Mis, SamplingMode::Mixture,
                                   SamplingMode::Preview};

// Window-system state the GLFW callbacks reach through the user pointer.
struct InputState {
  double scroll = 0.0;
};

class GlfwLibrary {
 public:
  GlfwLibrary() {
    glfwSetErrorCallback([](int, const char* text) { std::fprintf(stderr, "vplview: GLFW: %s\n", text); });
    ok_ = glfwInit() == GLFW_TRUE;
  }
  ~GlfwLibrary() {
    if (ok_) glfwTerminate();
  }
  bool ok() const { return ok_; }

 private:
  bool ok_ = false;
};

// Saves an image through `write`; a failure (InputError) is one line on stderr and in `message`.
template <class Write>
bool save(const std::string& path, Write write, std::string& message) {
  try {
    write(path);
    message = "saved " + path;
    return true;
  } catch (const InputError& e) {
    std::fprintf(stderr, "vplview: %s\n", e.what());
    message = e.what();
    return false;
  }
}

// The panel's editable copy of the settings that need a new session when applied.
struct PanelSettings {
  int vpls;
  int clusters;
  float coneDegrees;
  float bsdfProbability;
  bool learnSelection;  // mis: learn the BSDF probability per cache point (bsdfProbability is then the start)
  float defensive;
  float misDefensive;
  float uniformMutation;
  int roulette;  // index into kRoulettes
  bool connections;  // VPL connections in the guided modes
  bool learnedJoins;  // ... joined to vertices chosen by what earlier passes learned (else uniformly)
  int joinsPerVertex;  // ... this many per camera vertex
  int joinDepth;       // ... from camera vertices up to this depth: index into kJoinDepths
  bool learnGuides;   // guides learn from the paths between passes
  bool vplPrior;      // ... starting from the VPL guide (else from a uniform one)
  bool stratifiedSampler;  // Owen-scrambled Sobol' (else independent random numbers: the paper's)
  bool learnLights;        // next-event estimation learns which part of which light each region sees
};

constexpr RouletteRule kRoulettes[] = {RouletteRule::Auto, RouletteRule::Sqrt, RouletteRule::Throughput, RouletteRule::Vpl};
constexpr const char* kRouletteNames[] = {"auto", "sqrt", "throughput", "vpl (VPL weight window)"};

constexpr int kJoinDepths[] = {ConnectionSettings::kJoinDepthAuto, -1, 2, 1, 0};
constexpr const char* kJoinDepthNames[] = {"auto (every vertex vs up to depth 1, measured)", "every vertex", "up to depth 2",
                                           "up to depth 1", "the camera ray's hit only"};

int joinDepthIndex(int depth) {
  for (int i = 0; i < 5; ++i)
    if (kJoinDepths[i] == depth) return i;
  return 1;
}

int rouletteIndex(RouletteRule rule) {
  for (int i = 0; i < 4; ++i)
    if (kRoulettes[i] == rule) return i;
  return 0;
}

}  // namespace

int runViewer(const ViewerOptions& options) {
  // The scene first: a file that does not load never opens a window.
  SceneData data = loadGltf(options.scenePath);
  for (const std::string& notice : data.notices) std::fprintf(stderr, "vplview: note: %s\n", notice.c_str());
  auto scene = std::make_shared<const RenderScene>(std::move(data), options.sky);
  GlfwLibrary glfw;
  if (!glfw.ok()) {
    std::fprintf(stderr, "vplview: cannot open a window (no display?); use 'vplview render' or 'vplview capture'\n");
    return 1;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  const std::string title = "vplview - " + options.scenePath;
  GLFWwindow* window = glfwCreateWindow(options.windowWidth, options.windowHeight, title.c_str(), nullptr, nullptr);
  if (!window) {
    std::fprintf(stderr, "vplview: cannot create an OpenGL 3.3 core window\n");
    return 1;
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(0);  // paced by the loop below
  InputState input;
  glfwSetWindowUserPointer(window, &input);
  glfwSetScrollCallback(window, [](GLFWwindow* w, double, double dy) {
    static_cast<InputState*>(glfwGetWindowUserPointer(w))->scroll += dy;
  });

  GlApi gl;
  gl.load([](const char* name) { return reinterpret_cast<void*>(glfwGetProcAddress(name)); });
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini beside the user's files
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330");

  int exitStatus = 0;
  {
    DisplayPipeline display(gl);
    const CameraData start = defaultCamera(scene->data());
    CameraController controller(start, frameBounds(scene->data().boundsMin, scene->data().boundsMax, start.yfov),
                                scene->radius());
    SessionSettings settings = options.session;
    glfwGetFramebufferSize(window, &settings.width, &settings.height);
    settings.width = std::max(1, settings.width);
    settings.height = std::max(1, settings.height);
    auto session = std::make_unique<ProgressiveSession>(scene, start, settings);
    PanelSettings panel{settings.preview.vpl.count, settings.preview.clustering.clusterBudget,
                        settings.guide.coneAngle * 57.29578f, settings.guide.bsdfProbability, settings.guide.learnSelection,
                        settings.guide.defensive, settings.guide.misDefensive,
                        settings.guide.uniformMutation, rouletteIndex(settings.tracer.roulette),
                        settings.connections.paths != 0, settings.connections.learnChoice, settings.connections.joinsPerVertex,
                        joinDepthIndex(settings.connections.joinDepth),
                        settings.guide.learnDirections, settings.guide.vplPrior, settings.stratifiedSampler,
                        settings.tracer.learnLights};

    Image image, variance;
    uint64_t version = 0;
    float exposure = options.exposure;
    int view = 0;  // DisplayView
    bool showPanel = true;
    std::string message;
    const auto opened = Clock::now();
    auto lastFrame = Clock::now(), lastLog = Clock::now();
    int framesSinceLog = 0;
    std::FILE* log = options.statsLog.empty() ? nullptr : std::fopen(options.statsLog.c_str(), "w");
    // Key presses as edges: GLFW reports states, and a held key must act once.
    std::array<bool, GLFW_KEY_LAST + 1> wasDown{};
    auto pressed = [&](int key) {
      const bool down = glfwGetKey(window, key) == GLFW_PRESS, edge = down && !wasDown[size_t(key)];
      wasDown[size_t(key)] = down;
      return edge;
    };
    double lastX = 0.0, lastY = 0.0;
    glfwGetCursorPos(window, &lastX, &lastY);

    while (!glfwWindowShouldClose(window)) {
      // Pace the UI at kFrameSeconds: it wakes for input at once, and otherwise leaves the cores to
      // the render threads (a virtual display has no vertical sync to wait on).
      glfwWaitEventsTimeout(std::max(0.0, kFrameSeconds - secondsSince(lastFrame)));
      const double dt = secondsSince(lastFrame);
      lastFrame = Clock::now();
      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      ImGui::NewFrame();
      const ImGuiIO& io = ImGui::GetIO();

      // Navigation, unless the panel has the mouse or keyboard.
      double x = 0.0, y = 0.0;
      glfwGetCursorPos(window, &x, &y);
      int fbWidth = 0, fbHeight = 0;
      glfwGetFramebufferSize(window, &fbWidth, &fbHeight);
      if (!io.WantCaptureMouse) {
        const float dx = float(x - lastX), dy = float(y - lastY);
        if (glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS) controller.orbit(dx, dy);
        if (glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS) controller.pan(dx, dy, fbHeight);
        if (glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS) controller.dolly(-dy * 0.05f);
        if (input.scroll != 0.0) controller.dolly(float(input.scroll));
      }
      input.scroll = 0.0;
      lastX = x;
      lastY = y;
      if (!io.WantCaptureKeyboard) {
        auto down = [&](int key) { return glfwGetKey(window, key) == GLFW_PRESS ? 1.0f : 0.0f; };
        controller.fly({down(GLFW_KEY_D) - down(GLFW_KEY_A), down(GLFW_KEY_E) - down(GLFW_KEY_Q),
                        down(GLFW_KEY_W) - down(GLFW_KEY_S)},
                       float(dt));
        if (pressed(GLFW_KEY_R)) controller.reset();
        if (pressed(GLFW_KEY_F)) controller.frame();
        if (pressed(GLFW_KEY_TAB)) showPanel = !showPanel;
        if (pressed(GLFW_KEY_V)) {
          view = 1 - view;
          display.upload(view == 0 ? image : variance);
        }
        if (pressed(GLFW_KEY_ESCAPE)) glfwSetWindowShouldClose(window, GLFW_TRUE);
        for (int k = 0; k < 5; ++k)
          if (pressed(GLFW_KEY_1 + k)) session->setMode(kModes[k]);
      }
      if (controller.takeChanged()) session->setCamera(controller.camera());
      session->resize(fbWidth, fbHeight);  // ignores 0 x 0 (minimised) and unchanged sizes

      if (session->latestImage(image, version, &variance)) display.upload(view == 0 ? image : variance);
      const SessionStats stats = session->stats();

      if (showPanel && (options.screenshot.empty() || options.screenshotPanel)) {
        ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
        ImGui::SetNextWindowBgAlpha(0.8f);
        ImGui::Begin("vplview", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
        int modeIndex = 0;
        for (int k = 0; k < 5; ++k)
          if (kModes[k] == stats.mode) modeIndex = k;
        const char* names[] = {"1 BRDF", "2 Metropolis", "3 MIS", "4 mixture", "5 preview"};
        if (ImGui::Combo("mode", &modeIndex, names, 5)) session->setMode(kModes[modeIndex]);
        ImGui::SliderFloat("exposure", &exposure, -8.0f, 8.0f, "%.1f stops");
        const char* views[] = {"image", "relative variance (log, 1e-4 black .. 1 white)"};
        if (ImGui::Combo("view", &view, views, 2)) display.upload(view == 0 ? image : variance);
        ImGui::Text("%s  %d spp  %.1f s since restart", stageName(stats.stage), stats.spp, stats.sinceRestart);
        ImGui::Text("%.3g samples/s  %.3g rays/s  first frame %.0f ms", stats.samplesPerSecond, stats.raysPerSecond,
                    1e3 * stats.firstFrameSeconds);
        ImGui::Text("VPLs %zu (%.2f s)  clusters %.2f s  guide %.2f s  cache points %zu", stats.vpls, stats.vplSeconds,
                    stats.clusterSeconds, stats.guideSeconds, stats.cachePoints);
        ImGui::Text("UI %.0f fps  paths at once %d  discarded samples %llu  roulette %s", io.Framerate, stats.lanes,
                    static_cast<unsigned long long>(stats.discarded), stats.rouletteWindow ? "VPL window" : settings.tracer.roulette == RouletteRule::Throughput ? "throughput" : "sqrt");
        if (stats.mode == SamplingMode::Mis && stats.learnedBsdfProbability >= 0.0)
          ImGui::Text("MIS BSDF probability: %.2f (mean learned over cache points)", stats.learnedBsdfProbability);
        if (stats.mode == SamplingMode::Mis && stats.guideSwitchAdopted)
          ImGui::Text("guide: BSDF samples in lanes from the first pass (an earlier view's forecast gain %.2f)", stats.guideGain);
        else if (stats.mode == SamplingMode::Mis && stats.guideSwitchPass > 0)
          ImGui::Text("guide: forecast gain %.2f, BSDF samples in lanes from pass %d", stats.guideGain, stats.guideSwitchPass);
        else if (stats.mode == SamplingMode::Mis && stats.guideGain >= 0.0)
          ImGui::Text("guide: forecast gain %.2f, kept", stats.guideGain);
        if (stats.joinDepth != SessionStats::kNoJoins)
          ImGui::Text("joins: %s%s", stats.joinDepth < 0 ? "from every vertex" : ("up to depth " + std::to_string(stats.joinDepth)).c_str(),
                      stats.joinDepthTrial    ? (stats.joinDepthDecided ? " (auto: measured best)" : " (auto: trying the depths)")
                      : stats.joinDepthAdopted ? " (auto: measured best in an earlier view)"
                                               : "");
        if (stats.learnedLightRegions >= 0.0)
          ImGui::Text("light samples: %.0f %% of the regions learned which lights they see", 100.0 * stats.learnedLightRegions);
        if (isGuided(stats.mode) && stats.learnedGuideShare >= 0.0)
          ImGui::Text("guides: %.0f %% learned from the paths (mean over cache points)", 100.0 * stats.learnedGuideShare);
        if (ImGui::CollapsingHeader("VPLs and guide")) {
          ImGui::InputInt("VPLs", &panel.vpls, 1024, 8192);
          ImGui::InputInt("clusters per slice", &panel.clusters, 10, 100);
          ImGui::SliderFloat("cone (deg)", &panel.coneDegrees, 1.0f, 90.0f);
          ImGui::SliderFloat("MIS BSDF probability", &panel.bsdfProbability, 0.0f, 1.0f);
          ImGui::Checkbox("learn it per cache point", &panel.learnSelection);
          ImGui::SliderFloat("defensive", &panel.defensive, 0.001f, 1.0f);
          ImGui::SliderFloat("defensive, mis's learned guides", &panel.misDefensive, 0.001f, 1.0f);
          ImGui::SliderFloat("uniform mutation", &panel.uniformMutation, 0.0f, 1.0f);
          ImGui::Combo("roulette", &panel.roulette, kRouletteNames, 4);
          ImGui::Checkbox("VPL connections (guided modes)", &panel.connections);
          ImGui::Checkbox("learn which light vertex a join picks", &panel.learnedJoins);
          ImGui::SliderInt("joins per camera vertex", &panel.joinsPerVertex, 1, LightVertexCache::kMaxJoinsPerVertex);
          ImGui::Combo("camera vertices that join", &panel.joinDepth, kJoinDepthNames, 5);
          ImGui::Checkbox("learn the guides from the paths", &panel.learnGuides);
          ImGui::Checkbox("start learning from the VPL guide", &panel.vplPrior);
          ImGui::Checkbox("stratified sampler (else independent random numbers)", &panel.stratifiedSampler);
          ImGui::Checkbox("learn which part of which light each region sees", &panel.learnLights);
          if (ImGui::Button("apply (restarts)")) {
            SessionSettings next = settings;
            next.mode = stats.mode;
            next.width = std::max(1, fbWidth);
            next.height = std::max(1, fbHeight);
            next.preview.vpl.count = std::clamp(panel.vpls, 0, 10'000'000);
            next.preview.clustering.clusterBudget = std::clamp(panel.clusters, 1, 1 << 16);
            next.guide.coneAngle = std::clamp(panel.coneDegrees, 1.0f, 90.0f) / 57.29578f;
            next.guide.bsdfProbability = std::clamp(panel.bsdfProbability, 0.0f, 1.0f);
            next.guide.learnSelection = panel.learnSelection;
            next.guide.defensive = std::clamp(panel.defensive, 0.001f, 1.0f);
            next.guide.misDefensive = std::clamp(panel.misDefensive, 0.001f, 1.0f);
            next.guide.uniformMutation = std::clamp(panel.uniformMutation, 0.0f, 1.0f);
            next.tracer.roulette = kRoulettes[std::clamp(panel.roulette, 0, 3)];
            if (panel.connections != (settings.connections.paths != 0)) next.connections.paths = panel.connections ? -1 : 0;
            next.connections.learnChoice = panel.learnedJoins;
            next.connections.joinsPerVertex = std::clamp(panel.joinsPerVertex, 1, LightVertexCache::kMaxJoinsPerVertex);
            next.connections.joinDepth = kJoinDepths[std::clamp(panel.joinDepth, 0, 4)];
            next.guide.learnDirections = panel.learnGuides;
            next.guide.vplPrior = panel.vplPrior;
            next.stratifiedSampler = panel.stratifiedSampler;
            next.tracer.learnLights = panel.learnLights;
            session.reset();  // joins the old controller before the new one starts
            session = std::make_unique<ProgressiveSession>(scene, controller.camera(), next);
            settings = next;
            version = 0;
          }
        }
        // A failed save is reported and the session goes on; the earlier file stays as it was.
        if (ImGui::Button("screenshot PNG"))
          save("vplview_screenshot.png", [&](const std::string& path) {
            writePngBytes(path, fbWidth, fbHeight, display.readPixels(fbWidth, fbHeight));
          }, message);
        ImGui::SameLine();
        // The estimate, not the display's fade over the preview: an EXR is data, read back as radiance.
        if (ImGui::Button("save EXR")) {
          const ProgressiveSession::Estimate estimate = session->latestEstimate();
          if (estimate.image.width > 0 &&
              save("vplview_image.exr", [&](const std::string& path) { writeExr(path, estimate.image); }, message)) {
            const bool film = estimate.stage == SessionStage::Refine ||
                              (estimate.stage == SessionStage::Done && stats.mode != SamplingMode::Preview);
            message += std::string(" (") + modeName(stats.mode) + ", " + stageName(estimate.stage) + ", " +
                       std::to_string(estimate.spp) + (film ? " spp)" : estimate.spp == 1 ? " pass)" : " passes)");
          }
        }
        if (!message.empty()) ImGui::TextUnformatted(message.c_str());
        ImGui::End();
      }
      ImGui::Render();

      const bool shoot = fbWidth > 0 && fbHeight > 0 && !options.screenshot.empty() && secondsSince(opened) >= options.screenshotAfter;
      if (fbWidth > 0 && fbHeight > 0) {
        display.draw(fbWidth, fbHeight, exposure, DisplayView(view));
        // What the window shows: read before the panel is drawn over it, unless it is wanted.
        // --screenshot: a failed write ends the viewer with status 2 (DESIGN.md §3), after cleaning up.
        auto screenshot = [&] {
          const auto write = [&](const std::string& path) {
            writePngBytes(path, fbWidth, fbHeight, display.readPixels(fbWidth, fbHeight));
          };
          if (!save(options.screenshot, write, message)) exitStatus = 2;
        };
        if (shoot && !options.screenshotPanel) screenshot();
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        if (shoot && options.screenshotPanel) screenshot();
        if (shoot) glfwSetWindowShouldClose(window, GLFW_TRUE);
      }
      glfwSwapBuffers(window);
      ++framesSinceLog;
      // The screenshot's frame is always logged: a script can tell which stage it shows.
      if (log && (secondsSince(lastLog) >= 1.0 || shoot)) {
        std::fprintf(log,
                     "t %.2f fps %.1f stage %s spp %d first_frame_ms %.1f first_preview_ms %.1f refine_start_ms %.1f "
                     "samples_per_s %.4g\n",
                     secondsSince(opened), framesSinceLog / secondsSince(lastLog), stageName(stats.stage), stats.spp,
                     1e3 * stats.firstFrameSeconds, 1e3 * stats.firstPreviewSeconds, 1e3 * stats.refineStartSeconds,
                     stats.samplesPerSecond);
        std::fflush(log);
        framesSinceLog = 0;
        lastLog = Clock::now();
      }
      if (glfwGetWindowAttrib(window, GLFW_ICONIFIED)) glfwWaitEventsTimeout(0.1);
    }
    if (log) std::fclose(log);
    session.reset();  // stop rendering before the GL objects go
  }
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  return exitStatus;
}

}  // namespace vpl::ui
