// tactus study organ-removal: the removal stress test of issue 17. A
// structured block of tetrahedra (controllers/organs/removal.h's
// tx_block_mesh: 16 x 8 x 16 cubes of 5 mm, 12,288 tetrahedra; quick: 4 x 3
// x 4, 288) of liver-like FEM tissue (Bullet's stable Neo-Hookean, E = 5 kPa,
// nu = 0.45, 1060 kg/m^3, damping 5/s, 1 ms steps with mass scaling, as
// physics.organs steps it), its base held, a 5 mm tool sphere circling on its
// top 3 mm deep and one top node pulled kinematically (a grasper), loses
// 10,000 tetrahedra (quick: 250) one at a time, in random order (a fixed
// seed), one removal and two 1 ms steps a frame. After every removal and
// step it checks what physics.organs would publish: every node finite (a
// NaN or an overspeed is a fault: counted, the state restored), every live
// tetrahedron's signed volume positive (none inverted), and the surface made
// of the live tetrahedra's boundary (tx_cut_surface) sound by
// tx_surface_check: every row referenced, no two rows at one node, every
// corner a live row, every edge run as often one way as the other (closed);
// edges of more than two triangles (tetrahedra meeting along an edge only,
// which random removal makes) are counted apart. Every 100th removal (quick:
// every one) the boundary is also compared with the live tetrahedra's found
// afresh. Writes organ-removal.csv (one row a removal), .json and .png (live
// tetrahedra and the frame's CPU time against removals).
#include "studies.h"

#include "../scenarios/command.h"
#include "../views/aside.h"
#include "../views/plot.h"
#include "../views/report.h"
#include "../model/error.h"

#include <tactus/config.h>

#if TX_WITH_BULLET
#include "../controllers/organs/bullet/fem.h"
#include "../controllers/organs/removal.h"
#endif

#include <jansson.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#if TX_WITH_BULLET
static const double CUBE = 0.005, TOOL_R = 0.005, TOOL_DEPTH = 0.003, STEP = 1e-3;
enum { STEPS_PER_FRAME = 2 };

