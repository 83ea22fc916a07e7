// GL 3.3 core drawing of meshes, spheres, cylinders, tools and planes.
#include "renderer.h"

#include "organ_texture.h"

#include "../../model/error.h"

#include <tactus/components.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CYL_SIDES 16
#define STR_(x) #x
#define STR(x) STR_(x) // a macro's value as a string, for the shaders
#define SKIN_TEX 512

typedef struct mesh_slot {
  GLuint vao, vbo, ebo;
  float* verts;     // (n x 8) position m, normal, uv
  uint32_t* idx;    // (m x 3) checked indices
  size_t vcap, icap; // capacity in vertices and indices
  uint32_t nverts, nidx;
  float uv_basis[6]; // planar projection of the first frame: origin (u, v) and axes
  uint32_t uv_for;  // vertex count the basis was made for
  float colour[3];
  int textured; // 0: the colour; 1: the skin texture; 2: the colour times the tissue texture; 3: a scalar's colour map
} mesh_slot;

struct tx_renderer {
  tx_gl gl;
  GLuint mesh_prog, sphere_prog, cyl_prog;
  GLuint sphere_vao, sphere_vbo, sphere_inst;
  GLuint cyl_vao, cyl_vbo, cyl_inst;
  GLuint skin_tex, tissue_tex, cmap_tex;
  int cyl_nverts;
  mesh_slot meshes[TX_DRAW_MAX + TX_DRAW_MAX];
  int nmeshes;
  float* spheres; // (n x 7) centre m, radius m, colour
  size_t nspheres, sphere_cap, sphere_gpu_cap;
  float* cyls;    // (n x 10) p0 m, p1 m, radius m, colour
  size_t ncyls, cyl_cap, cyl_gpu_cap;
  double lo[3], hi[3];
  bool any;
  uint64_t skipped;
  tx_instrument_mesh* instruments[TX_DRAW_MAX]; // read at the first frame that draws each
  const tx_draw_item* instrument_of[TX_DRAW_MAX];
};

static void make_colour_map(tx_renderer* r); // colour_by on meshes, below

// per-pixel Blinn-Phong with the viewer at infinity (as fixed-function GL's
// default): the half vector is one per eye, and the highlight's power is five
// squarings, which llvmpipe runs far faster than pow()
#define SHADE_GLSL \
  "uniform vec3 u_light; uniform vec3 u_view_dir; uniform vec3 u_half; uniform vec4 u_lighting;\n" \
  "vec3 shade(vec3 n, vec3 base) {\n" \
  "  float diff = max(dot(n, -u_light), 0.0);\n" \
  "  float s = max(dot(n, u_half), 0.0);\n" \
  "  s *= s; s *= s; s *= s; s *= s; s *= s;\n" \
  "  float spec = diff > 0.0 ? s : 0.0;\n" \
  "  return base * (u_lighting.x + u_lighting.y * diff) + vec3(u_lighting.z * spec);\n" \
  "}\n"

static const char* const fs_src =
    "#version 330 core\n"
    "in vec3 v_normal; flat in vec3 v_colour; in vec2 v_uv;\n"
    "uniform int u_textured; uniform sampler2D u_tex;\n"
    "const float TISSUE_LO = " STR(TX_TISSUE_LO) "; const float TISSUE_SPAN = " STR(TX_TISSUE_SPAN) ";\n"
    SHADE_GLSL
    "out vec4 frag;\n"
    "void main() {\n"
    "  vec3 n = normalize(v_normal);\n"
    "  if (dot(n, u_view_dir) < 0.0) n = -n;\n" // two-sided: a cloth is seen from both sides
    "  vec3 base = u_textured == 1 ? texture(u_tex, v_uv).rgb\n"
    "            : u_textured == 2 ? v_colour * (TISSUE_LO + TISSUE_SPAN * texture(u_tex, v_uv).rgb) : v_colour;\n"
    "  frag = vec4(shade(n, base), 1.0);\n"
    "}\n";

// spheres are ray-cast impostors: one quad per sphere, facing the eye and just
// covering the cone of rays that touch it; each pixel intersects its ray with
// the sphere exactly, so the silhouette, normal and depth are exact at any size
// and a sphere costs four vertices instead of a tessellation
static const char* const sphere_vs =
    "#version 330 core\n"
    "layout(location = 0) in vec2 a_corner; layout(location = 1) in vec4 a_sphere; layout(location = 2) in vec3 a_colour;\n"
    "uniform mat4 u_proj; uniform mat4 u_view;\n"
    "out vec3 v_ray; flat out vec4 v_sphere; flat out vec3 v_colour;\n"
    "void main() {\n"
    "  vec3 c = (u_view * vec4(a_sphere.xyz, 1.0)).xyz; float r = a_sphere.w;\n" // view space: the eye at the origin
    "  float d2 = dot(c, c);\n"
    "  v_sphere = vec4(c, r); v_colour = a_colour;\n"
    "  if (d2 <= r * r * 1.0001) { gl_Position = vec4(2.0, 2.0, 2.0, 1.0); v_ray = vec3(0.0); return; }\n" // the eye inside: nothing
    "  vec3 w = c / sqrt(d2);\n"
    "  vec3 t = abs(w.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);\n"
    "  vec3 u = normalize(cross(t, w)); vec3 v = cross(w, u);\n"
    "  float h = r * sqrt(d2 / (d2 - r * r));\n" // the tangent cone's radius in the plane through the centre
    "  vec3 p = c + h * (a_corner.x * u + a_corner.y * v);\n"
    "  v_ray = p;\n"
    "  gl_Position = u_proj * vec4(p, 1.0);\n"
    "}\n";

