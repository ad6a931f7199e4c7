#include "app/sweep.h"

#include <cstdio>
#include <sstream>
#include <unistd.h>
#include <tbb/global_control.h>
#include "app/list_options.h"
#include "app/measurement.h"
#include "render/core/error.h"
#include "render/film/atomic_file.h"
#include "render/film/image_io.h"

namespace vpl::app {

namespace {

struct Variation {
  std::string flag;
  std::vector<std::string> values;
};

Variation parseVariation(const std::string& text) {
  const size_t eq = text.find('=');
  Variation v;
  if (eq != std::string::npos) {
    v.flag = text.substr(0, eq);
    v.values = splitCommas(text.substr(eq + 1));
  }
  if (v.flag.size() < 3 || v.flag.rfind("--", 0) != 0 || v.values.empty())
    throw InputError("--vary: '" + text + "' is not --FLAG=VALUE1,VALUE2,...");
  // The sweep sets these itself: a varied value would be silently overwritten.
  for (const char* owned : {"--mode", "--width", "--height", "--threads"})
    if (v.flag == owned)
      throw InputError("--vary: " + v.flag + " is set by the sweep itself (use --modes, the reference's size, --threads)");
  return v;
}

// The render options with one flag changed, checked by the same parser as the command line.
RenderOptions withFlag(const RenderOptions& base, const std::string& flag, const std::string& value) {
  RenderOptions options = base;
  CLI::App parser;
  options.addConvergeTo(parser);
  std::vector<std::string> args = {value, flag, base.scene};  // CLI11 takes them in reverse order
  try {
    parser.parse(args);
  } catch (const CLI::ParseError& e) {
    throw InputError("--vary " + flag + "=" + value + ": " + e.what());
  }
  return options;
}

}  // namespace

void SweepOptions::addTo(CLI::App& command) {
  command.add_option("--reference", reference, "reference image (OpenEXR, e.g. from 'vplview reference')")->required();
  command.add_option("--modes", modes, "comma-separated modes");
  command.add_option("--times", times, "comma-separated time budgets in seconds (preprocessing included)");
  command.add_option("--vary", vary, "--FLAG=V1,V2,...: a render flag and the values to try (repeatable)")->required();
  command.add_option("--repeats", repeats, "runs per setting (seeds seed, seed+1, ...), relMSE averaged")
      ->check(CLI::Range(1, 1000));
  command.add_option("--out-dir", outDir, "folder for sweep.csv and sweep.md (created if missing)")->required();
}

int runSweep(const SweepOptions& sweep, const RenderOptions& render, const CLI::App& command) {
  const std::vector<SamplingMode> modes = parseModes(sweep.modes);
  const std::vector<double> times = parseTimes(sweep.times);
  std::vector<Variation> variations;
  for (const std::string& text : sweep.vary) variations.push_back(parseVariation(text));
  // Every value is parsed before the first render, so a typo costs no time.
  std::vector<std::vector<RenderJobSettings>> settings(variations.size());
  const Image reference = readExr(sweep.reference);
  RenderJobSettings defaults = render.toSettings();
  matchReferenceSize(defaults, reference, sweep.reference, command);
  for (size_t v = 0; v < variations.size(); ++v)
    for (const std::string& value : variations[v].values) {
      RenderJobSettings s = withFlag(render, variations[v].flag, value).toSettings();
      s.width = defaults.width;
      s.height = defaults.height;
      settings[v].push_back(s);
    }
  const auto paths = prepareOutputs(sweep.outDir, {"sweep.csv", "sweep.md"});
  const std::string &csvPath = paths[0], &tablePath = paths[1];
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, render.threadCount());

  std::ostringstream csv, table;  // written whole at the end (atomic_file.h): no half-written table
  csv << "parameter,value,mode,budget,seconds,spp,relmse,bias\n";
  table << "| parameter | value | mode | budget | spp | relMSE | vs defaults |\n|---|---|---|---|---|---|---|\n";
  const bool terminal = isatty(STDERR_FILENO) != 0;
  size_t runs = 0;
  auto report = [&](const std::string& parameter, const std::string& value, SamplingMode mode, double budget,
                    const Measurement& o, double baseline) {
    csv << parameter << ',' << value << ',' << modeName(mode) << ',' << budget << ',' << o.seconds << ',' << o.spp << ','
        << o.relmse << ',' << o.bias << '\n';
    char line[256];
    std::snprintf(line, sizeof line, "| %s | %s | %s | %g s | %d | %.4g | %.2f |\n", parameter.c_str(), value.c_str(),
                  modeName(mode), budget, o.spp, o.relmse, baseline > 0.0 ? o.relmse / baseline : 0.0);
    table << line;
    if (terminal) std::fprintf(stderr, "sweep: %s", line);
    ++runs;
  };
  for (SamplingMode mode : modes)
    for (double budget : times) {
      RenderJobSettings base = defaults;
      base.mode = mode;
      base.timeBudget = budget;
      const Measurement baseline = measureAgainst(base, reference, sweep.repeats);
      report("defaults", "-", mode, budget, baseline, baseline.relmse);
      for (size_t v = 0; v < variations.size(); ++v)
        for (size_t i = 0; i < settings[v].size(); ++i) {
          RenderJobSettings s = settings[v][i];
          s.mode = mode;
          s.timeBudget = budget;
          report(variations[v].flag, variations[v].values[i], mode, budget, measureAgainst(s, reference, sweep.repeats),
                 baseline.relmse);
        }
    }
  writeFileAtomically(csvPath, csv.str());
  writeFileAtomically(tablePath, table.str());

  nlohmann::ordered_json j = measurementSummary("sweep", defaults, sweep.reference, runs * size_t(sweep.repeats));
  j["csv"] = csvPath;
  j["table"] = tablePath;
  std::printf("%s\n", j.dump().c_str());
  return 0;
}

}  // namespace vpl::app
