#include "app/converge.h"

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <unistd.h>
#include <tbb/global_control.h>
#include "render/film/atomic_file.h"
#include "render/film/image_io.h"
#include "render/film/plot.h"
#include "app/list_options.h"
#include "app/measurement.h"

namespace vpl::app {

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
  matchReferenceSize(settings, reference, converge.reference, command);
  const auto paths = prepareOutputs(converge.outDir, {"converge.csv", "converge.png"});
  const std::string &csvPath = paths[0], &plotPath = paths[1];
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, render.threadCount());

  std::ostringstream csv;  // written whole at the end (atomic_file.h): no half-written table
  csv << "mode,budget,seconds,spp,relmse,bias\n";
  std::vector<PlotSeries> series;
  const bool terminal = isatty(STDERR_FILENO) != 0;
  for (SamplingMode mode : modes) {
    PlotSeries line{modeName(mode), {}, {}};
    for (double budget : times) {
      settings.mode = mode;
      settings.timeBudget = budget;
      const Measurement m = measureAgainst(settings, reference);
      csv << modeName(mode) << ',' << budget << ',' << m.seconds << ',' << m.spp << ',' << m.relmse << ',' << m.bias << '\n';
      line.x.push_back(m.seconds);
      line.y.push_back(m.relmse);
      if (terminal)
        std::fprintf(stderr, "converge: %-10s %6.2f s  %5d spp  relMSE %.4g  bias %+.4f\n", modeName(mode), m.seconds, m.spp,
                     m.relmse, m.bias);
    }
    series.push_back(std::move(line));
  }
  writeFileAtomically(csvPath, csv.str());
  const std::string title = "relMSE against time: " + std::filesystem::path(settings.scenePath).filename().string() + ", " +
                            std::to_string(settings.width) + "x" + std::to_string(settings.height);
  const PlotPixels plot = plotLogLog(series, title, "seconds (preprocessing included)", "relMSE");
  writePngBytes(plotPath, plot.width, plot.height, plot.rgb);

  nlohmann::ordered_json j = measurementSummary("converge", settings, converge.reference, modes.size() * times.size());
  j["csv"] = csvPath;
  j["plot"] = plotPath;
  std::printf("%s\n", j.dump().c_str());
  return 0;
}

}  // namespace vpl::app
