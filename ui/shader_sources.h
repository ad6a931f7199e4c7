// GLSL of the display pipeline (shaders/), embedded at build time so the binary runs from anywhere.
#pragma once

namespace vpl::ui {
extern const char* const kDisplayVertexShader;
extern const char* const kDisplayFragmentShader;
}  // namespace vpl::ui
