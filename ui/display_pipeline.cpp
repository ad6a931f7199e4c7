#include "ui/display_pipeline.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include "ui/shader_sources.h"

namespace vpl::ui {

namespace {

// Throws with the driver's log when a shader did not compile or a program did not link.
void requireSuccess(const GlApi& gl, GLuint object, bool isProgram) {
  GLint ok = 0;
  (isProgram ? gl.GetProgramiv : gl.GetShaderiv)(object, isProgram ? GL_LINK_STATUS : GL_COMPILE_STATUS, &ok);
  if (ok) return;
  char log[2048] = {};
  (isProgram ? gl.GetProgramInfoLog : gl.GetShaderInfoLog)(object, sizeof(log), nullptr, log);
  (isProgram ? gl.DeleteProgram : gl.DeleteShader)(object);
  throw std::runtime_error(std::string(isProgram ? "display shaders do not link: " : "display shader does not compile: ") + log);
}

GLuint compile(const GlApi& gl, GLenum type, const char* source) {
  const GLuint shader = gl.CreateShader(type);
  gl.ShaderSource(shader, 1, &source, nullptr);
  gl.CompileShader(shader);
  requireSuccess(gl, shader, false);
  return shader;
}

}  // namespace

DisplayPipeline::DisplayPipeline(const GlApi& gl) : gl_(gl) {
  const GLuint vs = compile(gl, GL_VERTEX_SHADER, kDisplayVertexShader);
  const GLuint fs = compile(gl, GL_FRAGMENT_SHADER, kDisplayFragmentShader);
  program_ = gl.CreateProgram();
  gl.AttachShader(program_, vs);
  gl.AttachShader(program_, fs);
  gl.LinkProgram(program_);
  gl.DeleteShader(vs);
  gl.DeleteShader(fs);
  requireSuccess(gl, program_, true);
  exposureLocation_ = gl.GetUniformLocation(program_, "exposureScale");
  viewLocation_ = gl.GetUniformLocation(program_, "view");
  imageLocation_ = gl.GetUniformLocation(program_, "image");
  gl.GenVertexArrays(1, &vertexArray_);  // core profile: drawing needs one, even without attributes
  gl.GenTextures(1, &texture_);
  gl.BindTexture(GL_TEXTURE_2D, texture_);
  // Nearest: at equal sizes every window pixel shows exactly its image pixel.
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  gl.GenFramebuffers(1, &frameBuffer_);
  gl.GenTextures(1, &frameTexture_);
}

DisplayPipeline::~DisplayPipeline() {
  gl_.DeleteFramebuffers(1, &frameBuffer_);
  gl_.DeleteTextures(1, &frameTexture_);
  gl_.DeleteTextures(1, &texture_);
  gl_.DeleteVertexArrays(1, &vertexArray_);
  gl_.DeleteProgram(program_);
}

void DisplayPipeline::upload(const Image& image) {
  if (image.width <= 0 || image.height <= 0) return;
  gl_.BindTexture(GL_TEXTURE_2D, texture_);
  gl_.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
  gl_.TexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, image.width, image.height, 0, GL_RGB, GL_FLOAT, image.pixels.data());
  width_ = image.width;
  height_ = image.height;
  shaded_.valid = false;
}

void DisplayPipeline::shade(int width, int height, float exposureStops, DisplayView view) {
  if (width != shaded_.width || height != shaded_.height) {
    gl_.BindTexture(GL_TEXTURE_2D, frameTexture_);
    gl_.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl_.BindFramebuffer(GL_FRAMEBUFFER, frameBuffer_);
    gl_.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, frameTexture_, 0);
    if (gl_.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
      throw std::runtime_error("the display's frame buffer is incomplete");
    }
  }
  gl_.BindFramebuffer(GL_FRAMEBUFFER, frameBuffer_);
  gl_.Viewport(0, 0, width, height);
  gl_.UseProgram(program_);
  gl_.ActiveTexture(GL_TEXTURE0);
  gl_.BindTexture(GL_TEXTURE_2D, texture_);
  gl_.Uniform1i(imageLocation_, 0);
  gl_.Uniform1f(exposureLocation_, std::exp2(exposureStops));
  gl_.Uniform1i(viewLocation_, int(view));
  gl_.BindVertexArray(vertexArray_);
  gl_.DrawArrays(GL_TRIANGLES, 0, 3);  // covers the viewport: no clear needed
  gl_.BindVertexArray(0);
  gl_.UseProgram(0);
  gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
  shaded_ = {width, height, exposureStops, view, true};
}

void DisplayPipeline::draw(int viewportWidth, int viewportHeight, float exposureStops, DisplayView view) {
  gl_.Viewport(0, 0, viewportWidth, viewportHeight);
  if (!hasImage() || viewportWidth <= 0 || viewportHeight <= 0) {
    gl_.ClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    gl_.Clear(GL_COLOR_BUFFER_BIT);
    return;
  }
  if (!shaded_.valid || viewportWidth != shaded_.width || viewportHeight != shaded_.height ||
      exposureStops != shaded_.exposureStops || view != shaded_.view)
    shade(viewportWidth, viewportHeight, exposureStops, view);
  gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, frameBuffer_);
  gl_.BindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  gl_.BlitFramebuffer(0, 0, viewportWidth, viewportHeight, 0, 0, viewportWidth, viewportHeight, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
}

std::vector<uint8_t> DisplayPipeline::readPixels(int width, int height) const {
  std::vector<uint8_t> rgba(size_t(width) * size_t(height) * 4), rgb(size_t(width) * size_t(height) * 3);
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl_.ReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  for (int y = 0; y < height; ++y)  // GL's row 0 is the bottom
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c)
        rgb[(size_t(y) * size_t(width) + size_t(x)) * 3 + size_t(c)] =
            rgba[(size_t(height - 1 - y) * size_t(width) + size_t(x)) * 4 + size_t(c)];
  return rgb;
}

}  // namespace vpl::ui
