// A log-log line plot as an 8-bit RGB picture, for `vplview converge` (relMSE against seconds per
// mode). Text comes from stb_easy_font (no font files); non-positive or non-finite points are left out.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace vpl {

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;
};

struct PlotPixels {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // top row first
};

PlotPixels plotLogLog(const std::vector<PlotSeries>& series, const std::string& title, const std::string& xLabel,
                      const std::string& yLabel, int width = 800, int height = 560);

}  // namespace vpl