static const char* const sphere_fs =
    "#version 330 core\n"
    "in vec3 v_ray; flat in vec4 v_sphere; flat in vec3 v_colour;\n"
    "uniform mat4 u_proj; uniform mat4 u_view;\n"
    SHADE_GLSL
    "out vec4 frag;\n"
    "void main() {\n"
    "  vec3 dir = normalize(v_ray); vec3 c = v_sphere.xyz; float r = v_sphere.w;\n"
    "  float b = dot(dir, c); float disc = b * b - dot(c, c) + r * r;\n"
    "  if (disc < 0.0) discard;\n"
    "  vec3 p = (b - sqrt(disc)) * dir;\n" // the nearer hit
    "  vec4 clip = u_proj * vec4(p, 1.0);\n"
    "  float z = clip.z / clip.w;\n"
    "  if (z < -1.0) discard;\n" // before the near plane
    "  gl_FragDepth = 0.5 * z + 0.5;\n"
    "  vec3 n = ((p - c) / r) * mat3(u_view);\n" // back to world space: the view's rotation transposed
    "  frag = vec4(shade(n, v_colour), 1.0);\n"
    "}\n";

static const char* const mesh_vs =
    "#version 330 core\n"
    "layout(location = 0) in vec3 a_pos; layout(location = 1) in vec3 a_normal; layout(location = 2) in vec2 a_uv;\n"
    "uniform mat4 u_proj; uniform mat4 u_view; uniform vec3 u_colour;\n"
    "out vec3 v_normal; flat out vec3 v_colour; out vec2 v_uv;\n"
    "void main() {\n"
    "  v_normal = a_normal; v_colour = u_colour; v_uv = a_uv;\n"
    "  gl_Position = u_proj * u_view * vec4(a_pos, 1.0);\n"
    "}\n";

static const char* const cyl_vs =
    "#version 330 core\n"
    "layout(location = 0) in vec3 a_pos; layout(location = 1) in vec3 a_p0; layout(location = 2) in vec4 a_p1r;\n"
    "layout(location = 3) in vec3 a_colour;\n"
    "uniform mat4 u_proj; uniform mat4 u_view;\n"
    "out vec3 v_normal; flat out vec3 v_colour; out vec2 v_uv;\n"
    "void main() {\n"
    "  vec3 axis = a_p1r.xyz - a_p0; float len = length(axis);\n"
    "  vec3 y = len > 1e-9 ? axis / len : vec3(0.0, 1.0, 0.0);\n"
    "  vec3 t = abs(y.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);\n"
    "  vec3 x = normalize(cross(t, y)); vec3 z = cross(x, y);\n"
    "  vec3 radial = x * a_pos.x + z * a_pos.z;\n"
    "  vec3 p = a_p0 + y * (a_pos.y * len) + radial * a_p1r.w;\n"
    "  v_normal = radial; v_colour = a_colour; v_uv = vec2(0.0);\n"
    "  gl_Position = u_proj * u_view * vec4(p, 1.0);\n"
    "}\n";

static GLuint compile(tx_gl* gl, GLenum kind, const char* src) {
  GLuint s = gl->CreateShader(kind);
  gl->ShaderSource(s, 1, &src, NULL);
  gl->CompileShader(s);
  GLint ok = 0;
  gl->GetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[512] = "";
    gl->GetShaderInfoLog(s, sizeof log, NULL, log);
    for (char* c = log; *c; c++)
      if (*c == '\n') *c = ' ';
    tx_set_error("shader does not compile: %s", log);
    gl->DeleteShader(s);
    return 0;
  }
  return s;
}

static GLuint program(tx_gl* gl, const char* vs, const char* fs) {
  GLuint v = compile(gl, GL_VERTEX_SHADER, vs), f = v ? compile(gl, GL_FRAGMENT_SHADER, fs) : 0;
  if (!v || !f) return 0;
  GLuint p = gl->CreateProgram();
  gl->AttachShader(p, v);
  gl->AttachShader(p, f);
  gl->LinkProgram(p);
  gl->DeleteShader(v);
  gl->DeleteShader(f);
  GLint ok = 0;
  gl->GetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[512] = "";
    gl->GetProgramInfoLog(p, sizeof log, NULL, log);
    tx_set_error("shaders do not link: %s", log);
    gl->DeleteProgram(p);
    return 0;
  }
  return p;
}

void tx_colour_map(float t, float rgb[3]) {
  static const float stops[5][3] = {{0.1f, 0.2f, 0.9f}, {0.1f, 0.8f, 0.9f}, {0.2f, 0.8f, 0.2f}, {0.95f, 0.9f, 0.15f},
                                    {0.9f, 0.15f, 0.1f}};
  if (!(t > 0)) t = 0; // NaN too
  if (t > 1) t = 1;
  float x = t * 4;
  int i = x >= 4 ? 3 : (int)x;
  float f = x - (float)i;
  for (int c = 0; c < 3; c++) rgb[c] = stops[i][c] * (1 - f) + stops[i + 1][c] * f;
}

// tileable value noise: a hashed lattice of the given period, smoothly interpolated
static float lattice(int x, int y, int period, uint32_t seed) {
  x = ((x % period) + period) % period;
  y = ((y % period) + period) % period;
  uint32_t h = (uint32_t)x * 374761393u + (uint32_t)y * 668265263u + seed * 2246822519u;
  h = (h ^ (h >> 13)) * 1274126177u;
  return (float)((h ^ (h >> 16)) & 0xffff) / 65535.0f;
}

static float noise(float u, float v, int period, uint32_t seed) {
  int x = (int)floorf(u), y = (int)floorf(v);
  float fx = u - (float)x, fy = v - (float)y;
  fx = fx * fx * (3 - 2 * fx);
  fy = fy * fy * (3 - 2 * fy);
  float a = lattice(x, y, period, seed), b = lattice(x + 1, y, period, seed), c = lattice(x, y + 1, period, seed),
        d = lattice(x + 1, y + 1, period, seed);
  return (a * (1 - fx) + b * fx) * (1 - fy) + (c * (1 - fx) + d * fx) * fy;
}

