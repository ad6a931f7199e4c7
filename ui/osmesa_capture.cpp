#include "ui/osmesa_capture.h"

#include <memory>
#include <stdexcept>
#include <GL/osmesa.h>

namespace vpl::ui {

std::vector<uint8_t> captureThroughDisplay(const Image& image, float exposureStops, DisplayView view) {
  const int attributes[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                            OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
  const std::unique_ptr<osmesa_context, void (*)(OSMesaContext)> context(OSMesaCreateContextAttribs(attributes, nullptr),
                                                                         OSMesaDestroyContext);
  if (!context) throw std::runtime_error("cannot create an OSMesa OpenGL 3.3 core context");
  std::vector<uint8_t> buffer(size_t(image.width) * size_t(image.height) * 4);
  if (!OSMesaMakeCurrent(context.get(), buffer.data(), GL_UNSIGNED_BYTE, image.width, image.height))
    throw std::runtime_error("cannot make the OSMesa context current");
  GlApi gl;
  gl.load([](const char* name) { return reinterpret_cast<void*>(OSMesaGetProcAddress(name)); });
  std::vector<uint8_t> pixels;
  {
    DisplayPipeline display(gl);
    display.upload(image);
    display.draw(image.width, image.height, exposureStops, view);
    gl.Finish();
    pixels = display.readPixels(image.width, image.height);
  }
  OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
  return pixels;
}

}  // namespace vpl::ui
