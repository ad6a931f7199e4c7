// The interactive viewer: a GLFW window with an OpenGL 3.3 core context showing the progressive
// session's image through the display pipeline, camera navigation, and a Dear ImGui panel (mode,
// guide and VPL parameters, exposure, live statistics, screenshot and EXR save).
// Keys: 1-4 brdf / metropolis / mis / mixture, 5 preview, R reset camera, F frame the scene,
// WASD/QE fly, V toggle the relative-variance view, Tab hide the panel, Esc quit.
#pragma once
#include <string>
#include "render/scene/render_scene.h"
#include "render/session/progressive_session.h"

namespace vpl::ui {

struct ViewerOptions {
  std::string scenePath;
  SessionSettings session;
  SkySettings sky;
  int windowWidth = 1280, windowHeight = 720;
  float exposure = 0.0f;
  std::string screenshot;        // when set: save what the window shows after screenshotAfter seconds, then exit
  double screenshotAfter = 3.0;
  bool screenshotPanel = false;  // keep the panel in the screenshot (README pictures); off: the image alone
  std::string statsLog;          // when set: one line of frame and session figures per second (measurements)
};

// Returns the process exit status. Scene errors throw InputError before any window opens.
int runViewer(const ViewerOptions& options);

}  // namespace vpl::ui
