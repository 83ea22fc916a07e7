// The GL entry points, by name, from the current context's loader.
#include "gl.h"

#include <string.h>

bool tx_gl_load(tx_gl* gl, tx_gl_loader load, const char** missing) {
  memset(gl, 0, sizeof *gl);
  // a function pointer is stored through a same-sized copy: ISO C has no cast between the two kinds
#define TX_GL_LOAD(type, name)                                                                                 \
  {                                                                                                            \
    tx_gl_proc p = load("gl" #name);                                                                           \
    if (!p) return *missing = "gl" #name, false;                                                              \
    memcpy(&gl->name, &p, sizeof p);                                                                           \
  }
  TX_GL_FUNCS(TX_GL_LOAD)
#undef TX_GL_LOAD
  return true;
}
