// `vplview converge`: renders each mode at growing time budgets (preprocessing counted, DESIGN.md §4)
// and measures relMSE and bias against a reference; writes DIR/converge.csv (the source of truth)
// and DIR/converge.png (log-log relMSE against seconds, one line per mode).
#pragma once
#include <string>
#include <CLI/CLI.hpp>
#include "app/render_options.h"

namespace vpl::app {

struct ConvergeOptions {
  std::string reference, outDir, modes = "brdf,metropolis,mis,mixture", times = "1,2,4,8";
  void addTo(CLI::App& command);
};

// The image size is the reference's; --width/--height, when given, must agree with it.
int runConverge(const ConvergeOptions& converge, const RenderOptions& render, const CLI::App& command);

}  // namespace vpl::app
