// `vplview converge`: renders each mode at growing time budgets (preprocessing counted, DESIGN.md §4)
// and measures relMSE and bias against a reference; writes DIR/converge.csv (the source of truth)
// and DIR/converge.png (log-log relMSE against seconds, one line per mode).
#pragma once
#include <initializer_list>
#include <string>
#include <vector>
#include <CLI/CLI.hpp>
#include "app/render_options.h"
#include "render/film/image.h"

namespace vpl::app {

struct ConvergeOptions {
  std::string reference, outDir, modes = "brdf,metropolis,mis,mixture", times = "1,2,4,8";
  void addTo(CLI::App& command);
};

// Renders are compared with the reference at its size; --width/--height, when given, must agree.
void matchReferenceSize(RenderJobSettings& settings, const Image& reference, const std::string& referencePath,
                        const CLI::App& command);

// Creates `dir` if missing and returns dir/name for each name, each checked to be writable.
std::vector<std::string> prepareOutputs(const std::string& dir, std::initializer_list<const char*> names);

// The image size is the reference's; --width/--height, when given, must agree with it.
int runConverge(const ConvergeOptions& converge, const RenderOptions& render, const CLI::App& command);

}  // namespace vpl::app