void tx_skin_texture(uint8_t* rgb, int size) {
  // a mottled base tone (four octaves), fine pores, and faint creases
  static const float light[3] = {0.93f, 0.74f, 0.63f}, dark[3] = {0.78f, 0.55f, 0.46f}, pore[3] = {0.62f, 0.40f, 0.34f};
  for (int y = 0; y < size; y++)
    for (int x = 0; x < size; x++) {
      float u = (float)x / (float)size, v = (float)y / (float)size, m = 0, amp = 0.5f;
      for (int o = 0; o < 4; o++, amp *= 0.5f) {
        int period = 4 << o;
        m += amp * noise(u * (float)period, v * (float)period, period, 11u + (uint32_t)o);
      }
      float p = noise(u * 96, v * 96, 96, 7u), crease = noise(u * 12, v * 48, 12, 3u);
      float pores = p > 0.8f ? (p - 0.8f) * 5 : 0;
      float lines = fabsf(crease - 0.5f) < 0.02f ? 0.35f : 0;
      for (int c = 0; c < 3; c++) {
        float base = dark[c] + (light[c] - dark[c]) * m * 1.1f;
        float val = base * (1 - pores * 0.6f - lines * 0.3f) + pore[c] * pores * 0.3f;
        rgb[3 * (y * size + x) + c] = (uint8_t)(fminf(fmaxf(val, 0), 1) * 255 + 0.5f);
      }
    }
}

static void make_sphere(tx_renderer* r) {
  tx_gl* gl = &r->gl;
  const float corners[8] = {-1, -1, 1, -1, -1, 1, 1, 1}; // a triangle strip
  gl->GenVertexArrays(1, &r->sphere_vao);
  gl->BindVertexArray(r->sphere_vao);
  gl->GenBuffers(1, &r->sphere_vbo);
  gl->BindBuffer(GL_ARRAY_BUFFER, r->sphere_vbo);
  gl->BufferData(GL_ARRAY_BUFFER, sizeof corners, corners, GL_STATIC_DRAW);
  gl->EnableVertexAttribArray(0);
  gl->VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), 0);
  gl->GenBuffers(1, &r->sphere_inst);
  gl->BindBuffer(GL_ARRAY_BUFFER, r->sphere_inst);
  gl->EnableVertexAttribArray(1);
  gl->VertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, 7 * sizeof(float), 0);
  gl->VertexAttribDivisor(1, 1);
  gl->EnableVertexAttribArray(2);
  gl->VertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, 7 * sizeof(float), (void*)(4 * sizeof(float)));
  gl->VertexAttribDivisor(2, 1);
  gl->BindVertexArray(0);
}

static void make_cylinder(tx_renderer* r) {
  tx_gl* gl = &r->gl;
  float v[CYL_SIDES * 6 * 3];
  int nv = 0;
  for (int i = 0; i < CYL_SIDES; i++) {
    double a0 = 2 * M_PI * i / CYL_SIDES, a1 = 2 * M_PI * (i + 1) / CYL_SIDES;
    float c0 = (float)cos(a0), s0 = (float)sin(a0), c1 = (float)cos(a1), s1 = (float)sin(a1);
    float q[18] = {c0, 0, s0, c0, 1, s0, c1, 0, s1, c1, 0, s1, c0, 1, s0, c1, 1, s1};
    memcpy(v + nv, q, sizeof q);
    nv += 18;
  }
  r->cyl_nverts = nv / 3;
  gl->GenVertexArrays(1, &r->cyl_vao);
  gl->BindVertexArray(r->cyl_vao);
  gl->GenBuffers(1, &r->cyl_vbo);
  gl->BindBuffer(GL_ARRAY_BUFFER, r->cyl_vbo);
  gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * sizeof(float)), v, GL_STATIC_DRAW);
  gl->EnableVertexAttribArray(0);
  gl->VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), 0);
  gl->GenBuffers(1, &r->cyl_inst);
  gl->BindBuffer(GL_ARRAY_BUFFER, r->cyl_inst);
  const GLsizei stride = 10 * sizeof(float);
  gl->EnableVertexAttribArray(1);
  gl->VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, 0);
  gl->VertexAttribDivisor(1, 1);
  gl->EnableVertexAttribArray(2);
  gl->VertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, stride, (void*)(3 * sizeof(float)));
  gl->VertexAttribDivisor(2, 1);
  gl->EnableVertexAttribArray(3);
  gl->VertexAttribPointer(3, 3, GL_FLOAT, GL_FALSE, stride, (void*)(7 * sizeof(float)));
  gl->VertexAttribDivisor(3, 1);
  gl->BindVertexArray(0);
}

tx_renderer* tx_renderer_create(tx_gl_loader load) {
  tx_renderer* r = calloc(1, sizeof *r);
  if (!r) return tx_set_error("out of memory"), NULL;
  const char* missing = NULL;
  if (!tx_gl_load(&r->gl, load, &missing)) {
    tx_set_error("the GL context lacks %s (GL 3.3 core is needed)", missing);
    free(r);
    return NULL;
  }
  tx_gl* gl = &r->gl;
  if (!(r->mesh_prog = program(gl, mesh_vs, fs_src)) || !(r->sphere_prog = program(gl, sphere_vs, sphere_fs)) ||
      !(r->cyl_prog = program(gl, cyl_vs, fs_src))) {
    tx_renderer_destroy(r);
    return NULL;
  }
  make_sphere(r);
  make_cylinder(r);
  uint8_t* tex = malloc(SKIN_TEX * SKIN_TEX * 3);
  if (!tex) {
    tx_renderer_destroy(r);
    return tx_set_error("out of memory"), NULL;
  }
  for (int k = 0; k < 2; k++) {
    GLuint* id = k == 0 ? &r->skin_tex : &r->tissue_tex;
    if (k == 0) tx_skin_texture(tex, SKIN_TEX);
    else tx_tissue_texture(tex, SKIN_TEX);
    gl->GenTextures(1, id);
    gl->BindTexture(GL_TEXTURE_2D, *id);
    gl->PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl->TexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, SKIN_TEX, SKIN_TEX, 0, GL_RGB, GL_UNSIGNED_BYTE, tex);
    gl->GenerateMipmap(GL_TEXTURE_2D);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_NEAREST);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  }
  free(tex);
  make_colour_map(r);
  if (gl->GetError() != GL_NO_ERROR) {
    tx_renderer_destroy(r);
    return tx_set_error("GL error while setting up the renderer"), NULL;
  }
  return r;
}

