// The raw Embree ray rate on a scene: the ceiling the path tracer's rays/s is measured against
// (DESIGN.md §4). Incoherent rays from random surface points in random directions.
#pragma once
#include <cstdint>
#include <string>

namespace vpl {

struct RayBenchmark {
  uint64_t rays = 0;
  double seconds = 0.0;
  double raysPerSecond = 0.0;
};

// Loads the scene, pre-generates the rays, then traces them with rtcIntersect1 on the TBB pool
// for about `seconds`. Ray generation is not timed.
RayBenchmark measureRawRayRate(const std::string& scenePath, double seconds, uint64_t seed);

}  // namespace vpl
