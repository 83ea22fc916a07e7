// Text and bars over a frame: every lit font pixel is a small rectangle.
#include "overlay.h"

#include <ctype.h>
#include <stdlib.h>
#include <string.h>

#define MAX_RECTS 8192

static const struct { char c; unsigned char rows[7]; } font[] = {
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}}, {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}}, {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}}, {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}}, {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}}, {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'A', {0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}}, {'B', {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E}},
    {'C', {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}}, {'D', {0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C}},
    {'E', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}}, {'F', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10}},
    {'G', {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}}, {'H', {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}},
    {'I', {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}}, {'J', {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C}},
    {'K', {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}}, {'L', {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F}},
    {'M', {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}}, {'N', {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}},
    {'O', {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}}, {'P', {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}},
    {'Q', {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D}}, {'R', {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11}},
    {'S', {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}}, {'T', {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'U', {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}}, {'V', {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04}},
    {'W', {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}}, {'X', {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11}},
    {'Y', {0x11, 0x11, 0x0A, 0x04, 0x04, 0x04, 0x04}}, {'Z', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F}},
    {' ', {0, 0, 0, 0, 0, 0, 0}},                     {'.', {0, 0, 0, 0, 0, 0x0C, 0x0C}},
    {',', {0, 0, 0, 0, 0x0C, 0x04, 0x08}},            {':', {0, 0x0C, 0x0C, 0, 0x0C, 0x0C, 0}},
    {'-', {0, 0, 0, 0x1F, 0, 0, 0}},                  {'+', {0, 0x04, 0x04, 0x1F, 0x04, 0x04, 0}},
    {'/', {0x01, 0x01, 0x02, 0x04, 0x08, 0x10, 0x10}}, {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}}, {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {'_', {0, 0, 0, 0, 0, 0, 0x1F}},                  {'=', {0, 0, 0x1F, 0, 0x1F, 0, 0}},
    {'|', {0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
};

const unsigned char* tx_overlay_glyph(char c) {
  c = (char)toupper((unsigned char)c);
  for (size_t i = 0; i < sizeof font / sizeof font[0]; i++)
    if (font[i].c == c) return font[i].rows;
  return NULL;
}

struct tx_overlay {
  const tx_gl* gl;
  GLuint prog, vao, vbo;
  float* verts; // (6 per rect x 5) px position, colour
  int nrects;
};

static const char* const vs =
    "#version 330 core\n"
    "layout(location = 0) in vec2 a_px; layout(location = 1) in vec3 a_colour;\n"
    "uniform vec2 u_size; out vec3 v_colour;\n"
    "void main() { v_colour = a_colour; gl_Position = vec4(2.0 * a_px.x / u_size.x - 1.0, 1.0 - 2.0 * a_px.y / u_size.y, 0.0, 1.0); }\n";
static const char* const fs =
    "#version 330 core\n"
    "in vec3 v_colour; out vec4 frag;\n"
    "void main() { frag = vec4(v_colour, 1.0); }\n";

tx_overlay* tx_overlay_create(const tx_gl* gl) {
  tx_overlay* o = calloc(1, sizeof *o);
  if (!o || !(o->verts = malloc(sizeof(float) * 30 * MAX_RECTS))) return free(o), NULL;
  o->gl = gl;
  GLuint v = gl->CreateShader(GL_VERTEX_SHADER), f = gl->CreateShader(GL_FRAGMENT_SHADER);
  gl->ShaderSource(v, 1, &vs, NULL);
  gl->ShaderSource(f, 1, &fs, NULL);
  gl->CompileShader(v);
  gl->CompileShader(f);
  o->prog = gl->CreateProgram();
  gl->AttachShader(o->prog, v);
  gl->AttachShader(o->prog, f);
  gl->LinkProgram(o->prog);
  gl->DeleteShader(v);
  gl->DeleteShader(f);
  GLint ok = 0;
  gl->GetProgramiv(o->prog, GL_LINK_STATUS, &ok);
  if (!ok) {
    gl->DeleteProgram(o->prog);
    free(o->verts);
    free(o);
    return NULL;
  }
  gl->GenVertexArrays(1, &o->vao);
  gl->BindVertexArray(o->vao);
  gl->GenBuffers(1, &o->vbo);
  gl->BindBuffer(GL_ARRAY_BUFFER, o->vbo);
  gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(float) * 30 * MAX_RECTS), NULL, GL_STREAM_DRAW);
  gl->EnableVertexAttribArray(0);
  gl->VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 5 * sizeof(float), 0);
  gl->EnableVertexAttribArray(1);
  gl->VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 5 * sizeof(float), (void*)(2 * sizeof(float)));
  gl->BindVertexArray(0);
  return o;
}

void tx_overlay_destroy(tx_overlay* o) {
  if (!o) return;
  o->gl->DeleteBuffers(1, &o->vbo);
  o->gl->DeleteVertexArrays(1, &o->vao);
  o->gl->DeleteProgram(o->prog);
  free(o->verts);
  free(o);
}

void tx_overlay_rect(tx_overlay* o, int x, int y, int w, int h, const float rgb[3]) {
  if (!o || o->nrects == MAX_RECTS) return;
  float x0 = (float)x, y0 = (float)y, x1 = (float)(x + w), y1 = (float)(y + h);
  const float corners[6][2] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y0}, {x1, y1}, {x0, y1}};
  float* v = o->verts + 30 * o->nrects++;
  for (int k = 0; k < 6; k++) {
    v[5 * k] = corners[k][0];
    v[5 * k + 1] = corners[k][1];
    memcpy(v + 5 * k + 2, rgb, 3 * sizeof(float));
  }
}

void tx_overlay_text(tx_overlay* o, int x, int y, int scale, const char* text, const float rgb[3]) {
  for (; *text; text++, x += 6 * scale) {
    const unsigned char* g = tx_overlay_glyph(*text);
    if (!g) continue;
    for (int row = 0; row < 7; row++)
      for (int col = 0; col < 5; col++)
        if (g[row] & (0x10 >> col)) tx_overlay_rect(o, x + col * scale, y + row * scale, scale, scale, rgb);
  }
}

void tx_overlay_flush(tx_overlay* o, int width, int height) {
  tx_overlay_draw(o, 0, 0, width, height);
  tx_overlay_clear(o);
}

void tx_overlay_clear(tx_overlay* o) {
  if (o) o->nrects = 0;
}

void tx_overlay_draw(tx_overlay* o, int x, int y, int width, int height) {
  if (!o || !o->nrects) return;
  const tx_gl* gl = o->gl;
  gl->Viewport(x, y, width, height);
  gl->Disable(GL_DEPTH_TEST);
  gl->UseProgram(o->prog);
  const float size[2] = {(float)width, (float)height};
  GLint at = gl->GetUniformLocation(o->prog, "u_size");
  gl->Uniform2fv(at, 1, size);
  gl->BindVertexArray(o->vao);
  gl->BindBuffer(GL_ARRAY_BUFFER, o->vbo);
  gl->BufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)(sizeof(float) * 30 * o->nrects), o->verts);
  gl->DrawArrays(GL_TRIANGLES, 0, 6 * o->nrects);
  gl->BindVertexArray(0);
  gl->Enable(GL_DEPTH_TEST);
}