void tx_renderer_destroy(tx_renderer* r) {
  if (!r) return;
  tx_gl* gl = &r->gl;
  if (gl->DeleteProgram) {
    for (int i = 0; i < TX_DRAW_MAX * 2; i++) {
      mesh_slot* m = &r->meshes[i];
      if (m->vao) gl->DeleteVertexArrays(1, &m->vao), gl->DeleteBuffers(1, &m->vbo), gl->DeleteBuffers(1, &m->ebo);
      free(m->verts);
      free(m->idx);
    }
    if (r->sphere_vao) gl->DeleteVertexArrays(1, &r->sphere_vao);
    if (r->cyl_vao) gl->DeleteVertexArrays(1, &r->cyl_vao);
    GLuint bufs[4] = {r->sphere_vbo, r->sphere_inst, r->cyl_vbo, r->cyl_inst};
    for (int i = 0; i < 4; i++)
      if (bufs[i]) gl->DeleteBuffers(1, &bufs[i]);
    if (r->skin_tex) gl->DeleteTextures(1, &r->skin_tex);
    if (r->tissue_tex) gl->DeleteTextures(1, &r->tissue_tex);
    if (r->cmap_tex) gl->DeleteTextures(1, &r->cmap_tex);
    if (r->mesh_prog) gl->DeleteProgram(r->mesh_prog);
    if (r->sphere_prog) gl->DeleteProgram(r->sphere_prog);
    if (r->cyl_prog) gl->DeleteProgram(r->cyl_prog);
  }
  for (int i = 0; i < TX_DRAW_MAX; i++) tx_instrument_mesh_free(r->instruments[i]);
  free(r->spheres);
  free(r->cyls);
  free(r);
}

const tx_gl* tx_renderer_gl(const tx_renderer* r) { return &r->gl; }
uint64_t tx_renderer_skipped(const tx_renderer* r) { return r->skipped; }

static bool grow(void** p, size_t* cap, size_t need, size_t elem) {
  if (need <= *cap) return true;
  size_t c = *cap ? *cap : 64;
  while (c < need) c *= 2;
  void* q = realloc(*p, c * elem);
  if (!q) return false;
  *p = q;
  *cap = c;
  return true;
}

static void include(tx_renderer* r, const float p[3], float pad) {
  for (int i = 0; i < 3; i++) {
    r->lo[i] = fmin(r->lo[i], p[i] - pad);
    r->hi[i] = fmax(r->hi[i], p[i] + pad);
  }
  r->any = true;
}

static bool finite_n(const float* v, int n) {
  for (int i = 0; i < n; i++)
    if (!isfinite(v[i])) return false;
  return true;
}

static void add_sphere(tx_renderer* r, const float c[3], float radius, const float colour[3]) {
  if (!grow((void**)&r->spheres, &r->sphere_cap, r->nspheres + 1, 7 * sizeof(float))) return;
  float* s = r->spheres + 7 * r->nspheres++;
  memcpy(s, c, 3 * sizeof(float));
  s[3] = radius;
  memcpy(s + 4, colour, 3 * sizeof(float));
  include(r, c, radius);
}

static void add_cylinder(tx_renderer* r, const float p0[3], const float p1[3], float radius, const float colour[3]) {
  if (!grow((void**)&r->cyls, &r->cyl_cap, r->ncyls + 1, 10 * sizeof(float))) return;
  float* s = r->cyls + 10 * r->ncyls++;
  memcpy(s, p0, 3 * sizeof(float));
  memcpy(s + 3, p1, 3 * sizeof(float));
  s[6] = radius;
  memcpy(s + 7, colour, 3 * sizeof(float));
  include(r, p0, radius);
  include(r, p1, radius);
}

// a planar texture projection: the two axes of largest extent of the first frame
static void uv_basis(mesh_slot* m, const float* x, uint32_t nv) {
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (uint32_t i = 0; i < nv; i++)
    for (int c = 0; c < 3; c++)
      if (isfinite(x[3 * i + c])) lo[c] = fminf(lo[c], x[3 * i + c]), hi[c] = fmaxf(hi[c], x[3 * i + c]);
  int flat = 0;
  for (int c = 1; c < 3; c++)
    if (hi[c] - lo[c] < hi[flat] - lo[flat]) flat = c;
  int a = flat == 0 ? 1 : 0, b = flat == 2 ? 1 : 2;
  m->uv_basis[0] = isfinite(lo[a]) ? lo[a] : 0;
  m->uv_basis[1] = isfinite(lo[b]) ? lo[b] : 0;
  m->uv_basis[2] = (float)a;
  m->uv_basis[3] = (float)b;
  m->uv_for = nv;
}

#define UV_PER_M 20.0f // the texture repeats every 5 cm

