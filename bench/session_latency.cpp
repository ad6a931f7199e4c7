// How fast the viewer's session answers a camera move, and whether it survives many of them: at a
// window size and mode, it lets the session render, then moves the camera `moves` times, waiting
// after each for the first frame of the new view (the quick stage), and prints the latency from the
// move to that frame (median, 95th percentile, max). With a rapid count it then fires that many
// camera and mode changes back to back without waiting, and checks the session still renders.
// Usage: session_latency SCENE [width=1280] [height=720] [mode=mis] [moves=20] [rapid changes=1000]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>
#include "render/core/error.h"
#include "render/scene/gltf_loader.h"
#include "render/session/progressive_session.h"

using namespace vpl;
using Clock = std::chrono::steady_clock;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: session_latency SCENE [width] [height] [mode] [moves] [rapid changes]\n");
    return 2;
  }
  SessionSettings settings;
  settings.width = argc > 2 ? std::atoi(argv[2]) : 1280;
  settings.height = argc > 3 ? std::atoi(argv[3]) : 720;
  const auto mode = parseMode(argc > 4 ? argv[4] : "mis");
  const int moves = argc > 5 ? std::atoi(argv[5]) : 20, rapid = argc > 6 ? std::atoi(argv[6]) : 1000;
  if (!mode || settings.width < 1 || settings.height < 1) {
    std::fprintf(stderr, "session_latency: bad mode or size\n");
    return 2;
  }
  settings.mode = *mode;
  try {
    const auto scene = std::make_shared<const RenderScene>(loadGltf(argv[1]));
    CameraData camera = defaultCamera(scene->data());
    ProgressiveSession session(scene, camera, settings);
    std::this_thread::sleep_for(std::chrono::seconds(3));  // well into preview or refinement
    std::vector<double> latencies;
    Image image;
    uint64_t version = 0;
    session.latestImage(image, version);
    for (int i = 0; i < moves; ++i) {
      camera.eye += glm::vec3(0.01f * scene->radius(), 0.0f, 0.0f);
      const uint64_t restarts = session.stats().restarts;
      const auto moved = Clock::now();
      session.setCamera(camera);
      // The first new frame: a published image after the restart was taken up.
      for (;;) {
        if (session.latestImage(image, version) && session.stats().restarts > restarts) break;
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
      latencies.push_back(std::chrono::duration<double>(Clock::now() - moved).count());
      std::this_thread::sleep_for(std::chrono::milliseconds(400));  // let it get back into its stages
    }
    std::sort(latencies.begin(), latencies.end());
    if (!latencies.empty())
      std::printf("camera move -> first new frame at %dx%d (%s), %d moves: median %.1f ms, p95 %.1f ms, max %.1f ms\n",
                  settings.width, settings.height, modeName(settings.mode), moves, 1e3 * latencies[latencies.size() / 2],
                  1e3 * latencies[std::min(latencies.size() - 1, latencies.size() * 95 / 100)], 1e3 * latencies.back());
    const auto start = Clock::now();
    for (int i = 0; i < rapid; ++i) {
      camera.eye += glm::vec3(0.0f, 1e-3f * scene->radius(), 0.0f);
      if (i % 3 == 0) session.setMode(i % 2 ? SamplingMode::Brdf : SamplingMode::Mis);
      session.setCamera(camera);
    }
    const double posting = std::chrono::duration<double>(Clock::now() - start).count();
    const uint64_t before = version;
    std::this_thread::sleep_for(std::chrono::seconds(2));
    session.latestImage(image, version);
    std::printf("%d rapid camera/mode changes posted in %.1f ms; rendering afterwards: %s\n", rapid, 1e3 * posting,
                version > before ? "yes" : "NO");
    return version > before ? 0 : 1;
  } catch (const InputError& e) {
    std::fprintf(stderr, "session_latency: %s\n", e.what());
    return 2;
  }
}
