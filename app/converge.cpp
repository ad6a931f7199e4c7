#include "app/converge.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>
#include "render/core/error.h"
#include "render/film/image_io.h"
#include "render/film/image_metrics.h"
#include "render/film/plot.h"
#include "render/session/render_job.h"

namespace vpl::app {

namespace {

std::vector<std::string> splitCommas(const std::string& list) {
  std::vector<std::string> items;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) items.push_back(item);
  return items;
}

std::vector<SamplingMode> parseModes(const std::string& list) {
  std::vector<SamplingMode> modes;
  for (const std::string& name : splitCommas(list)) {
    const auto mode = parseMode(name);
    if (!mode) throw InputError("--modes: unknown mode '" + name + "' (brdf, metropolis, mis, mixture, preview)");
    modes.push_back(*mode);
  }
  if (modes.empty()) throw InputError("--modes: no mode given");
  return modes;
}

std::vector<double> parseTimes(const std::string& list) {
  std::vector<double> times;
  for (const std::string& item : splitCommas(list)) {
    char* end = nullptr;
    const double t = std::strtod(item.c_str(), &end);
    if (end == item.c_str() || *end != '\0' || !(t > 0.0) || !(t < 1e6))
      throw InputError("--times: '" + item + "' is not a positive number of seconds");
    times.push_back(t);
  }
  if (times.empty()) throw InputError("--times: no budget given");
  return times;
}

}  // namespace

void ConvergeOptions::addTo(CLI::App& command) {
  command.add_option("--reference", reference, "reference image (OpenEXR, e.g. from 'vplview reference')")->required();
  command.add_option("--modes", modes, "comma-separated modes");
  command.add_option("--times", times, "comma-separated time budgets in seconds (preprocessing included)");
  command.add_option("--out-dir", outDir, "folder for converge.csv and converge.png (created if missing)")->required();
}

int runConverge(const ConvergeOptions& converge, const RenderOptions& render, const CLI::App& command) {
  const std::vector<SamplingMode> modes = parseModes(converge.modes);
  const std::vector<double> times = parseTimes(converge.times);
  const Image reference = readExr(converge.reference);
  RenderJobSettings settings = render.toSettings();
  const bool sizeGiven = command.count("--width") > 0 || command.count("--height") > 0;
  if (sizeGiven && (settings.width != reference.width || settings.height != reference.height))
    throw InputError(converge.reference + ": the reference is " + std::to_string(reference.width) + "x" +
                     std::to_string(reference.height) + ", not the requested size");
  settings.width = reference.width;
  settings.height = reference.height;
  std::error_code ec;
  std::filesystem::create_directories(converge.outDir, ec);
  const std::string csvPath = converge.outDir + "/converge.csv", plotPath = converge.outDir + "/converge.png";
  checkWritable(csvPath);
  checkWritable(plotPath);
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, render.threadCount());

  std::ofstream csv(csvPath);
  csv << "mode,budget,seconds,spp,relmse,bias\n";
  std::vector<PlotSeries> series;
  const bool terminal = isatty(STDERR_FILENO) != 0;
  for (SamplingMode mode : modes) {
    PlotSeries line{modeName(mode), {}, {}};
    for (double budget : times) {
      settings.mode = mode;
      settings.timeBudget = budget;
      const RenderJobResult result = runRenderJob(settings);
      const double error = relMse(result.image, reference), bias = relativeBias(result.image, reference);
      csv << modeName(mode) << ',' << budget << ',' << result.seconds << ',' << result.spp << ',' << error << ',' << bias
          << '\n';
      line.x.push_back(result.seconds);
      line.y.push_back(error);
      if (terminal)
        std::fprintf(stderr, "converge: %-10s %6.2f s  %5d spp  relMSE %.4g  bias %+.4f\n", modeName(mode), result.seconds,
                     result.spp, error, bias);
    }
    series.push_back(std::move(line));
  }
  csv.close();
  if (!csv) throw InputError(csvPath + ": cannot write");
  const std::string title = "relMSE against time: " + std::filesystem::path(settings.scenePath).filename().string() + ", " +
                            std::to_string(settings.width) + "x" + std::to_string(settings.height);
  const PlotPixels plot = plotLogLog(series, title, "seconds (preprocessing included)", "relMSE");
  writePngBytes(plotPath, plot.width, plot.height, plot.rgb);

  nlohmann::ordered_json j;
  j["command"] = "converge";
  j["scene"] = settings.scenePath;
  j["reference"] = converge.reference;
  j["width"] = settings.width;
  j["height"] = settings.height;
  j["runs"] = modes.size() * times.size();
  j["csv"] = csvPath;
  j["plot"] = plotPath;
  std::printf("%s\n", j.dump().c_str());
  return 0;
}

}  // namespace vpl::app