// vertices with area-weighted normals, and the triangles whose indices are in range
static void fill_mesh(tx_renderer* r, mesh_slot* m, const float* x, uint32_t nv, const int32_t* tri, uint32_t nt) {
  if (!grow((void**)&m->verts, &m->vcap, nv, 8 * sizeof(float)) ||
      !grow((void**)&m->idx, &m->icap, (size_t)nt * 3, sizeof(uint32_t))) {
    m->nverts = m->nidx = 0;
    return;
  }
  if (m->uv_for != nv) uv_basis(m, x, nv);
  int a = (int)m->uv_basis[2], b = (int)m->uv_basis[3];
  for (uint32_t i = 0; i < nv; i++) {
    float* v = m->verts + 8 * i;
    bool ok = finite_n(x + 3 * i, 3);
    for (int c = 0; c < 3; c++) v[c] = ok ? x[3 * i + c] : 0, v[3 + c] = 0;
    v[6] = (v[a] - m->uv_basis[0]) * UV_PER_M;
    v[7] = (v[b] - m->uv_basis[1]) * UV_PER_M;
    if (ok) include(r, v, 0);
    else r->skipped++;
  }
  m->nidx = 0;
  for (uint32_t t = 0; t < nt; t++) {
    const int32_t* q = tri + 3 * t;
    if (q[0] < 0 || q[1] < 0 || q[2] < 0 || (uint32_t)q[0] >= nv || (uint32_t)q[1] >= nv || (uint32_t)q[2] >= nv) {
      r->skipped++;
      continue;
    }
    float *p0 = m->verts + 8 * q[0], *p1 = m->verts + 8 * q[1], *p2 = m->verts + 8 * q[2];
    float e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]}, e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    float nrm[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    for (int k = 0; k < 3; k++)
      for (int c = 0; c < 3; c++) m->verts[8 * q[k] + 3 + c] += nrm[c];
    for (int k = 0; k < 3; k++) m->idx[m->nidx++] = (uint32_t)q[k];
  }
  for (uint32_t i = 0; i < nv; i++) {
    float* n = m->verts + 8 * i + 3;
    float l = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (l > 0) n[0] /= l, n[1] /= l, n[2] /= l;
    else n[1] = 1;
  }
  m->nverts = nv;
}

// A mesh coloured by a scalar per vertex (colour_by, e.g. ORGAN.temperature,
// the paper's Figure 12): the scalar goes into the texture coordinate and the
// colour map is a 1-D texture, so the colours interpolate smoothly across
// each triangle through the shaders the textures use.
#define CMAP_TEXELS 256

static void make_colour_map(tx_renderer* r) {
  tx_gl* gl = &r->gl;
  uint8_t rgb[CMAP_TEXELS * 3];
  for (int i = 0; i < CMAP_TEXELS; i++) {
    float c[3];
    tx_colour_map((float)i / (CMAP_TEXELS - 1), c);
    for (int k = 0; k < 3; k++) rgb[3 * i + k] = (uint8_t)lroundf(255 * c[k]);
  }
  gl->GenTextures(1, &r->cmap_tex);
  gl->BindTexture(GL_TEXTURE_2D, r->cmap_tex);
  gl->PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  gl->TexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, CMAP_TEXELS, 1, 0, GL_RGB, GL_UNSIGNED_BYTE, rgb);
  gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

// the scalar of each vertex into u (texel centres of the map), or the plain
// colour while the scalar has other rows (not yet published)
static void colour_mesh_by(tx_renderer* r, mesh_slot* m, const tx_draw_item* it, const float* scalar, uint32_t n) {
  if (!scalar || n != m->nverts || !n) {
    if (n) r->skipped++;
    return;
  }
  for (uint32_t i = 0; i < n; i++) {
    float t = (scalar[i] - it->range[0]) / (it->range[1] - it->range[0]);
    if (!(t > 0)) t = 0; // NaN too
    if (t > 1) t = 1;
    m->verts[8 * i + 6] = (0.5f + t * (CMAP_TEXELS - 1)) / CMAP_TEXELS;
    m->verts[8 * i + 7] = 0.5f;
  }
  m->textured = 3;
}

static mesh_slot* slot(tx_renderer* r) {
  mesh_slot* m = &r->meshes[r->nmeshes++];
  if (!m->vao) {
    tx_gl* gl = &r->gl;
    gl->GenVertexArrays(1, &m->vao);
    gl->BindVertexArray(m->vao);
    gl->GenBuffers(1, &m->vbo);
    gl->GenBuffers(1, &m->ebo);
    gl->BindBuffer(GL_ARRAY_BUFFER, m->vbo);
    gl->BindBuffer(GL_ELEMENT_ARRAY_BUFFER, m->ebo);
    for (int a = 0; a < 3; a++) gl->EnableVertexAttribArray((GLuint)a);
    gl->VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 8 * sizeof(float), 0);
    gl->VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 8 * sizeof(float), (void*)(3 * sizeof(float)));
    gl->VertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, 8 * sizeof(float), (void*)(6 * sizeof(float)));
    gl->BindVertexArray(0);
  }
  return m;
}

static void upload_mesh(tx_renderer* r, mesh_slot* m) {
  tx_gl* gl = &r->gl;
  gl->BindVertexArray(m->vao);
  gl->BindBuffer(GL_ARRAY_BUFFER, m->vbo);
  gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(m->nverts * 8 * sizeof(float)), m->verts, GL_STREAM_DRAW);
  gl->BufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(m->nidx * sizeof(uint32_t)), m->idx, GL_STREAM_DRAW);
  gl->BindVertexArray(0);
}

static void scalar_colour(const tx_draw_item* it, const float* scalar, uint32_t nscalar, uint32_t i, float out[3]) {
  if (!scalar || i >= nscalar) {
    memcpy(out, it->colour, 3 * sizeof(float));
    return;
  }
  tx_colour_map((scalar[i] - it->range[0]) / (it->range[1] - it->range[0]), out);
}

// rotate v by the unit quaternion (w, x, y, z)
static void rotate(const double q[4], const float v[3], float out[3]) {
  double w = q[0], x = q[1], y = q[2], z = q[3];
  double t[3] = {2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])};
  out[0] = (float)(v[0] + w * t[0] + (y * t[2] - z * t[1]));
  out[1] = (float)(v[1] + w * t[1] + (z * t[0] - x * t[2]));
  out[2] = (float)(v[2] + w * t[2] + (x * t[1] - y * t[0]));
}

