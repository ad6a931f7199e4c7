// `vplview sweep`: what a parameter buys at equal time. For every --vary FLAG=V1,V2,... it renders
// each value (all other flags as given) for each mode and budget, preprocessing counted, plus the
// defaults once, and measures relMSE and bias against a reference; writes DIR/sweep.csv (the
// source of truth) and DIR/sweep.md (a table with each value's error relative to the defaults).
#pragma once
#include <string>
#include <vector>
#include <CLI/CLI.hpp>
#include "app/render_options.h"

namespace vpl::app {

struct SweepOptions {
  std::string reference, outDir, modes = "mis", times = "10";
  std::vector<std::string> vary;
  int repeats = 1;  // runs per setting with seeds seed, seed + 1, ...; their relMSE is averaged
  void addTo(CLI::App& command);
};

int runSweep(const SweepOptions& sweep, const RenderOptions& render, const CLI::App& command);

}  // namespace vpl::app
