// The accumulation buffer of a progressive render: per pixel, a weighted sum of radiance samples, a
// weighted sum of squared luminance (for the relative-variance view), the sum of the weights and a
// sample count. A sample added by addSample() weighs 1; add() adds a whole film's samples (`--join-depth
// auto`'s trial passes), and can weigh them less: the mean is then the weighted mean.
//
// Threading contract: workers call addSample() only for pixels of tiles they own (no two threads
// write one pixel at once); any thread may call resolve() at any time. Fields are relaxed atomics,
// so a concurrent resolve() may see a pixel mid-update (a torn, still finite, value) but never races.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <glm/glm.hpp>
#include "render/film/image.h"

namespace vpl {

class Film {
 public:
  Film(int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }

  void addSample(int x, int y, const glm::vec3& radiance);
  // Adds another film's samples of the same size, each weighing `weight` times what it weighed there.
  void add(const Film& other, double weight = 1.0);
  void clear();

  Image resolve() const;           // per-pixel weighted mean; pixels without samples are black
  Image resolveVariance() const;   // per-pixel relative variance of the mean luminance, in all channels
  uint64_t totalSamples() const;
  // The image's relative variance per sample, brightness-weighted: the sum over pixels of the
  // luminance samples' variance over the sum of their squared means (0 without two samples).
  double sampleRelativeVariance() const;

 private:
  struct Pixel {
    std::atomic<double> r{0}, g{0}, b{0}, lum2{0}, weight{0};
    std::atomic<uint32_t> count{0};
  };
  // The luminance of a pixel's weighted mean, w its sum of weights (> 0).
  static double meanLuminance(const Pixel& p, double w);
  int width_, height_;
  std::unique_ptr<Pixel[]> pixels_;
};

}  // namespace vpl
