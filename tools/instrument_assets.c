// tactus-instrument-assets: writes the six instrument descriptions
// (OUTDIR/<name>.urdf) and their visual meshes (OUTDIR/meshes/<name>_<link>.obj)
// from one table of dimensions, so that the collision primitives, the
// inertias and the meshes cannot disagree. assets/instruments/README.md gives
// the dimensions and their sources.
//
//   tactus-instrument-assets OUTDIR
//
// Frames: x runs along the instrument to its tip, z is the direction the
// upper jaw opens to, y = z cross x. A jaw link's frame is at its pivot; its
// joint angle is 0 with the jaws closed and grows as they open. Lengths in m,
// masses in kg (stainless steel, solid), inertias in kg m^2 about the link's
// centre of mass. Bad input: one line on stderr and exit status 2; every file
// is written aside and renamed when whole.
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define STEEL_DENSITY 7900.0 // kg/m^3, AISI 304/420 instrument steel
#define MAX_PARTS 6
#define MAX_LINKS 3
#define SEGMENTS 24 // around a cylinder or a ring
#define RING_SEGMENTS 10 // around a ring's wire

typedef enum { PART_TAPER, PART_CYLINDER, PART_RING } part_kind;

// One solid piece of a link. A taper is a box whose y-z section (w, h) and
// centre (cy, cz) change linearly from x0 to x1 (a box when both ends are
// equal); its collision shape is the box of the mean section. A cylinder has
// its axis along x, y or z (axis 0, 1, 2), radius r, from s0 to s1 along the
// axis, centred at c on the others. A ring (a finger ring) lies in the x-z
// plane: centre c, radius r to its wire, wire radius w; it has mass and a
// mesh but no collision shape (it stays in the hand, out of the field).
typedef struct {
  const char* name;
  part_kind kind;
  double x0, x1, w0, h0, cy0, cz0, w1, h1, cy1, cz1; // taper
  int axis;
  double r, s0, s1, c[3]; // cylinder; ring uses r, w, c
  double w;
} part;

typedef struct {
  const char* name;
  double axis[3]; // opening direction, in the parent's frame
  double pivot[3]; // in the root frame
  double lower, upper, effort, velocity; // rad, rad, N m, rad/s
} jaw_joint;

typedef struct {
  const char* name;
  part parts[MAX_PARTS];
  int nparts;
  jaw_joint joint; // unused for the root (link 0)
} link_desc;

typedef struct {
  const char* name;
  const char* title;
  link_desc links[MAX_LINKS];
  int nlinks;
} instrument;

static part taper(const char* name, double x0, double x1, double w0, double h0, double cz0, double w1, double h1,
                  double cz1, double cy) {
  return (part){.name = name, .kind = PART_TAPER, .x0 = x0, .x1 = x1, .w0 = w0, .h0 = h0, .cy0 = cy, .cz0 = cz0,
                .w1 = w1, .h1 = h1, .cy1 = cy, .cz1 = cz1};
}
static part cylinder(const char* name, int axis, double r, double s0, double s1, double c0, double c1, double c2) {
  return (part){.name = name, .kind = PART_CYLINDER, .axis = axis, .r = r, .s0 = s0, .s1 = s1, .c = {c0, c1, c2}};
}
static part ring(const char* name, double cx, double cz, double r, double w) {
  return (part){.name = name, .kind = PART_RING, .r = r, .w = w, .c = {cx, 0, cz}};
}

// ---- the instruments (README.md, "Dimensions", gives each number's source)

// Open instruments (Kelly, Metzenbaum): a root at the pivot (box lock or
// screw) and two halves, each a jaw or blade ahead of the pivot and a shank
// and finger ring behind it on the other side.
static void open_halves(instrument* in, double jaw_len, double jaw_w0, double jaw_h0, double jaw_w1, double jaw_h1,
                        bool shear, double shank_len, double shank_w, double shank_h, double ring_r, double ring_w,
                        double ring_dz, double open, double effort, double velocity) {
  for (int side = 0; side < 2; side++) {
    double s = side == 0 ? 1.0 : -1.0; // upper half: jaw at +z, shank and ring at -z
    link_desc* l = &in->links[1 + side];
    l->name = side == 0 ? "jaw_upper" : "jaw_lower";
    // jaws of a clamp meet at z = 0; scissor blades pass each other side by side in y
    double cy = shear ? s * jaw_w0 / 2 : 0.0;
    double cz0 = shear ? 0.0 : s * jaw_h0 / 2, cz1 = shear ? 0.0 : s * jaw_h1 / 2;
    l->parts[0] = taper(side == 0 ? "jaw_upper" : "jaw_lower", 0.004, jaw_len, jaw_w0, jaw_h0, cz0, jaw_w1, jaw_h1,
                        cz1, cy);
    double zs = -s * (shank_h / 2 + 0.0015);
    l->parts[1] = taper("shank", -shank_len, -0.004, shank_w, shank_h, zs, shank_w, shank_h, zs, cy);
    l->parts[2] = ring("ring", -shank_len - ring_r, -s * ring_dz, ring_r, ring_w);
    l->nparts = 3;
    l->joint = (jaw_joint){.name = side == 0 ? "jaw_upper_joint" : "jaw_lower_joint",
                           .axis = {0, -s, 0},
                           .lower = 0,
                           .upper = open,
                           .effort = effort,
                           .velocity = velocity};
  }
  in->nlinks = 3;
}

