// What the window shows: the render core's linear image as a float texture, drawn by the shaders in
// shaders/ (exposure, the sRGB curve of render/film/tonemap.h, or a false-colour error view). The
// window and the headless OSMesa capture both draw through this class.
#pragma once
#include <cstdint>
#include <vector>
#include "render/film/image.h"
#include "ui/gl_api.h"

namespace vpl::ui {

enum class DisplayView { Image = 0, ErrorMap = 1 };

class DisplayPipeline {
 public:
  // Needs a current OpenGL 3.3 core context; throws std::runtime_error with the compiler's log.
  explicit DisplayPipeline(const GlApi& gl);
  ~DisplayPipeline();
  DisplayPipeline(const DisplayPipeline&) = delete;
  DisplayPipeline& operator=(const DisplayPipeline&) = delete;

  void upload(const Image& image);
  bool hasImage() const { return width_ > 0; }
  // Fills the viewport with the image (stretched to it). The shaded frame is kept in a texture and
  // shaded again only when the image, the viewport's size, the exposure or the view change; other
  // frames copy it. Under a software GL (llvmpipe, Xvfb) shading 1280x720 pixels at 50 fps took about
  // a core of two from the render threads: refinement in the viewer began at 3.45 s on the interior.
  void draw(int viewportWidth, int viewportHeight, float exposureStops, DisplayView view);
  // The framebuffer's RGB bytes, top row first (for PNG screenshots).
  std::vector<uint8_t> readPixels(int width, int height) const;

 private:
  const GlApi& gl_;
  GLuint program_ = 0, texture_ = 0, vertexArray_ = 0;
  GLuint frameBuffer_ = 0, frameTexture_ = 0;  // the shaded frame
  struct Shaded {
    int width = 0, height = 0;
    float exposureStops = 0.0f;
    DisplayView view = DisplayView::Image;
    bool valid = false;
  } shaded_;
  void shade(int width, int height, float exposureStops, DisplayView view);
  GLint exposureLocation_ = -1, viewLocation_ = -1, imageLocation_ = -1;
  int width_ = 0, height_ = 0;
};

}  // namespace vpl::ui
