// Error of an image against a reference (DESIGN.md §4).
#pragma once
#include <glm/glm.hpp>
#include "render/film/image.h"

namespace vpl {

// Mean over pixels and channels of (x - r)^2 / (r^2 + 0.01). Sizes must match (else InputError).
double relMse(const Image& image, const Image& reference);
// Per-pixel relMSE (mean over channels), in every channel of the result: the map behind relMse.
Image relMseMap(const Image& image, const Image& reference);
// A false-colour picture of an error map: log10 of the error from 1e-4 (black) through blue, red,
// yellow to 1e+0 and above (white), so that where a mode loses is seen at a glance.
Image falseColourLog(const Image& errors, float logMin = -4.0f, float logMax = 0.0f);
glm::dvec3 meanRgb(const Image& image);
// (mean luminance of image - that of reference) / that of reference.
double relativeBias(const Image& image, const Image& reference);

}  // namespace vpl
