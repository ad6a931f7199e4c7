// The convergence plot: every series is drawn in its own colour, unusable points are left out.
#include <cmath>
#include "render/film/plot.h"
#include "tests/unit/support.h"

namespace vpl {
namespace {

size_t countColour(const PlotPixels& p, uint8_t r, uint8_t g, uint8_t b) {
  size_t n = 0;
  for (size_t i = 0; i + 2 < p.rgb.size(); i += 3) n += p.rgb[i] == r && p.rgb[i + 1] == g && p.rgb[i + 2] == b;
  return n;
}

TEST(Plot, SeriesAreDrawnAndBadPointsSkipped) {
  const std::vector<PlotSeries> series = {{"brdf", {1, 2, 4, 8}, {1e-2, 5e-3, 2.5e-3, 1.2e-3}},
                                          {"mis", {1, 2, NAN, 8, -1}, {2e-2, 0.0, 1e-3, 3e-3, 1e-3}}};
  const PlotPixels p = plotLogLog(series, "title", "seconds", "relMSE", 640, 400);
  ASSERT_EQ(p.width, 640);
  ASSERT_EQ(p.height, 400);
  ASSERT_EQ(p.rgb.size(), size_t(640 * 400 * 3));
  EXPECT_GT(countColour(p, 31, 119, 180), 500u);  // first series' colour: line, markers, legend
  EXPECT_GT(countColour(p, 214, 39, 40), 300u);   // second series: two usable points and its legend
  EXPECT_GT(countColour(p, 255, 255, 255), size_t(640 * 400 / 2));  // mostly background
}

TEST(Plot, NothingUsableStillGivesAPicture) {
  const PlotPixels empty = plotLogLog({}, "", "", "", 100, 80);
  EXPECT_EQ(empty.rgb.size(), size_t(100 * 80 * 3));
  const PlotPixels bad = plotLogLog({{"x", {NAN, 0}, {1, INFINITY}}}, "t", "x", "y", 300, 200);
  EXPECT_EQ(countColour(bad, 31, 119, 180), countColour(plotLogLog({{"x", {}, {}}}, "t", "x", "y", 300, 200), 31, 119, 180));
}

}  // namespace
}  // namespace vpl
