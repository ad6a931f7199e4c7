// The OpenGL 3.3 core entry points the display uses, loaded through whichever context is current
// (GLFW's window or OSMesa's buffer): the binary links neither libGL nor OSMesa's GL symbols into
// its own calls, so the two contexts never fight over one set of global gl* functions.
#pragma once
#include <GL/glcorearb.h>

namespace vpl::ui {

struct GlApi {
  PFNGLACTIVETEXTUREPROC ActiveTexture = nullptr;
  PFNGLATTACHSHADERPROC AttachShader = nullptr;
  PFNGLBINDTEXTUREPROC BindTexture = nullptr;
  PFNGLBINDFRAMEBUFFERPROC BindFramebuffer = nullptr;
  PFNGLBINDVERTEXARRAYPROC BindVertexArray = nullptr;
  PFNGLBLITFRAMEBUFFERPROC BlitFramebuffer = nullptr;
  PFNGLCHECKFRAMEBUFFERSTATUSPROC CheckFramebufferStatus = nullptr;
  PFNGLCLEARPROC Clear = nullptr;
  PFNGLCLEARCOLORPROC ClearColor = nullptr;
  PFNGLCOMPILESHADERPROC CompileShader = nullptr;
  PFNGLCREATEPROGRAMPROC CreateProgram = nullptr;
  PFNGLCREATESHADERPROC CreateShader = nullptr;
  PFNGLDELETEFRAMEBUFFERSPROC DeleteFramebuffers = nullptr;
  PFNGLDELETEPROGRAMPROC DeleteProgram = nullptr;
  PFNGLDELETESHADERPROC DeleteShader = nullptr;
  PFNGLDELETETEXTURESPROC DeleteTextures = nullptr;
  PFNGLDELETEVERTEXARRAYSPROC DeleteVertexArrays = nullptr;
  PFNGLDRAWARRAYSPROC DrawArrays = nullptr;
  PFNGLFINISHPROC Finish = nullptr;
  PFNGLFRAMEBUFFERTEXTURE2DPROC FramebufferTexture2D = nullptr;
  PFNGLGENFRAMEBUFFERSPROC GenFramebuffers = nullptr;
  PFNGLGENTEXTURESPROC GenTextures = nullptr;
  PFNGLGENVERTEXARRAYSPROC GenVertexArrays = nullptr;
  PFNGLGETERRORPROC GetError = nullptr;
  PFNGLGETPROGRAMINFOLOGPROC GetProgramInfoLog = nullptr;
  PFNGLGETPROGRAMIVPROC GetProgramiv = nullptr;
  PFNGLGETSHADERINFOLOGPROC GetShaderInfoLog = nullptr;
  PFNGLGETSHADERIVPROC GetShaderiv = nullptr;
  PFNGLGETUNIFORMLOCATIONPROC GetUniformLocation = nullptr;
  PFNGLLINKPROGRAMPROC LinkProgram = nullptr;
  PFNGLPIXELSTOREIPROC PixelStorei = nullptr;
  PFNGLREADPIXELSPROC ReadPixels = nullptr;
  PFNGLSHADERSOURCEPROC ShaderSource = nullptr;
  PFNGLTEXIMAGE2DPROC TexImage2D = nullptr;
  PFNGLTEXPARAMETERIPROC TexParameteri = nullptr;
  PFNGLUNIFORM1FPROC Uniform1f = nullptr;
  PFNGLUNIFORM1IPROC Uniform1i = nullptr;
  PFNGLUSEPROGRAMPROC UseProgram = nullptr;
  PFNGLVIEWPORTPROC Viewport = nullptr;

  using ProcLoader = void* (*)(const char* name);
  // Fills every entry from the current context; throws std::runtime_error naming a missing one.
  void load(ProcLoader loader);
};

}  // namespace vpl::ui
