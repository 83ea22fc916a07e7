// tactus-band-assets: the gastric band of the LAGB paper (section 2.3) as two
// tetrahedral meshes, swept along their centre lines: the thick ring part, a
// C-shaped arc in the x-y plane (its curved rest shape; the band's width
// along z) with the buckle at its head, and the long tube part, straight off
// the ring's tail, a small gap apart (the distance joint spans it).
//
//   tactus-band-assets OUTDIR [key=value ...]      (keys: README, --help)
//
// Writes OUTDIR/band_ring.node/.ele and band_tube.node/.ele (TetGen 1.5,
// numbered from 0; each node's boundary marker: 1 on the part's first
// cross-section, 2 on its last, 0 elsewhere), each file written aside and
// renamed when whole; bad input: one line naming the key, status 2, nothing
// written. Each hexahedral cell of the sweep is split into Kuhn's six
// tetrahedra, which match across shared faces, all of TetGen's orientation.
#include "tools/lagb/mesh.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

typedef struct band_dims {
  double ring_length, ring_arc_deg, ring_width, ring_thickness;
  int ring_segments, ring_across;
  double tube_length, tube_side, gap;
  int tube_segments;
} band_dims;

typedef struct key {
  const char* name;
  double* num;
  int* count;
  double lo, hi;
  const char* help;
} key;

// a centre line: point and frame at a parameter s in [0, 1]
typedef void (*centre_fn)(const band_dims* d, double s, double c[3], double t[3], double n[3]);

static const double PI = 3.14159265358979323846;

// the ring's arc: tail at 135 degrees, counter-clockwise to the head; the
// gap between head and tail is centred on +y (anterior)
static double ring_radius(const band_dims* d) { return d->ring_length / (d->ring_arc_deg * PI / 180); }
static double ring_angle(const band_dims* d, double s) {
  double gap = 2 * PI - d->ring_arc_deg * PI / 180;
  return PI / 2 + gap / 2 + s * d->ring_arc_deg * PI / 180;
}

static void ring_centre(const band_dims* d, double s, double c[3], double t[3], double n[3]) {
  double r = ring_radius(d), a = ring_angle(d, s);
  c[0] = r * cos(a), c[1] = r * sin(a), c[2] = 0;
  t[0] = -sin(a), t[1] = cos(a), t[2] = 0; // along increasing s
  n[0] = cos(a), n[1] = sin(a), n[2] = 0;  // radially out
}

// the tube: from the ring's tail, a gap beyond it, straight on away from the ring
static void tube_centre(const band_dims* d, double s, double c[3], double t[3], double n[3]) {
  double c0[3], t0[3], n0[3];
  ring_centre(d, 0, c0, t0, n0);
  double along = d->gap + s * d->tube_length;
  for (int a = 0; a < 3; a++) c[a] = c0[a] - t0[a] * along, t[a] = -t0[a], n[a] = n0[a];
}

static double tet_volume(const double* a, const double* b, const double* c, const double* e) {
  double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]},
         w[3] = {e[0] - a[0], e[1] - a[1], e[2] - a[2]};
  return (u[0] * (v[1] * w[2] - v[2] * w[1]) + u[1] * (v[2] * w[0] - v[0] * w[2]) + u[2] * (v[0] * w[1] - v[1] * w[0])) / 6;
}

