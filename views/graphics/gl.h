// Internal: the GL 3.3 core entry points the renderer uses, loaded through the
// context's own proc-address function (OSMesaGetProcAddress or
// glfwGetProcAddress), so that OSMesa and a system libGL never clash over the
// same exported names in one process.
#ifndef TX_VIEWS_GRAPHICS_GL_H
#define TX_VIEWS_GRAPHICS_GL_H

#include <GL/glcorearb.h>
#include <stdbool.h>

#define TX_GL_FUNCS(X)                                                                                        \
  X(PFNGLGETERRORPROC, GetError) X(PFNGLGETSTRINGPROC, GetString) X(PFNGLVIEWPORTPROC, Viewport)             \
  X(PFNGLSCISSORPROC, Scissor) X(PFNGLCLEARCOLORPROC, ClearColor) X(PFNGLCLEARPROC, Clear)                  \
  X(PFNGLENABLEPROC, Enable) X(PFNGLDISABLEPROC, Disable) X(PFNGLCOLORMASKPROC, ColorMask)                 \
  X(PFNGLDEPTHMASKPROC, DepthMask) X(PFNGLDRAWBUFFERPROC, DrawBuffer) X(PFNGLREADBUFFERPROC, ReadBuffer)    \
  X(PFNGLREADPIXELSPROC, ReadPixels) X(PFNGLFINISHPROC, Finish) X(PFNGLPIXELSTOREIPROC, PixelStorei)       \
  X(PFNGLGETINTEGERVPROC, GetIntegerv) X(PFNGLBLENDFUNCPROC, BlendFunc)                                      \
  X(PFNGLCREATESHADERPROC, CreateShader) X(PFNGLSHADERSOURCEPROC, ShaderSource)                              \
  X(PFNGLCOMPILESHADERPROC, CompileShader) X(PFNGLGETSHADERIVPROC, GetShaderiv)                              \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog) X(PFNGLCREATEPROGRAMPROC, CreateProgram)                    \
  X(PFNGLATTACHSHADERPROC, AttachShader) X(PFNGLLINKPROGRAMPROC, LinkProgram)                                \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv) X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                    \
  X(PFNGLDELETESHADERPROC, DeleteShader) X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                            \
  X(PFNGLUSEPROGRAMPROC, UseProgram) X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                      \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv) X(PFNGLUNIFORM3FVPROC, Uniform3fv)                          \
  X(PFNGLUNIFORM4FVPROC, Uniform4fv) X(PFNGLUNIFORM2FVPROC, Uniform2fv) X(PFNGLUNIFORM1IPROC, Uniform1i) X(PFNGLUNIFORM1FPROC, Uniform1f)       \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays) X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                  \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays) X(PFNGLGENBUFFERSPROC, GenBuffers)                      \
  X(PFNGLBINDBUFFERPROC, BindBuffer) X(PFNGLBUFFERDATAPROC, BufferData)                                      \
  X(PFNGLBUFFERSUBDATAPROC, BufferSubData) X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                          \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)                                               \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer) X(PFNGLVERTEXATTRIBDIVISORPROC, VertexAttribDivisor)  \
  X(PFNGLDRAWARRAYSPROC, DrawArrays) X(PFNGLDRAWELEMENTSPROC, DrawElements)                                  \
  X(PFNGLDRAWELEMENTSINSTANCEDPROC, DrawElementsInstanced) X(PFNGLGENTEXTURESPROC, GenTextures)              \
  X(PFNGLDRAWARRAYSINSTANCEDPROC, DrawArraysInstanced)                                                       \
  X(PFNGLBINDTEXTUREPROC, BindTexture) X(PFNGLTEXIMAGE2DPROC, TexImage2D)                                    \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri) X(PFNGLGENERATEMIPMAPPROC, GenerateMipmap)                        \
  X(PFNGLACTIVETEXTUREPROC, ActiveTexture) X(PFNGLDELETETEXTURESPROC, DeleteTextures)

typedef struct tx_gl {
#define TX_GL_FIELD(type, name) type name;
  TX_GL_FUNCS(TX_GL_FIELD)
#undef TX_GL_FIELD
} tx_gl;

typedef void (*tx_gl_proc)(void);
typedef tx_gl_proc (*tx_gl_loader)(const char* name);

// fill every entry point; false (with the missing name in *missing) if one is absent
bool tx_gl_load(tx_gl* gl, tx_gl_loader load, const char** missing);

#endif
