// The display pipeline without a window: an OSMesa (software) OpenGL 3.3 core context draws the
// image exactly as the viewer would and hands back the pixels. Used by `vplview capture`.
#pragma once
#include <cstdint>
#include <vector>
#include "render/film/image.h"
#include "ui/display_pipeline.h"

namespace vpl::ui {

// RGB bytes, top row first, of `image` drawn at its own size; throws std::runtime_error when no
// OSMesa context can be made.
std::vector<uint8_t> captureThroughDisplay(const Image& image, float exposureStops, DisplayView view = DisplayView::Image);

}  // namespace vpl::ui