// Laparoscopic instruments: a 5 mm shaft whose far end is the pivot (the root
// frame), and two jaws or blades on it.
static void lap_shaft(link_desc* root, double shaft_len) {
  root->name = "root";
  root->parts[0] = cylinder("shaft", 0, 0.0025, -shaft_len, 0.0, 0, 0, 0);
  root->nparts = 1;
}
static void lap_jaws(instrument* in, double len, double w0, double h0, double w1, double h1, bool shear, double open,
                     double effort, double velocity) {
  for (int side = 0; side < 2; side++) {
    double s = side == 0 ? 1.0 : -1.0;
    link_desc* l = &in->links[1 + side];
    l->name = side == 0 ? "jaw_upper" : "jaw_lower";
    double cy = shear ? s * w0 / 2 : 0.0;
    double cz0 = shear ? 0.0 : s * h0 / 2, cz1 = shear ? 0.0 : s * h1 / 2;
    l->parts[0] = taper(l->name, 0.0, len, w0, h0, cz0, w1, h1, cz1, cy);
    l->nparts = 1;
    l->joint = (jaw_joint){.name = side == 0 ? "jaw_upper_joint" : "jaw_lower_joint",
                           .axis = {0, -s, 0},
                           .lower = 0,
                           .upper = open,
                           .effort = effort,
                           .velocity = velocity};
  }
  in->nlinks = 3;
}