// CPU time of this thread: the frame's own cost, not the other processes' on a shared machine
static double cpu_s(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double now_s(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int cmp_double(const void* a, const void* b) {
  double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}
#endif

int tx_study_organ_removal(const tx_study_args* a) {
  bool quick;
  int bad = tx_study_quick_set(a, &quick);
  if (bad) return bad;
#if !TX_WITH_BULLET
  (void)quick;
  return tx_bad_input("study organ-removal: this build has no Bullet (configured with TX_WITH_BULLET=OFF)");
#else
  const int nx = quick ? 4 : 16, ny = quick ? 3 : 8, nz = quick ? 4 : 16, removals = quick ? 250 : 10000;
  const int reference_every = quick ? 1 : 100;
  double* x0 = NULL;
  int *tet = NULL, nv, ne;
  if (!tx_block_mesh(nx, ny, nz, CUBE, &x0, &nv, &tet, &ne)) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  tx_fem_def d = tx_fem_def_default();
  d.model = TX_FEM_NEOHOOKEAN, d.young = 5e3, d.poisson = 0.45, d.density = 1060, d.damping = 5;
  d.dt = STEP, d.mass_scaling = true, d.max_speed = 20;
  tx_fem* body = tx_fem_create(&d, x0, nv, tet, ne);
  // everything sized once, as a controller would at init
  int32_t *row_of = malloc(sizeof(int32_t) * (size_t)nv), *node_of = malloc(sizeof(int32_t) * (size_t)nv),
          *seen = malloc(sizeof(int32_t) * (size_t)nv), *tri = malloc(sizeof(int32_t) * 12 * (size_t)ne);
  float* xs = malloc(sizeof(float) * 3 * (size_t)nv);
  double* pos = malloc(sizeof(double) * 3 * (size_t)nv);
  uint64_t* keys = malloc(sizeof(uint64_t) * 12 * (size_t)ne);
  int* order = malloc(sizeof(int) * (size_t)ne);
  double* frame_ms = malloc(sizeof(double) * (size_t)removals);
  double *plot_x = malloc(sizeof(double) * (size_t)removals), *plot_live = malloc(sizeof(double) * (size_t)removals);
  if (!body || !row_of || !node_of || !seen || !tri || !xs || !pos || !keys || !order || !frame_ms || !plot_x ||
      !plot_live) {
    fprintf(stderr, "tactus: study organ-removal: %s\n", body ? "out of memory" : tx_error());
    tx_fem_destroy(body);
    free(x0), free(tet), free(row_of), free(node_of), free(seen), free(tri), free(xs), free(pos), free(keys), free(order);
    free(frame_ms), free(plot_x), free(plot_live);
    return 1;
  }
  for (int i = 0; i < nv; i++) row_of[i] = -1;
  // the base held; the grasped node: the top's corner
  int grasped = -1;
  for (int i = 0; i < nv; i++) {
    if (x0[3 * i + 1] < 1e-9) tx_fem_fix(body, i);
    if (x0[3 * i + 1] > ny * CUBE - 1e-9 && x0[3 * i] < 1e-9 && x0[3 * i + 2] < 1e-9) grasped = i;
  }
  // a random order (a fixed seed: the run is the same every time)
  for (int e = 0; e < ne; e++) order[e] = e;
  uint64_t s = 0x9e3779b97f4a7c15u;
  for (int e = ne - 1; e > 0; e--) {
    s = s * 6364136223846793005u + 1442695040888963407u;
    int j = (int)((s >> 33) % (uint64_t)(e + 1)), w = order[e];
    order[e] = order[j], order[j] = w;
  }
  printf("study organ-removal: a block of %d x %d x %d cubes of %g mm, %d tetrahedra, %d nodes, Neo-Hookean E = %g kPa, "
         "nu = %g, %g kg/m^3, damping %g/s, steps of %g ms (mass scaling), base held, a %g mm tool circling %g mm deep "
         "on top (pressed in over 0.5 s), a top node pulled; %d tetrahedra removed one a frame (%d steps) in random order%s\n",
         nx, ny, nz, CUBE * 1e3, ne, nv, d.young * 1e-3, d.poisson, d.density, d.damping, STEP * 1e3, TOOL_R * 1e3,
         TOOL_DEPTH * 1e3, removals, STEPS_PER_FRAME, quick ? " (quick)" : "");

  tx_aside out;
  FILE* csv = tx_aside_begin(&out, a->out_dir, "organ-removal.csv") ? out.f : NULL;
  if (!csv) {
    tx_fem_destroy(body);
    free(x0), free(tet), free(row_of), free(node_of), free(seen), free(tri), free(xs), free(pos), free(keys), free(order);
    free(frame_ms), free(plot_x), free(plot_live);
    return tx_bad_input("--out %s", tx_error());
  }
  fprintf(csv, "removal,tet,live_tets,live_nodes,surface_rows,surface_triangles,nonmanifold_edges,faults,inverted,"
               "min_volume_ratio,surface_ok,reference_ok,frame_ms\n");
  long faults = 0, inverted = 0, not_finite = 0, surface_bad = 0, reference_bad = 0, references = 0, refused = 0;
  long unreferenced = 0, doubled = 0, out_of_range = 0, open_edges = 0, degenerate = 0;
  int nonmanifold_max = 0, frames_nonmanifold = 0;
  double worst_ratio = INFINITY, t_start = now_s();
  const double top = ny * CUBE, cx = nx * CUBE / 2, cz = nz * CUBE / 2, orbit = 0.3 * fmin(nx, nz) * CUBE;
  tx_fem_save(body);
  for (int r = 0; r < removals; r++) {
    double t = (r + 1) * STEPS_PER_FRAME * STEP;
    double f0 = cpu_s();
    // the frame: a removal, the loads moved, the steps, the surface built
    if (!tx_fem_remove_tet(body, order[r])) refused++;
    double depth = TOOL_DEPTH * fmin(1, t / 0.5); // pressed in over the first 0.5 s
    double tool[3] = {cx + orbit * cos(2 * M_PI * t), top + TOOL_R - depth, cz + orbit * sin(2 * M_PI * t)};
    tx_fem_set_tool(body, tool, TOOL_R);
    if (grasped >= 0 && tx_fem_node_live(body, grasped)) {
      double p[3] = {x0[3 * grasped] - 0.004 * sin(M_PI * t), x0[3 * grasped + 1] + 0.004 * sin(M_PI * t), x0[3 * grasped + 2]};
      tx_fem_set_kinematic(body, grasped, p);
    }
    bool ok = tx_fem_step(body, STEPS_PER_FRAME);
    if (ok) tx_fem_save(body);
    else faults++, tx_fem_restore(body);
    tx_fem_positions(body, pos);
    int nf;
    const int* hull = tx_fem_hull(body, &nf);
    int rows = tx_cut_surface(hull, nf, pos, row_of, node_of, xs, tri);
    frame_ms[r] = (cpu_s() - f0) * 1e3;
    // the checks
    for (int i = 0; i < 3 * nv; i++)
      if (!isfinite(pos[i])) {
        not_finite++;
        break;
      }
    int inv = 0, live_nodes = 0;
    double ratio = INFINITY;
    for (int e = 0; e < ne; e++) {
      if (!tx_fem_tet_live(body, e)) continue;
      double v = tx_fem_tet_volume(body, e);
      if (!(v > 0)) inv++;
      ratio = fmin(ratio, v / (CUBE * CUBE * CUBE / 6));
    }
    for (int i = 0; i < nv; i++) live_nodes += tx_fem_node_live(body, i);
    inverted += inv;
    worst_ratio = fmin(worst_ratio, ratio);
    tx_surface_report rep;
    bool sound = tx_surface_check(tri, nf, rows, node_of, nv, keys, seen, &rep);
    for (int k = 0; k < rows && sound; k++) sound = tx_fem_node_live(body, node_of[k]);
    surface_bad += !sound;
    unreferenced += rep.unreferenced, doubled += rep.doubled, out_of_range += rep.out_of_range;
    open_edges += rep.open_edges, degenerate += rep.degenerate;
    nonmanifold_max = rep.nonmanifold_edges > nonmanifold_max ? rep.nonmanifold_edges : nonmanifold_max;
    frames_nonmanifold += rep.nonmanifold_edges > 0;
    int reference = -1;
    if ((r + 1) % reference_every == 0 || r == removals - 1) {
      reference = tx_fem_hull_is_live_boundary(body);
      references++, reference_bad += !reference;
    }
    plot_x[r] = r + 1, plot_live[r] = tx_fem_live_tet_count(body);
    fprintf(csv, "%d,%d,%d,%d,%d,%d,%d,%d,%d,%.6g,%d,%d,%.4f\n", r + 1, order[r], tx_fem_live_tet_count(body), live_nodes,
            rows, nf, rep.nonmanifold_edges, ok ? 0 : 1, inv, ratio, sound, reference, frame_ms[r]);
    if (!quick && (r + 1) % 1000 == 0)
      printf("  %5d removed: %5d tetrahedra and %5d nodes live, surface %5d rows %5d triangles, %4.2f ms a frame\n", r + 1,
             tx_fem_live_tet_count(body), live_nodes, rows, nf, frame_ms[r]);
  }
  double seconds = now_s() - t_start;
  double* sorted = malloc(sizeof(double) * (size_t)removals);
  double p50 = NAN, p99 = NAN, pmax = NAN;
  if (sorted) {
    memcpy(sorted, frame_ms, sizeof(double) * (size_t)removals);
    qsort(sorted, (size_t)removals, sizeof(double), cmp_double);
    p50 = sorted[removals / 2], p99 = sorted[(int)(0.99 * (removals - 1))], pmax = sorted[removals - 1];
    free(sorted);
  }
  bool passed = faults == 0 && not_finite == 0 && inverted == 0 && surface_bad == 0 && reference_bad == 0 && refused == 0;
  printf("\n  %d removals in %.1f s: %ld refused, %ld faults (NaN or overspeed), %ld frames not finite, %ld inverted "
         "tetrahedra (smallest volume %.3g of the initial), surface unsound in %ld frames (%ld unreferenced rows, %ld "
         "doubled, %ld out of range, %ld open edges, %ld degenerate), boundary unlike the live tetrahedra's in %ld of %ld "
         "comparisons; edges of more than two triangles in %d frames (at most %d)\n  a frame (removal, 2 steps, surface): "
         "p50 %.3f ms, p99 %.3f ms, max %.3f ms\n  passed: %s\n",
         removals, seconds, refused, faults, not_finite, inverted, worst_ratio, surface_bad, unreferenced, doubled,
         out_of_range, open_edges, degenerate, reference_bad, references, frames_nonmanifold, nonmanifold_max, p50, p99,
         pmax, passed ? "yes" : "NO");
  int live_end = tx_fem_live_tet_count(body);
  tx_fem_destroy(body);
  free(x0), free(tet), free(row_of), free(node_of), free(seen), free(tri), free(xs), free(pos), free(keys), free(order);
  int rc = 0;
  if (!tx_aside_end(&out)) {
    fprintf(stderr, "tactus: %s\n", tx_error());
    rc = 1;
  }
  json_t* doc = rc ? NULL
                   : json_pack("{s:s,s:b,s:{s:i,s:i,s:i,s:f,s:i,s:i},s:{s:f,s:f,s:f,s:f,s:f,s:f,s:f},s:i,s:i,s:I,s:I,s:I,"
                               "s:I,s:f,s:{s:I,s:I,s:I,s:I,s:I,s:I},s:I,s:I,s:i,s:i,s:{s:f,s:f,s:f},s:f,s:b}",
                               "study", "organ-removal", "quick", quick, "block", "nx", nx, "ny", ny, "nz", nz, "cube_m",
                               CUBE, "tets", ne, "nodes", nv, "tissue", "young_pa", d.young, "poisson", d.poisson, "density",
                               d.density, "damping_per_s", d.damping, "step_s", STEP, "tool_radius_m", TOOL_R,
                               "tool_depth_m", TOOL_DEPTH, "removals", removals, "live_tets_at_end", live_end, "refused",
                               (json_int_t)refused, "faults", (json_int_t)faults, "not_finite_frames",
                               (json_int_t)not_finite, "inverted", (json_int_t)inverted, "min_volume_ratio", worst_ratio,
                               "surface", "unsound_frames", (json_int_t)surface_bad, "unreferenced_rows",
                               (json_int_t)unreferenced, "doubled_rows", (json_int_t)doubled, "out_of_range",
                               (json_int_t)out_of_range, "open_edges", (json_int_t)open_edges, "degenerate",
                               (json_int_t)degenerate, "reference_comparisons", (json_int_t)references,
                               "reference_mismatches", (json_int_t)reference_bad, "frames_with_nonmanifold_edges",
                               frames_nonmanifold, "nonmanifold_edges_max", nonmanifold_max, "frame_ms", "p50", p50, "p99",
                               p99, "max", pmax, "seconds", seconds, "passed", passed);
  if (!rc && (!doc || tx_report_save(doc, a->out_dir, "organ-removal.json"))) {
    fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "organ-removal: out of memory");
    rc = 1;
  }
  json_decref(doc);
  if (!rc) {
    char png[4200];
    snprintf(png, sizeof png, "%s/organ-removal.png", a->out_dir);
    tx_plot_series live = {"live tetrahedra", plot_x, plot_live, removals, false, 1};
    tx_plot_series took = {"frame (removal, 2 steps, surface)", plot_x, frame_ms, removals, false, 2};
    tx_plot panels[2] = {{"Removal at random: tetrahedra left", "removals", "live tetrahedra", false, false, &live, 1},
                         {"Removal at random: the frame's time", "removals", "time (ms)", false, false, &took, 1}};
    bool plotted = tx_plot_png_panels(png, panels, 2, 2) == 0;
    if (!plotted) fprintf(stderr, "tactus: %s\n", tx_error());
    printf("\nwrote %s/organ-removal.json, .csv%s\n", a->out_dir, plotted ? ", .png" : "");
  }
  free(frame_ms), free(plot_x), free(plot_live);
  return rc ? rc : passed ? 0 : 1;
#endif
}
