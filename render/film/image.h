// A linear RGB image in memory (row 0 at the top).
#pragma once
#include <vector>
#include <glm/glm.hpp>

namespace vpl {

struct Image {
  int width = 0, height = 0;
  std::vector<glm::vec3> pixels;

  Image() = default;
  Image(int w, int h) : width(w), height(h), pixels(size_t(w) * size_t(h), glm::vec3(0.0f)) {}
  glm::vec3& at(int x, int y) { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
  const glm::vec3& at(int x, int y) const { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
};

}  // namespace vpl