static int build_instruments(instrument* out) {
  int n = 0;
  instrument* in;

  // blunt-nosed thumb (dissecting) forceps, 13 cm: two blades sprung from a heel
  in = &out[n++];
  *in = (instrument){.name = "thumb_forceps", .title = "blunt-nosed thumb forceps, 13 cm"};
  in->links[0] = (link_desc){.name = "root", .nparts = 1};
  in->links[0].parts[0] = taper("heel", 0.0, 0.012, 0.009, 0.003, 0.0, 0.009, 0.003, 0.0, 0.0);
  for (int side = 0; side < 2; side++) {
    double s = side == 0 ? 1.0 : -1.0;
    link_desc* l = &in->links[1 + side];
    l->name = side == 0 ? "jaw_upper" : "jaw_lower";
    l->parts[0] = taper(l->name, 0.0, 0.118, 0.009, 0.0015, s * 0.00075, 0.0025, 0.0012, s * 0.0006, 0.0);
    l->nparts = 1;
    l->joint = (jaw_joint){.name = side == 0 ? "jaw_upper_joint" : "jaw_lower_joint",
                           .axis = {0, -s, 0},
                           .pivot = {0.012, 0, 0},
                           .lower = 0,
                           .upper = 0.07,
                           .effort = 0.3,
                           .velocity = 2};
  }
  in->nlinks = 3;

  // needle holder: Kelly forceps, straight, 14 cm
  in = &out[n++];
  *in = (instrument){.name = "needle_holder", .title = "needle holder (Kelly forceps, straight), 14 cm"};
  in->links[0] = (link_desc){.name = "root", .nparts = 1};
  in->links[0].parts[0] = cylinder("box_lock", 1, 0.004, -0.003, 0.003, 0, 0, 0);
  open_halves(in, 0.035, 0.005, 0.003, 0.002, 0.0015, false, 0.085, 0.004, 0.003, 0.009, 0.0018, 0.011, 0.26, 0.5, 4);

  // Metzenbaum scissors, straight, 14 cm
  in = &out[n++];
  *in = (instrument){.name = "metzenbaum_scissors", .title = "Metzenbaum scissors, straight, 14 cm"};
  in->links[0] = (link_desc){.name = "root", .nparts = 1};
  in->links[0].parts[0] = cylinder("screw", 1, 0.003, -0.002, 0.002, 0, 0, 0);
  open_halves(in, 0.040, 0.0018, 0.006, 0.0018, 0.0015, true, 0.081, 0.0018, 0.0035, 0.0085, 0.0018, 0.011, 0.4,
              0.5, 6);

  // laparoscopic grasper: 5 mm x 31 cm shaft, 20 mm jaws opening to a 20 mm span
  in = &out[n++];
  *in = (instrument){.name = "lap_grasper", .title = "laparoscopic grasper, 5 mm x 31 cm shaft"};
  lap_shaft(&in->links[0], 0.310);
  lap_jaws(in, 0.020, 0.005, 0.0025, 0.003, 0.0015, false, 0.52, 0.2, 6);

  // laparoscopic (Metzenbaum-type) scissors: 5 mm x 31 cm shaft, 16 mm blades
  in = &out[n++];
  *in = (instrument){.name = "lap_scissors", .title = "laparoscopic scissors, 5 mm x 31 cm shaft"};
  lap_shaft(&in->links[0], 0.310);
  lap_jaws(in, 0.016, 0.0022, 0.004, 0.0022, 0.001, true, 0.44, 0.1, 6);

  // monopolar L-hook cautery: 5 mm x 31 cm shaft, a 4.5 mm hook; one rigid body
  in = &out[n++];
  *in = (instrument){.name = "hook_cautery", .title = "L-hook cautery electrode, 5 mm x 31 cm shaft"};
  in->links[0] = (link_desc){.name = "root", .nparts = 3};
  in->links[0].parts[0] = cylinder("shaft", 0, 0.0025, -0.310, 0.0, 0, 0, 0);
  in->links[0].parts[1] = cylinder("electrode", 0, 0.0006, 0.0, 0.010, 0, 0, 0);
  in->links[0].parts[2] = cylinder("hook", 2, 0.0006, 0.0, 0.0045, 0.0094, 0, 0);
  in->nlinks = 1;
  return n;
}

// ---- mass properties, about the link frame, then moved to the centre of mass

typedef struct {
  double m, com[3], I[3][3]; // I about com, link axes
} mass_props;

static mass_props part_mass(const part* p) {
  mass_props mp = {0};
  double ix = 0, iy = 0, iz = 0; // principal, about the part's own centre, link axes
  switch (p->kind) {
    case PART_TAPER: {
      double L = p->x1 - p->x0, w = (p->w0 + p->w1) / 2, h = (p->h0 + p->h1) / 2;
      mp.m = STEEL_DENSITY * L * w * h;
      mp.com[0] = (p->x0 + p->x1) / 2, mp.com[1] = (p->cy0 + p->cy1) / 2, mp.com[2] = (p->cz0 + p->cz1) / 2;
      ix = mp.m * (w * w + h * h) / 12, iy = mp.m * (L * L + h * h) / 12, iz = mp.m * (L * L + w * w) / 12;
      break;
    }
    case PART_CYLINDER: {
      double L = p->s1 - p->s0, r = p->r;
      mp.m = STEEL_DENSITY * M_PI * r * r * L;
      for (int k = 0; k < 3; k++) mp.com[k] = p->c[k];
      mp.com[p->axis] = (p->s0 + p->s1) / 2;
      double ia = mp.m * r * r / 2, ip = mp.m * (3 * r * r + L * L) / 12;
      ix = p->axis == 0 ? ia : ip, iy = p->axis == 1 ? ia : ip, iz = p->axis == 2 ? ia : ip;
      break;
    }
    case PART_RING: { // a torus about the y axis
      double R = p->r, a = p->w;
      mp.m = STEEL_DENSITY * 2 * M_PI * M_PI * R * a * a;
      for (int k = 0; k < 3; k++) mp.com[k] = p->c[k];
      iy = mp.m * (R * R + 0.75 * a * a);
      ix = iz = mp.m * (0.5 * R * R + 0.625 * a * a);
      break;
    }
  }
  mp.I[0][0] = ix, mp.I[1][1] = iy, mp.I[2][2] = iz;
  return mp;
}

