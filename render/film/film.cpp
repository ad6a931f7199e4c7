#include "render/film/film.h"

#include "render/core/color.h"

namespace vpl {

namespace {
constexpr auto kRelaxed = std::memory_order_relaxed;
// Only the owning worker writes a pixel, so load + store is not a lost update.
void addTo(std::atomic<double>& a, double v) { a.store(a.load(kRelaxed) + v, kRelaxed); }
}  // namespace

double Film::meanLuminance(const Pixel& p, double w) {
  return luminance(glm::vec3(float(p.r.load(kRelaxed)), float(p.g.load(kRelaxed)), float(p.b.load(kRelaxed)))) / w;
}

Film::Film(int width, int height)
    : width_(width), height_(height), pixels_(std::make_unique<Pixel[]>(size_t(width) * size_t(height))) {}

void Film::addSample(int x, int y, const glm::vec3& L) {
  Pixel& p = pixels_[size_t(y) * size_t(width_) + size_t(x)];
  addTo(p.r, L.x);
  addTo(p.g, L.y);
  addTo(p.b, L.z);
  const double l = luminance(L);
  addTo(p.lum2, l * l);
  addTo(p.weight, 1.0);
  p.count.store(p.count.load(kRelaxed) + 1, kRelaxed);
}

void Film::add(const Film& other, double weight) {
  if (other.width_ != width_ || other.height_ != height_) return;
  for (size_t i = 0, n = size_t(width_) * size_t(height_); i < n; ++i) {
    Pixel& p = pixels_[i];
    const Pixel& o = other.pixels_[i];
    addTo(p.r, weight * o.r.load(kRelaxed));
    addTo(p.g, weight * o.g.load(kRelaxed));
    addTo(p.b, weight * o.b.load(kRelaxed));
    addTo(p.lum2, weight * o.lum2.load(kRelaxed));
    addTo(p.weight, weight * o.weight.load(kRelaxed));
    p.count.store(p.count.load(kRelaxed) + o.count.load(kRelaxed), kRelaxed);
  }
}

void Film::clear() {
  for (size_t i = 0, n = size_t(width_) * size_t(height_); i < n; ++i) {
    pixels_[i].r.store(0, kRelaxed);
    pixels_[i].g.store(0, kRelaxed);
    pixels_[i].b.store(0, kRelaxed);
    pixels_[i].lum2.store(0, kRelaxed);
    pixels_[i].weight.store(0, kRelaxed);
    pixels_[i].count.store(0, kRelaxed);
  }
}

Image Film::resolve() const {
  Image image(width_, height_);
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    const Pixel& p = pixels_[i];
    const double w = p.weight.load(kRelaxed);
    if (!(w > 0.0)) continue;  // no samples (or only weightless ones)
    const double inv = 1.0 / w;
    image.pixels[i] = glm::vec3(float(p.r.load(kRelaxed) * inv), float(p.g.load(kRelaxed) * inv), float(p.b.load(kRelaxed) * inv));
  }
  return image;
}

Image Film::resolveVariance() const {
  Image image(width_, height_);
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    const Pixel& p = pixels_[i];
    const uint32_t n = p.count.load(kRelaxed);
    const double w = p.weight.load(kRelaxed);
    if (n < 2 || !(w > 0.0)) continue;
    const double mean = meanLuminance(p, w);
    const double var = std::max(0.0, (p.lum2.load(kRelaxed) / w - mean * mean) * n / (n - 1));
    image.pixels[i] = glm::vec3(float(var / n / (mean * mean + 1e-4)));
  }
  return image;
}

double Film::sampleRelativeVariance() const {
  double variance = 0.0, mean2 = 0.0;
  for (size_t i = 0, n = size_t(width_) * size_t(height_); i < n; ++i) {
    const Pixel& p = pixels_[i];
    const uint32_t count = p.count.load(kRelaxed);
    const double w = p.weight.load(kRelaxed);
    if (count < 2 || !(w > 0.0)) continue;
    const double mean = meanLuminance(p, w);
    variance += std::max(0.0, (p.lum2.load(kRelaxed) / w - mean * mean) * count / (count - 1));
    mean2 += mean * mean;
  }
  return mean2 > 0.0 ? variance / mean2 : 0.0;
}

uint64_t Film::totalSamples() const {
  uint64_t total = 0;
  for (size_t i = 0, n = size_t(width_) * size_t(height_); i < n; ++i) total += pixels_[i].count.load(kRelaxed);
  return total;
}

}  // namespace vpl
