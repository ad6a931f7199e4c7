// How soon the viewer's refinement comes back after a camera move, with and without the decisions
// that the first view's passes made about the scene (SessionSettings::keepSceneDecisions: mis's guide
// switch, the join depth trial's choice of every vertex). For each arm it opens a session, lets the
// first view render past those decisions, then moves the camera (a small step, as a drag does) and
// takes the seconds from the move to the new view's refining film at 1, 4, 8 and 16 spp (16: the
// default hand-over, when the preview has faded out). The arms alternate, `runs` times each; it prints
// the medians and their ratios.
// Usage: refine_after_move SCENE [width=1280] [height=720] [mode=mis] [runs=3]
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>
#include "render/core/error.h"
#include "render/scene/gltf_loader.h"
#include "render/session/guide_switch.h"
#include "render/session/progressive_session.h"

using namespace vpl;
using Clock = std::chrono::steady_clock;

namespace {

constexpr std::array<int, 4> kMilestones = {1, 4, 8, 16};
constexpr double kTimeout = 600.0;

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Polls until the shown image is the refining film at `spp` or more; false on timeout.
bool waitForRefine(const ProgressiveSession& session, int spp, Clock::time_point start) {
  for (;;) {
    const SessionStats s = session.stats();
    if ((s.stage == SessionStage::Refine || s.stage == SessionStage::Done) && s.spp >= spp) return true;
    if (since(start) > kTimeout) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

// Seconds from the move to each milestone.
std::array<double, kMilestones.size()> afterMove(std::shared_ptr<const RenderScene> scene, SessionSettings settings) {
  CameraData camera = defaultCamera(scene->data());
  ProgressiveSession session(scene, camera, settings);
  std::array<double, kMilestones.size()> seconds{};
  if (!waitForRefine(session, int(GuideSwitch::kDecisionPass) + 1, Clock::now())) return seconds;
  camera.eye += glm::vec3(0.01f * scene->radius(), 0.0f, 0.0f);
  const auto moved = Clock::now();
  session.setCamera(camera);
  // The stats keep the old view's stage and spp until the new view's first frame (the quick stage).
  for (SessionStats s = session.stats(); s.restarts < 2 || s.stage != SessionStage::Quick; s = session.stats())
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  for (size_t i = 0; i < kMilestones.size(); ++i) seconds[i] = waitForRefine(session, kMilestones[i], moved) ? since(moved) : -1.0;
  const SessionStats s = session.stats();
  std::printf("  after the move: guide switch %s, joins %s, paths at once %d\n",
              s.guideSwitchAdopted ? "kept" : s.guideGain >= 0.0 ? "measured" : "not decided yet",
              s.joinDepthAdopted ? "kept" : s.joinDepthTrial ? "on trial" : "-", s.lanes);
  return seconds;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: refine_after_move SCENE [width] [height] [mode] [runs]\n");
    return 2;
  }
  SessionSettings settings;
  settings.width = argc > 2 ? std::atoi(argv[2]) : 1280;
  settings.height = argc > 3 ? std::atoi(argv[3]) : 720;
  const auto mode = parseMode(argc > 4 ? argv[4] : "mis");
  const int runs = argc > 5 ? std::atoi(argv[5]) : 3;
  if (!mode || *mode == SamplingMode::Preview || settings.width < 1 || settings.height < 1 || runs < 1) {
    std::fprintf(stderr, "refine_after_move: bad mode, size or run count\n");
    return 2;
  }
  settings.mode = *mode;
  try {
    const auto scene = std::make_shared<const RenderScene>(loadGltf(argv[1]));
    std::array<std::array<std::vector<double>, kMilestones.size()>, 2> seconds;  // [kept][milestone]
    for (int run = 0; run < runs; ++run)
      for (int kept : {0, 1}) {
        settings.keepSceneDecisions = kept == 1;
        const auto s = afterMove(scene, settings);
        for (size_t i = 0; i < kMilestones.size(); ++i) seconds[kept][i].push_back(s[i]);
        std::printf("run %d, %s: %.2f %.2f %.2f %.2f s\n", run + 1, kept ? "kept" : "measured again", s[0], s[1], s[2], s[3]);
      }
    std::printf("%s at %dx%d (%s), %d runs each, camera move -> refining film at 1 / 4 / 8 / 16 spp (medians):\n",
                argv[1], settings.width, settings.height, modeName(settings.mode), runs);
    for (int kept : {0, 1}) {
      std::printf("  %-34s", kept ? "decisions kept across the move" : "every view measures again");
      for (size_t i = 0; i < kMilestones.size(); ++i) std::printf(" %7.2f s", median(seconds[kept][i]));
      std::printf("\n");
    }
    std::printf("  %-34s", "kept / again");
    for (size_t i = 0; i < kMilestones.size(); ++i) std::printf(" %9.2f", median(seconds[1][i]) / median(seconds[0][i]));
    std::printf("\n");
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "refine_after_move: %s\n", e.what());
    return 2;
  }
}