static mass_props link_mass(const link_desc* l) {
  mass_props sum = {0};
  for (int i = 0; i < l->nparts; i++) {
    mass_props p = part_mass(&l->parts[i]);
    sum.m += p.m;
    for (int k = 0; k < 3; k++) sum.com[k] += p.m * p.com[k];
  }
  for (int k = 0; k < 3; k++) sum.com[k] /= sum.m;
  for (int i = 0; i < l->nparts; i++) { // parallel axes: I + m (|d|^2 E - d d^T)
    mass_props p = part_mass(&l->parts[i]);
    double d[3] = {p.com[0] - sum.com[0], p.com[1] - sum.com[1], p.com[2] - sum.com[2]};
    double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++) sum.I[a][b] += p.I[a][b] + p.m * ((a == b ? dd : 0.0) - d[a] * d[b]);
  }
  return sum;
}

// ---- meshes

typedef struct {
  double v[8192][3];
  int f[16384][3];
  int nv, nf;
} mesh;

static int vert(mesh* m, double x, double y, double z) {
  m->v[m->nv][0] = x, m->v[m->nv][1] = y, m->v[m->nv][2] = z;
  return m->nv++;
}
static void tri(mesh* m, int a, int b, int c) {
  m->f[m->nf][0] = a, m->f[m->nf][1] = b, m->f[m->nf][2] = c;
  m->nf++;
}
static void quad(mesh* m, int a, int b, int c, int d) { // counter-clockwise seen from outside
  tri(m, a, b, c);
  tri(m, a, c, d);
}

static void mesh_taper(mesh* m, const part* p) {
  int v[8];
  for (int e = 0; e < 2; e++) {
    double x = e ? p->x1 : p->x0, w = e ? p->w1 : p->w0, h = e ? p->h1 : p->h0;
    double cy = e ? p->cy1 : p->cy0, cz = e ? p->cz1 : p->cz0;
    v[4 * e + 0] = vert(m, x, cy - w / 2, cz - h / 2);
    v[4 * e + 1] = vert(m, x, cy + w / 2, cz - h / 2);
    v[4 * e + 2] = vert(m, x, cy + w / 2, cz + h / 2);
    v[4 * e + 3] = vert(m, x, cy - w / 2, cz + h / 2);
  }
  quad(m, v[0], v[3], v[2], v[1]); // -x end
  quad(m, v[4], v[5], v[6], v[7]); // +x end
  for (int k = 0; k < 4; k++) {
    int k1 = (k + 1) % 4;
    quad(m, v[k], v[k1], v[4 + k1], v[4 + k]);
  }
}

// point at angle t around the axis, at distance r, axial coordinate s
static void around(int axis, const double c[3], double r, double t, double s, double out[3]) {
  int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  out[axis] = s;
  out[a1] = c[a1] + r * cos(t);
  out[a2] = c[a2] + r * sin(t);
}

static void mesh_cylinder(mesh* m, const part* p) {
  int base = m->nv;
  double q[3];
  for (int e = 0; e < 2; e++)
    for (int i = 0; i < SEGMENTS; i++) {
      around(p->axis, p->c, p->r, 2 * M_PI * i / SEGMENTS, e ? p->s1 : p->s0, q);
      vert(m, q[0], q[1], q[2]);
    }
  around(p->axis, p->c, 0, 0, p->s0, q);
  int c0 = vert(m, q[0], q[1], q[2]);
  around(p->axis, p->c, 0, 0, p->s1, q);
  int c1 = vert(m, q[0], q[1], q[2]);
  for (int i = 0; i < SEGMENTS; i++) {
    int i1 = (i + 1) % SEGMENTS;
    quad(m, base + i, base + i1, base + SEGMENTS + i1, base + SEGMENTS + i);
    tri(m, c0, base + i1, base + i);
    tri(m, c1, base + SEGMENTS + i, base + SEGMENTS + i1);
  }
}

static void mesh_ring(mesh* m, const part* p) {
  int base = m->nv;
  for (int i = 0; i < SEGMENTS; i++) {
    double t = 2 * M_PI * i / SEGMENTS;
    for (int j = 0; j < RING_SEGMENTS; j++) {
      double u = 2 * M_PI * j / RING_SEGMENTS, rr = p->r + p->w * cos(u);
      vert(m, p->c[0] + rr * cos(t), p->w * sin(u), p->c[2] + rr * sin(t));
    }
  }
  for (int i = 0; i < SEGMENTS; i++)
    for (int j = 0; j < RING_SEGMENTS; j++) {
      int i1 = (i + 1) % SEGMENTS, j1 = (j + 1) % RING_SEGMENTS;
      quad(m, base + i * RING_SEGMENTS + j, base + i * RING_SEGMENTS + j1, base + i1 * RING_SEGMENTS + j1,
           base + i1 * RING_SEGMENTS + j);
    }
}

