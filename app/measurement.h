// What `converge` and `sweep` share: renders measured against a reference image (DESIGN.md §4,
// preprocessing counted), their output files, and the head of their JSON line.
#pragma once
#include <initializer_list>
#include <string>
#include <vector>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include "render/film/image.h"
#include "render/session/render_job.h"

namespace vpl::app {

// Renders are compared with the reference at its size; --width/--height, when given, must agree.
void matchReferenceSize(RenderJobSettings& settings, const Image& reference, const std::string& referencePath,
                        const CLI::App& command);

// Creates `dir` if missing and returns dir/name for each name, each checked to be writable.
std::vector<std::string> prepareOutputs(const std::string& dir, std::initializer_list<const char*> names);

struct Measurement {
  double seconds = 0.0, relmse = 0.0, bias = 0.0;
  int spp = 0;
};

// Renders `settings` `repeats` times with seeds seed, seed + 1, ... and averages the figures.
Measurement measureAgainst(RenderJobSettings settings, const Image& reference, int repeats = 1);

// command, scene, reference, size and run count; the caller adds its files.
nlohmann::ordered_json measurementSummary(const char* command, const RenderJobSettings& settings,
                                          const std::string& referencePath, size_t runs);

}  // namespace vpl::app