void tx_force_arrow_start(const float p[3], const float shaft[3], float radius, const double f[3], float out[3]) {
  double fl = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]), sl = 0;
  for (int c = 0; c < 3; c++) sl += (double)shaft[c] * shaft[c];
  sl = sqrt(sl);
  memcpy(out, p, 3 * sizeof(float));
  if (!(fl > 0) || !isfinite(fl) || !(sl > 0)) return;
  double u[3] = {f[0] / fl, f[1] / fl, f[2] / fl}, cosa = 0;
  for (int c = 0; c < 3; c++) cosa += u[c] * shaft[c] / sl;
  // off the HIP sphere; the rod (0.45 r) clears the shaft (0.35 r) once its axis is 0.8 r
  // from the shaft's, and its distance grows along the force: at the sphere it is r sin(a)
  double t = radius, sina = sqrt(fmax(0, 1 - cosa * cosa));
  if (cosa > 0 && sina < 0.8) t = fmax(t, sl / cosa); // within the shaft: start where the shaft ends
  for (int c = 0; c < 3; c++) out[c] = (float)(p[c] + t * u[c]);
}

void tx_renderer_upload(tx_renderer* r, const tx_scene* s) {
  r->nmeshes = 0;
  r->nspheres = r->ncyls = 0;
  r->any = false;
  for (int i = 0; i < 3; i++) r->lo[i] = INFINITY, r->hi[i] = -INFINITY;
  for (int k = 0; k < s->count; k++) {
    const tx_scene_item* si = &s->items[k];
    const tx_draw_item* it = si->item;
    switch (it->kind) {
    case TX_DRAW_MESH: {
      mesh_slot* m = slot(r);
      fill_mesh(r, m, si->data[0], si->rows[0], si->data[1], si->rows[1]);
      memcpy(m->colour, it->colour, sizeof m->colour);
      m->textured = it->skin_texture ? 1 : it->tissue_texture ? 2 : 0;
      if (*it->scalar) colour_mesh_by(r, m, it, si->data[2], si->rows[2]);
      upload_mesh(r, m);
      break;
    }
    case TX_DRAW_PLANE: {
      // a square around the point, spanned by two directions normal to the plane's normal
      const float* p = it->plane;
      float nrm[3] = {p[3], p[4], p[5]}, t[3] = {0, 1, 0};
      if (fabsf(nrm[1]) > 0.9f) t[0] = 1, t[1] = 0;
      float u[3] = {t[1] * nrm[2] - t[2] * nrm[1], t[2] * nrm[0] - t[0] * nrm[2], t[0] * nrm[1] - t[1] * nrm[0]};
      float lu = sqrtf(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      for (int c = 0; c < 3; c++) u[c] /= lu;
      float v[3] = {nrm[1] * u[2] - nrm[2] * u[1], nrm[2] * u[0] - nrm[0] * u[2], nrm[0] * u[1] - nrm[1] * u[0]};
      float x[12];
      const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      for (int q = 0; q < 4; q++)
        for (int c = 0; c < 3; c++) x[3 * q + c] = p[c] + p[6] * (corners[q][0] * u[c] + corners[q][1] * v[c]);
      const int32_t tri[6] = {0, 1, 2, 0, 2, 3};
      mesh_slot* m = slot(r);
      fill_mesh(r, m, x, 4, tri, 2);
      memcpy(m->colour, it->colour, sizeof m->colour);
      m->textured = 0;
      upload_mesh(r, m);
      break;
    }
    case TX_DRAW_SPHERES: {
      const tx_sphere* sp = si->data[0];
      const float* scalar = *it->scalar ? si->data[1] : NULL;
      uint32_t nscalar = *it->scalar ? si->rows[1] : 0;
      for (uint32_t i = 0; i < si->rows[0]; i++) {
        if (!finite_n(sp[i].c, 3) || !isfinite(sp[i].r) || !(sp[i].r > 0)) {
          r->skipped++;
          continue;
        }
        if (it->has_cut) { // cut away: not drawn, and not an error
          const float* c = sp[i].c;
          float side = (c[0] - it->cut[0]) * it->cut[3] + (c[1] - it->cut[1]) * it->cut[4] + (c[2] - it->cut[2]) * it->cut[5];
          if (side > 0) continue;
        }
        float colour[3];
        scalar_colour(it, scalar, nscalar, i, colour);
        add_sphere(r, sp[i].c, sp[i].r, colour);
      }
      break;
    }
    case TX_DRAW_SEGMENTS: {
      const tx_segment* sg = si->data[0];
      const float* scalar = *it->scalar ? si->data[1] : NULL;
      uint32_t nscalar = *it->scalar ? si->rows[1] : 0;
      for (uint32_t i = 0; i < si->rows[0]; i++) {
        if (sg[i].r == 0) continue; // a gap on purpose (a cut thread's severed link), not a bad row
        if (!finite_n(sg[i].a, 3) || !finite_n(sg[i].b, 3) || !isfinite(sg[i].r) || !(sg[i].r > 0)) {
          r->skipped++;
          continue;
        }
        float colour[3];
        scalar_colour(it, scalar, nscalar, i, colour);
        add_cylinder(r, sg[i].a, sg[i].b, sg[i].r, colour);
      }
      break;
    }
    case TX_DRAW_INSTRUMENT: {
      if (r->instrument_of[k] != it) { // a new view: its meshes (checked when the view was configured)
        tx_instrument_mesh_free(r->instruments[k]);
        r->instruments[k] = tx_instrument_mesh_load(it->urdf);
        r->instrument_of[k] = it;
      }
      const float* x;
      const int32_t* tri;
      uint32_t nv, nt;
      const tx_instrument_held* held = si->data[1];
      if (!si->rows[0] || !si->rows[1]) break; // not published yet
      if (!r->instruments[k] || !tx_instrument_mesh_place(r->instruments[k], held->index, si->data[0], si->rows[0], &x, &nv, &tri, &nt)) {
        r->skipped++;
        break;
      }
      mesh_slot* m = slot(r);
      fill_mesh(r, m, x, nv, tri, nt);
      memcpy(m->colour, it->colour, sizeof m->colour);
      m->textured = false;
      upload_mesh(r, m);
      break;
    }
    case TX_DRAW_MARKERS: {
      // each puncture on the triangle it pierced, where the skin is now; rows
      // past the list's end (v[0] = -1) are no punctures, not bad rows
      int dk = 0; // the components, in tx_draw_item_components order
      const tx_puncture* pu = *it->name ? si->data[dk] : NULL;
      uint32_t npu = *it->name ? si->rows[dk] : 0;
      const float* x = *it->name ? si->data[dk + 1] : NULL;
      uint32_t nx = *it->name ? si->rows[dk + 1] : 0;
      if (*it->name) dk += 2;
      const tx_sphere* th = *it->thread ? si->data[dk] : NULL;
      uint32_t nth = *it->thread ? si->rows[dk] : 0;
      // grasps green, knots orange, the size of the punctures' markers
      const float green[3] = {0.2f, 0.85f, 0.3f}, orange[3] = {1.0f, 0.55f, 0.1f};
      const tx_marker_list* ml = s->markers[k];
      for (uint32_t i = 0; ml && i < ml->n; i++) {
        const tx_marker* m = &ml->m[i];
        if (m->kind == TX_EVENT_GRASP) {
          add_sphere(r, m->p, it->radius, green);
          continue;
        }
        // the knot's cylinders first..last join nodes first..last + 1
        if (!th || m->last + 1 >= nth) { // no thread to place it on, or nodes past it
          r->skipped++;
          continue;
        }
        float c[3] = {0, 0, 0}, w = 1.0f / (float)(m->last - m->first + 2);
        for (uint32_t j = m->first; j <= m->last + 1; j++)
          for (int e = 0; e < 3; e++) c[e] += w * th[j].c[e];
        if (finite_n(c, 3)) add_sphere(r, c, it->radius, orange);
        else r->skipped++;
      }
      for (uint32_t i = 0; i < npu; i++) {
        if (pu[i].v[0] == -1) continue;
        float c[3] = {0, 0, 0};
        bool ok = true;
        for (int j = 0; j < 3 && ok; j++) {
          double v = pu[i].v[j], b = pu[i].bary[j];
          ok = v >= 0 && v < (double)nx && v == floor(v) && isfinite(b);
          for (int e = 0; e < 3 && ok; e++) c[e] += (float)b * x[3 * (uint32_t)v + e];
        }
        if (!ok || !finite_n(c, 3)) {
          r->skipped++;
          continue;
        }
        add_sphere(r, c, it->radius, it->colour);
      }
      break;
    }
    case TX_DRAW_TOOL: {
      const tx_pose* pose = si->data[0];
      if (!si->rows[0]) break;
      bool ok = true;
      for (int c = 0; c < 3; c++) ok = ok && isfinite(pose->pos[c]);
      for (int c = 0; c < 4; c++) ok = ok && isfinite(pose->quat[c]);
      const double* pq = pose->quat;
      double qn = sqrt(pq[0] * pq[0] + pq[1] * pq[1] + pq[2] * pq[2] + pq[3] * pq[3]);
      if (!ok || !(qn > 1e-9)) {
        r->skipped++;
        break;
      }
      double q[4] = {pq[0] / qn, pq[1] / qn, pq[2] / qn, pq[3] / qn};
      float p[3] = {(float)pose->pos[0], (float)pose->pos[1], (float)pose->pos[2]};
      add_sphere(r, p, it->radius, it->colour);
      // the instrument's shaft leaves the HIP along the tool's own +Y axis
      const float axis[3] = {0, 16 * it->radius, 0}, grey[3] = {0.7f, 0.72f, 0.75f};
      float a[3], tip[3];
      rotate(q, axis, a);
      for (int c = 0; c < 3; c++) tip[c] = p[c] + a[c];
      add_cylinder(r, p, tip, 0.35f * it->radius, grey);
      if (it->show_force && si->rows[1]) {
        const tx_force* f = si->data[1];
        float start[3], end[3];
        const float yellow[3] = {0.95f, 0.85f, 0.1f};
        tx_force_arrow_start(p, a, it->radius, f->f, start);
        for (int c = 0; c < 3; c++) end[c] = start[c] + (float)f->f[c] * it->force_scale;
        if (finite_n(start, 3) && finite_n(end, 3)) add_cylinder(r, start, end, 0.45f * it->radius, yellow);
      }
      int pk = it->show_force ? 2 : 1; // the proxy's force model, after the pose and the force
      if (*it->proxy && si->rows[pk]) {
        const tx_force_model* fm = si->data[pk];
        bool contact = false; // a force model of zeros is no contact: nothing holds the tool
        for (int c = 0; c < 3; c++) contact = contact || fm->f0[c] != 0;
        for (int c = 0; c < 9; c++) contact = contact || fm->k[c] != 0;
        // where the local model's force vanishes along F0 (x0 + s F0/|F0|, F0 + s K u = 0 along u):
        // on the surface, for a wall's spring; x0 itself where the model does not fall off that way
        double f = sqrt(fm->f0[0] * fm->f0[0] + fm->f0[1] * fm->f0[1] + fm->f0[2] * fm->f0[2]), along = 0, u[3] = {0};
        if (f > 0) {
          double uku = 0;
          for (int c = 0; c < 3; c++) u[c] = fm->f0[c] / f;
          for (int c = 0; c < 3; c++)
            for (int e = 0; e < 3; e++) uku += u[c] * fm->k[3 * c + e] * u[e];
          if (uku < 0) along = -f / uku;
        }
        float x0[3];
        for (int c = 0; c < 3; c++) x0[c] = (float)(fm->x0[c] + along * u[c]);
        const float cyan[3] = {0.1f, 0.85f, 0.9f};
        if (contact && finite_n(x0, 3)) {
          add_sphere(r, x0, 0.7f * it->radius, cyan);
          add_cylinder(r, p, x0, 0.2f * it->radius, cyan); // from the device to where the surface holds it
        }
      }
      break;
    }
    }
  }
  tx_gl* gl = &r->gl;
  // instance buffers keep their size and grow by doubling
  if (r->nspheres) {
    gl->BindBuffer(GL_ARRAY_BUFFER, r->sphere_inst);
    if (r->nspheres > r->sphere_gpu_cap) {
      r->sphere_gpu_cap = r->sphere_cap;
      gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(r->sphere_gpu_cap * 7 * sizeof(float)), NULL, GL_STREAM_DRAW);
    }
    gl->BufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)(r->nspheres * 7 * sizeof(float)), r->spheres);
  }
  if (r->ncyls) {
    gl->BindBuffer(GL_ARRAY_BUFFER, r->cyl_inst);
    if (r->ncyls > r->cyl_gpu_cap) {
      r->cyl_gpu_cap = r->cyl_cap;
      gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(r->cyl_gpu_cap * 10 * sizeof(float)), NULL, GL_STREAM_DRAW);
    }
    gl->BufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)(r->ncyls * 10 * sizeof(float)), r->cyls);
  }
}