// ---- output

static const char* g_outdir;

static int bad(const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  fprintf(stderr, "tactus-instrument-assets: ");
  vfprintf(stderr, fmt, ap);
  fprintf(stderr, "\n");
  va_end(ap);
  return 2;
}

// "-0" and "0" read the same; print one of them so that the files do not
// depend on which side of zero a rounding landed
static const char* num(char* buf, double v) {
  snprintf(buf, 32, "%.6g", v);
  if (strcmp(buf, "-0") == 0) strcpy(buf, "0");
  return buf;
}

static bool finish(FILE* f, const char* tmp, const char* path) {
  bool ok = !ferror(f);
  ok = (fclose(f) == 0) && ok;
  if (ok && rename(tmp, path) != 0) ok = false;
  if (!ok) {
    remove(tmp);
    bad("%s: cannot write: %s", path, strerror(errno ? errno : EIO));
  }
  return ok;
}

static bool write_mesh(const instrument* in, const link_desc* l, mesh* m) {
  m->nv = m->nf = 0;
  for (int i = 0; i < l->nparts; i++) {
    const part* p = &l->parts[i];
    if (p->kind == PART_TAPER) mesh_taper(m, p);
    if (p->kind == PART_CYLINDER) mesh_cylinder(m, p);
    if (p->kind == PART_RING) mesh_ring(m, p);
  }
  char path[4096], tmp[4200];
  snprintf(path, sizeof path, "%s/meshes/%s_%s.obj", g_outdir, in->name, l->name);
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  FILE* f = fopen(tmp, "w");
  if (!f) return bad("%s: cannot write: %s", path, strerror(errno)), false;
  fprintf(f, "# %s, link %s: written by tools/instrument_assets.c; do not edit\n", in->title, l->name);
  fprintf(f, "# metres, link frame (assets/instruments/README.md)\no %s\n", l->name);
  char a[32], b[32], c[32];
  for (int i = 0; i < m->nv; i++) fprintf(f, "v %s %s %s\n", num(a, m->v[i][0]), num(b, m->v[i][1]), num(c, m->v[i][2]));
  for (int i = 0; i < m->nf; i++) fprintf(f, "f %d %d %d\n", m->f[i][0] + 1, m->f[i][1] + 1, m->f[i][2] + 1);
  return finish(f, tmp, path);
}

static void write_collision(FILE* f, const part* p) {
  char a[32], b[32], c[32], d[32], e[32], g[32];
  if (p->kind == PART_TAPER) {
    fprintf(f, "    <collision name=\"%s\">\n      <origin xyz=\"%s %s %s\" rpy=\"0 0 0\"/>\n", p->name,
            num(a, (p->x0 + p->x1) / 2), num(b, (p->cy0 + p->cy1) / 2), num(c, (p->cz0 + p->cz1) / 2));
    fprintf(f, "      <geometry><box size=\"%s %s %s\"/></geometry>\n    </collision>\n", num(d, p->x1 - p->x0),
            num(e, (p->w0 + p->w1) / 2), num(g, (p->h0 + p->h1) / 2));
  } else if (p->kind == PART_CYLINDER) {
    double o[3] = {p->c[0], p->c[1], p->c[2]};
    o[p->axis] = (p->s0 + p->s1) / 2;
    // a URDF cylinder's axis is its frame's z: turn z onto x or y
    const char* rpy = p->axis == 0 ? "0 1.5707963267949 0" : p->axis == 1 ? "1.5707963267949 0 0" : "0 0 0";
    fprintf(f, "    <collision name=\"%s\">\n      <origin xyz=\"%s %s %s\" rpy=\"%s\"/>\n", p->name, num(a, o[0]),
            num(b, o[1]), num(c, o[2]), rpy);
    fprintf(f, "      <geometry><cylinder radius=\"%s\" length=\"%s\"/></geometry>\n    </collision>\n", num(d, p->r),
            num(e, p->s1 - p->s0));
  }
}

