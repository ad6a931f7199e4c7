// Error of an image against a reference (DESIGN.md §4).
#pragma once
#include <glm/glm.hpp>
#include "render/film/image.h"

namespace vpl {

// Mean over pixels and channels of (x - r)^2 / (r^2 + 0.01). Sizes must match (else InputError).
double relMse(const Image& image, const Image& reference);
glm::dvec3 meanRgb(const Image& image);
// (mean luminance of image - that of reference) / that of reference.
double relativeBias(const Image& image, const Image& reference);

}  // namespace vpl