// The sweep: (segments + 1) cross-sections of (nu + 1) x (nv + 1) nodes, u
// across the thickness (along n), v across the width (along z).
static int sweep(const band_dims* d, centre_fn f, int segments, int nu, int nv, double thick, double width,
                 tx_tetmesh* m, int** marker) {
  const int per = (nu + 1) * (nv + 1);
  m->nv = (segments + 1) * per;
  m->ne = segments * nu * nv * 6;
  m->v = malloc(sizeof(double) * 3 * (size_t)m->nv);
  m->e = malloc(sizeof(int) * 4 * (size_t)m->ne);
  *marker = calloc((size_t)m->nv, sizeof(int));
  if (!m->v || !m->e || !*marker) return -1;
  for (int k = 0; k <= segments; k++) {
    double c[3], t[3], n[3];
    f(d, (double)k / segments, c, t, n);
    for (int j = 0; j <= nv; j++)
      for (int i = 0; i <= nu; i++) {
        int id = k * per + j * (nu + 1) + i;
        double u = thick * ((double)i / nu - 0.5), v = width * ((double)j / nv - 0.5);
        for (int a = 0; a < 3; a++) m->v[3 * id + a] = c[a] + n[a] * u + (a == 2 ? v : 0);
        (*marker)[id] = k == 0 ? 1 : k == segments ? 2 : 0;
      }
  }
  // Kuhn's split: one tetrahedron per order in which the path from corner
  // 000 to 111 steps along the three axes
  static const int order[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  int e = 0;
  for (int k = 0; k < segments; k++)
    for (int j = 0; j < nv; j++)
      for (int i = 0; i < nu; i++)
        for (int o = 0; o < 6; o++) {
          int corner[3] = {0, 0, 0}, *q = m->e + 4 * e++;
          for (int s = 0; s < 4; s++) {
            if (s > 0) corner[order[o][s - 1]] = 1;
            q[s] = (k + corner[2]) * per + (j + corner[1]) * (nu + 1) + i + corner[0];
          }
          if (tet_volume(m->v + 3 * q[0], m->v + 3 * q[1], m->v + 3 * q[2], m->v + 3 * q[3]) < 0) {
            int x = q[1];
            q[1] = q[2], q[2] = x;
          }
        }
  return 0;
}

static int write_part(const char* dir, const char* name, const tx_tetmesh* m, const int* marker, const char* what) {
  char path[4096], part[4200];
  const char* ext[2] = {"node", "ele"};
  for (int w = 0; w < 2; w++) {
    snprintf(path, sizeof path, "%s/%s.%s", dir, name, ext[w]);
    snprintf(part, sizeof part, "%s.part", path);
    FILE* f = fopen(part, "w");
    if (!f) return fprintf(stderr, "tactus-band-assets: %s: %s\n", part, strerror(errno)), -1;
    if (w == 0) {
      fprintf(f, "%d 3 0 1\n", m->nv);
      for (int i = 0; i < m->nv; i++)
        fprintf(f, "%d %.9g %.9g %.9g %d\n", i, m->v[3 * i], m->v[3 * i + 1], m->v[3 * i + 2], marker[i]);
    } else {
      fprintf(f, "%d 4 0\n", m->ne);
      for (int i = 0; i < m->ne; i++) fprintf(f, "%d %d %d %d %d\n", i, m->e[4 * i], m->e[4 * i + 1], m->e[4 * i + 2], m->e[4 * i + 3]);
    }
    fprintf(f, "# %s, tactus-band-assets\n", what);
    if (fclose(f) != 0) return fprintf(stderr, "tactus-band-assets: %s: write failed\n", part), remove(part), -1;
  }
  return 0;
}

static int publish(const char* dir, const char* name) {
  char path[4096], part[4200];
  const char* ext[2] = {"node", "ele"};
  for (int w = 0; w < 2; w++) {
    snprintf(path, sizeof path, "%s/%s.%s", dir, name, ext[w]);
    snprintf(part, sizeof part, "%s.part", path);
    if (rename(part, path) != 0) return fprintf(stderr, "tactus-band-assets: %s: %s\n", path, strerror(errno)), -1;
  }
  return 0;
}

static void discard(const char* dir, const char* name) {
  char part[4200];
  snprintf(part, sizeof part, "%s/%s.node.part", dir, name), remove(part);
  snprintf(part, sizeof part, "%s/%s.ele.part", dir, name), remove(part);
}

int main(int argc, char** argv) {
  band_dims d = {.ring_length = 0.10,
                 .ring_arc_deg = 270,
                 .ring_width = 0.013,
                 .ring_thickness = 0.004,
                 .ring_segments = 24,
                 .ring_across = 2,
                 .tube_length = 0.15,
                 .tube_side = 0.003,
                 .gap = 0.003,
                 .tube_segments = 40};
  const key keys[] = {
      {"ring_length", &d.ring_length, NULL, 0.02, 0.5, "m, the ring part's centre line"},
      {"ring_arc_deg", &d.ring_arc_deg, NULL, 30, 350, "degrees of arc of its curved rest shape"},
      {"ring_width", &d.ring_width, NULL, 0.002, 0.05, "m, along z"},
      {"ring_thickness", &d.ring_thickness, NULL, 0.001, 0.02, "m, radially"},
      {"ring_segments", NULL, &d.ring_segments, 2, 400, "cells along the ring"},
      {"ring_across", NULL, &d.ring_across, 1, 8, "cells across its width"},
      {"tube_length", &d.tube_length, NULL, 0.01, 1, "m"},
      {"tube_side", &d.tube_side, NULL, 0.0005, 0.02, "m, the tube's square cross-section"},
      {"tube_segments", NULL, &d.tube_segments, 2, 1000, "cells along the tube"},
      {"gap", &d.gap, NULL, 0.0005, 0.05, "m, from the ring's tail to the tube's start: the distance joint's length"},
  };
  const int nkeys = (int)(sizeof keys / sizeof keys[0]);
  if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
    FILE* o = argc < 2 ? stderr : stdout;
    fprintf(o, "usage: tactus-band-assets OUTDIR [key=value ...]\n");
    for (int k = 0; k < nkeys; k++) fprintf(o, "  %-15s %s\n", keys[k].name, keys[k].help);
    return argc < 2 ? 2 : 0;
  }
  for (int a = 2; a < argc; a++) {
    const char* eq = strchr(argv[a], '=');
    int k = 0;
    while (k < nkeys && !(eq && strlen(keys[k].name) == (size_t)(eq - argv[a]) && strncmp(argv[a], keys[k].name, (size_t)(eq - argv[a])) == 0)) k++;
    if (k == nkeys) return fprintf(stderr, "tactus-band-assets: %s: unknown option (expected key=value)\n", argv[a]), 2;
    char* end;
    errno = 0;
    double v = strtod(eq + 1, &end);
    if (end == eq + 1 || *end || errno || !(v >= keys[k].lo && v <= keys[k].hi) || (keys[k].count && v != floor(v)))
      return fprintf(stderr, "tactus-band-assets: %s: expected %s from %g to %g\n", keys[k].name, keys[k].count ? "a whole number" : "a number", keys[k].lo, keys[k].hi), 2;
    if (keys[k].num) *keys[k].num = v;
    else *keys[k].count = (int)v;
  }
  struct stat st;
  if (stat(argv[1], &st) != 0 || !S_ISDIR(st.st_mode)) return fprintf(stderr, "tactus-band-assets: %s: not a folder\n", argv[1]), 2;

  tx_tetmesh ring = {0}, tube = {0};
  int *ring_mark = NULL, *tube_mark = NULL, rc = 1;
  if (sweep(&d, ring_centre, d.ring_segments, 1, d.ring_across, d.ring_thickness, d.ring_width, &ring, &ring_mark) ||
      sweep(&d, tube_centre, d.tube_segments, 1, 1, d.tube_side, d.tube_side, &tube, &tube_mark)) {
    fprintf(stderr, "tactus-band-assets: out of memory\n");
    goto done;
  }
  tx_tetmesh_report rr, tr;
  tx_tetmesh_inspect(&ring, &rr);
  tx_tetmesh_inspect(&tube, &tr);
  if (rr.inverted || rr.degenerate || tr.inverted || tr.degenerate) {
    fprintf(stderr, "tactus-band-assets: ring_thickness: the sweep folds (inverted tetrahedra); a thinner ring or a longer arc\n");
    rc = 2;
    goto done;
  }
  char what[512];
  snprintf(what, sizeof what, "ring part: %.4g m over %.4g degrees (radius %.4g m), %.4g x %.4g m", d.ring_length,
           d.ring_arc_deg, ring_radius(&d), d.ring_width, d.ring_thickness);
  if (write_part(argv[1], "band_ring", &ring, ring_mark, what)) goto fail;
  snprintf(what, sizeof what, "tube part: %.4g m, %.4g m square, %.4g m from the ring's tail", d.tube_length, d.tube_side, d.gap);
  if (write_part(argv[1], "band_tube", &tube, tube_mark, what)) goto fail;
  if (publish(argv[1], "band_ring") || publish(argv[1], "band_tube")) goto done;
  printf("ring: %d nodes, %d tetrahedra, %.4g cm^3, dihedral %.1f-%.1f degrees\n", ring.nv, ring.ne, rr.volume * 1e6,
         rr.min_dihedral, rr.max_dihedral);
  printf("tube: %d nodes, %d tetrahedra, %.4g cm^3, dihedral %.1f-%.1f degrees\n", tube.nv, tube.ne, tr.volume * 1e6,
         tr.min_dihedral, tr.max_dihedral);
  rc = 0;
  goto done;
fail:
  discard(argv[1], "band_ring");
  discard(argv[1], "band_tube");
done:
  tx_tetmesh_free(&ring);
  tx_tetmesh_free(&tube);
  free(ring_mark);
  free(tube_mark);
  return rc;
}