static bool write_urdf(const instrument* in, mesh* m) {
  char path[4096], tmp[4200];
  snprintf(path, sizeof path, "%s/%s.urdf", g_outdir, in->name);
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  FILE* f = fopen(tmp, "w");
  if (!f) return bad("%s: cannot write: %s", path, strerror(errno)), false;
  char a[32], b[32], c[32], d[32], e[32], g[32];
  fprintf(f, "<?xml version=\"1.0\"?>\n<!-- %s: written by tools/instrument_assets.c; do not edit.\n", in->title);
  fprintf(f, "     Dimensions and sources: README.md. x to the tip, jaws open towards +z and -z,\n"
             "     jaw angle 0 = closed. SI units; solid stainless steel (%g kg/m^3). -->\n",
          STEEL_DENSITY);
  fprintf(f, "<robot name=\"%s\">\n  <material name=\"steel\"><color rgba=\"0.72 0.74 0.77 1\"/></material>\n",
          in->name);
  for (int li = 0; li < in->nlinks; li++) {
    const link_desc* l = &in->links[li];
    mass_props mp = link_mass(l);
    fprintf(f, "  <link name=\"%s\">\n    <inertial>\n      <origin xyz=\"%s %s %s\" rpy=\"0 0 0\"/>\n", l->name,
            num(a, mp.com[0]), num(b, mp.com[1]), num(c, mp.com[2]));
    fprintf(f, "      <mass value=\"%s\"/>\n", num(a, mp.m));
    fprintf(f, "      <inertia ixx=\"%s\" ixy=\"%s\" ixz=\"%s\" iyy=\"%s\" iyz=\"%s\" izz=\"%s\"/>\n    </inertial>\n",
            num(a, mp.I[0][0]), num(b, mp.I[0][1]), num(c, mp.I[0][2]), num(d, mp.I[1][1]), num(e, mp.I[1][2]),
            num(g, mp.I[2][2]));
    fprintf(f, "    <visual>\n      <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n"
               "      <geometry><mesh filename=\"meshes/%s_%s.obj\"/></geometry>\n"
               "      <material name=\"steel\"/>\n    </visual>\n",
            in->name, l->name);
    for (int i = 0; i < l->nparts; i++) write_collision(f, &l->parts[i]);
    fprintf(f, "  </link>\n");
    if (!write_mesh(in, l, m)) {
      fclose(f);
      remove(tmp);
      return false;
    }
  }
  for (int li = 1; li < in->nlinks; li++) {
    const jaw_joint* j = &in->links[li].joint;
    fprintf(f, "  <joint name=\"%s\" type=\"revolute\">\n    <parent link=\"%s\"/>\n    <child link=\"%s\"/>\n",
            j->name, in->links[0].name, in->links[li].name);
    fprintf(f, "    <origin xyz=\"%s %s %s\" rpy=\"0 0 0\"/>\n", num(a, j->pivot[0]), num(b, j->pivot[1]),
            num(c, j->pivot[2]));
    fprintf(f, "    <axis xyz=\"%s %s %s\"/>\n", num(a, j->axis[0]), num(b, j->axis[1]), num(c, j->axis[2]));
    fprintf(f, "    <limit lower=\"%s\" upper=\"%s\" effort=\"%s\" velocity=\"%s\"/>\n  </joint>\n", num(a, j->lower),
            num(b, j->upper), num(d, j->effort), num(e, j->velocity));
  }
  fprintf(f, "</robot>\n");
  return finish(f, tmp, path);
}

int main(int argc, char** argv) {
  if (argc >= 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
    printf("usage: tactus-instrument-assets OUTDIR\n"
           "writes OUTDIR/<instrument>.urdf and OUTDIR/meshes/<instrument>_<link>.obj\n");
    return 0;
  }
  if (argc != 2 || argv[1][0] == '-' || !argv[1][0])
    return bad("expected one argument, the output folder (--help)");
  g_outdir = argv[1];
  struct stat st;
  if (stat(g_outdir, &st) != 0 || !S_ISDIR(st.st_mode)) return bad("%s: not a folder", g_outdir);
  char meshes[4200];
  snprintf(meshes, sizeof meshes, "%s/meshes", g_outdir);
  if (mkdir(meshes, 0777) != 0 && errno != EEXIST) return bad("%s: cannot create: %s", meshes, strerror(errno));
  static instrument ins[8];
  static mesh m;
  int n = build_instruments(ins);
  for (int i = 0; i < n; i++)
    if (!write_urdf(&ins[i], &m)) return 2;
  for (int i = 0; i < n; i++) {
    double total = 0;
    for (int li = 0; li < ins[i].nlinks; li++) total += link_mass(&ins[i].links[li]).m;
    printf("%s: %d links, %.1f g\n", ins[i].name, ins[i].nlinks, total * 1000);
  }
  return 0;
}
