#include "app/measurement.h"

#include <filesystem>
#include "app/render_options.h"
#include "render/core/error.h"
#include "render/film/image_metrics.h"

namespace vpl::app {

void matchReferenceSize(RenderJobSettings& settings, const Image& reference, const std::string& referencePath,
                        const CLI::App& command) {
  const bool sizeGiven = command.count("--width") > 0 || command.count("--height") > 0;
  if (sizeGiven && (settings.width != reference.width || settings.height != reference.height))
    throw InputError(referencePath + ": the reference is " + std::to_string(reference.width) + "x" +
                     std::to_string(reference.height) + ", not the requested size");
  settings.width = reference.width;
  settings.height = reference.height;
}

std::vector<std::string> prepareOutputs(const std::string& dir, std::initializer_list<const char*> names) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  std::vector<std::string> paths;
  for (const char* name : names) {
    paths.push_back(dir + "/" + name);
    checkWritable(paths.back());
  }
  return paths;
}

Measurement measureAgainst(RenderJobSettings settings, const Image& reference, int repeats) {
  Measurement m;
  for (int r = 0; r < repeats; ++r) {
    const RenderJobResult result = runRenderJob(settings);
    m.seconds += result.seconds / repeats;
    m.spp += result.spp;
    m.relmse += relMse(result.image, reference) / repeats;
    m.bias += relativeBias(result.image, reference) / repeats;
    ++settings.seed;
  }
  m.spp /= repeats;
  return m;
}

nlohmann::ordered_json measurementSummary(const char* command, const RenderJobSettings& settings,
                                          const std::string& referencePath, size_t runs) {
  nlohmann::ordered_json j;
  j["command"] = command;
  j["scene"] = settings.scenePath;
  j["reference"] = referencePath;
  j["width"] = settings.width;
  j["height"] = settings.height;
  j["runs"] = runs;
  return j;
}

}  // namespace vpl::app