bool tx_renderer_bounds(const tx_renderer* r, double lo[3], double hi[3]) {
  if (!r->any) return false;
  memcpy(lo, r->lo, sizeof r->lo);
  memcpy(hi, r->hi, sizeof r->hi);
  return true;
}

static void common_uniforms(tx_renderer* r, GLuint prog, const tx_view_def* d, const float view[16], const float proj[16],
                            const double eye[3]) {
  tx_gl* gl = &r->gl;
  gl->UseProgram(prog);
  gl->UniformMatrix4fv(gl->GetUniformLocation(prog, "u_proj"), 1, GL_FALSE, proj);
  gl->UniformMatrix4fv(gl->GetUniformLocation(prog, "u_view"), 1, GL_FALSE, view);
  gl->Uniform3fv(gl->GetUniformLocation(prog, "u_light"), 1, d->light_dir);
  // view matrix rows: the third is the camera's backward axis, towards the viewer
  float back[3] = {view[2], view[6], view[10]}, half[3];
  float hl = 0;
  for (int i = 0; i < 3; i++) half[i] = back[i] - d->light_dir[i], hl += half[i] * half[i];
  hl = hl > 0 ? sqrtf(hl) : 1;
  for (int i = 0; i < 3; i++) half[i] /= hl;
  gl->Uniform3fv(gl->GetUniformLocation(prog, "u_view_dir"), 1, back);
  gl->Uniform3fv(gl->GetUniformLocation(prog, "u_half"), 1, half);
  (void)eye;
  const float lighting[4] = {TX_LIGHT_AMBIENT, TX_LIGHT_DIFFUSE, TX_LIGHT_SPECULAR, TX_LIGHT_SHININESS};
  gl->Uniform4fv(gl->GetUniformLocation(prog, "u_lighting"), 1, lighting);
  gl->Uniform1i(gl->GetUniformLocation(prog, "u_textured"), 0);
  gl->Uniform1i(gl->GetUniformLocation(prog, "u_tex"), 0);
}

