#include "ui/gl_api.h"

#include <stdexcept>
#include <string>

namespace vpl::ui {

void GlApi::load(ProcLoader loader) {
  auto get = [loader](auto& slot, const char* name) {
    slot = reinterpret_cast<std::remove_reference_t<decltype(slot)>>(loader(name));
    if (!slot) throw std::runtime_error(std::string("OpenGL function ") + name + " is missing");
  };
  get(ActiveTexture, "glActiveTexture");
  get(AttachShader, "glAttachShader");
  get(BindTexture, "glBindTexture");
  get(BindVertexArray, "glBindVertexArray");
  get(Clear, "glClear");
  get(ClearColor, "glClearColor");
  get(CompileShader, "glCompileShader");
  get(CreateProgram, "glCreateProgram");
  get(CreateShader, "glCreateShader");
  get(DeleteProgram, "glDeleteProgram");
  get(DeleteShader, "glDeleteShader");
  get(DeleteTextures, "glDeleteTextures");
  get(DeleteVertexArrays, "glDeleteVertexArrays");
  get(DrawArrays, "glDrawArrays");
  get(Finish, "glFinish");
  get(GenTextures, "glGenTextures");
  get(GenVertexArrays, "glGenVertexArrays");
  get(GetError, "glGetError");
  get(BindFramebuffer, "glBindFramebuffer");
  get(BlitFramebuffer, "glBlitFramebuffer");
  get(CheckFramebufferStatus, "glCheckFramebufferStatus");
  get(DeleteFramebuffers, "glDeleteFramebuffers");
  get(FramebufferTexture2D, "glFramebufferTexture2D");
  get(GenFramebuffers, "glGenFramebuffers");
  get(GetProgramInfoLog, "glGetProgramInfoLog");
  get(GetProgramiv, "glGetProgramiv");
  get(GetShaderInfoLog, "glGetShaderInfoLog");
  get(GetShaderiv, "glGetShaderiv");
  get(GetUniformLocation, "glGetUniformLocation");
  get(LinkProgram, "glLinkProgram");
  get(PixelStorei, "glPixelStorei");
  get(ReadPixels, "glReadPixels");
  get(ShaderSource, "glShaderSource");
  get(TexImage2D, "glTexImage2D");
  get(TexParameteri, "glTexParameteri");
  get(Uniform1f, "glUniform1f");
  get(Uniform1i, "glUniform1i");
  get(UseProgram, "glUseProgram");
  get(Viewport, "glViewport");
}

}  // namespace vpl::ui