void tx_renderer_draw(tx_renderer* r, const tx_view_def* d, const tx_camera* c, tx_eye eye, int x, int y, int w, int h,
                      unsigned clear) {
  tx_gl* gl = &r->gl;
  float view[16], proj[16];
  tx_camera_matrices(c, eye, (double)w / (double)h, view, proj);
  double e[3];
  tx_camera_eye_position(c, eye, e);
  gl->Viewport(x, y, w, h);
  if (clear) {
    gl->ClearColor(d->background[0], d->background[1], d->background[2], 1);
    gl->Clear(clear);
  }
  gl->Enable(GL_DEPTH_TEST);

  common_uniforms(r, r->mesh_prog, d, view, proj, e);
  gl->ActiveTexture(GL_TEXTURE0);
  gl->BindTexture(GL_TEXTURE_2D, r->skin_tex);
  GLint colour_at = gl->GetUniformLocation(r->mesh_prog, "u_colour"),
        textured_at = gl->GetUniformLocation(r->mesh_prog, "u_textured");
  for (int i = 0; i < r->nmeshes; i++) {
    mesh_slot* m = &r->meshes[i];
    if (!m->nidx) continue;
    gl->Uniform3fv(colour_at, 1, m->colour);
    gl->Uniform1i(textured_at, m->textured == 3 ? 1 : m->textured); // the map is drawn as a texture
    gl->BindTexture(GL_TEXTURE_2D, m->textured == 3 ? r->cmap_tex : m->textured == 2 ? r->tissue_tex : r->skin_tex);
    gl->BindVertexArray(m->vao);
    gl->DrawElements(GL_TRIANGLES, (GLsizei)m->nidx, GL_UNSIGNED_INT, 0);
  }
  if (r->nspheres) {
    common_uniforms(r, r->sphere_prog, d, view, proj, e);
    gl->BindVertexArray(r->sphere_vao);
    gl->DrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)r->nspheres);
  }
  if (r->ncyls) {
    common_uniforms(r, r->cyl_prog, d, view, proj, e);
    gl->BindVertexArray(r->cyl_vao);
    gl->DrawArraysInstanced(GL_TRIANGLES, 0, r->cyl_nverts, (GLsizei)r->ncyls);
  }
  gl->BindVertexArray(0);
}
