// tactus study organ-hemisphere: the LAGB paper's check of its soft bodies
// (its Figure 14). A hemisphere (R = 2 cm, E = 5 kPa, nu = 0.45) with its
// base fixed is indented at its pole by a tool's tip (a rigid frictionless
// ball of 5 mm, on tetrahedra graded toward the pole, assets/hemisphere) or
// by a rigid frictionless plate (on structured meshes), on
// Bullet's FEM deformables (corotated) at three refinements and on Bullet's
// classic soft body (links) at several iteration counts. The force against
// Hertz, F = (4/3) E / (1 - nu^2) sqrt(R) d^(3/2) ((16/9) E sqrt(R) d^(3/2)
// at nu = 0.5, R the two curvatures' Ri Rh / (Ri + Rh)); the force's observed order and Richardson limit; the
// deformation profile against the finest FEM mesh; error against CPU time.
// Quasi-static: each depth is held until the body is at rest (mass-scaled
// explicit steps, damping), so the answers do not depend on density or time.
// Writes organ-hemisphere.csv, .json and .png.
#include "studies.h"

#include "experiments/organ_axisym.h"
#include "experiments/organ_hemisphere.h"
#include "../scenarios/command.h"
#include "../views/aside.h"
#include "../views/plot.h"
#include "../views/report.h"
#include "../model/error.h"
#include "../tools/lagb/mesh.h"

#include <tactus/config.h>
#include <tactus/model.h>

#if TX_WITH_BULLET
#include "../controllers/organs/bullet/fem.h"
#endif

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static json_t* num(double v) { return isfinite(v) ? json_real(v) : json_null(); }

#if TX_WITH_BULLET
enum { DEPTHS = 5, LEVELS = 3, LINK_RUNS = 4 };

static const double RADIUS = 0.02, YOUNG = 5e3;

// what presses the pole: a ball of radius `radius` (m; 0: a flat plate), and
// Hertz's radius for the two curvatures. A ball's contact is small, so its
// meshes are tetgen's, graded toward the pole (assets/hemisphere/graded-L,
// tools/hemisphere_assets.c); the plate's are the structured ones, graded 1.5.
typedef struct indenter {
  double radius, hertz_radius;
} indenter;
static const double GRADE = 1.5;
// the continuum's elements per side (quick: the coarser three) and grading toward the pole
static const int AXI_FULL[LEVELS] = {16, 32, 64}, AXI_QUICK[LEVELS] = {8, 16, 32};
static const double AXI_GRADE = 2;

typedef struct run_result {
  int tets;
  double dt;             // s
  double cpu;            // s
  double force[DEPTHS];  // N, at d / R = 0.02 .. 0.10
  int np;                // surface nodes of the cap (the base's left out)
  double* phi;           // (np) their angle from the pole at rest, rad
  double* uy;            // (np) their vertical displacement at the deepest depth, m
  bool finite;
} run_result;

static double cpu_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

// the mesh at refinement `level`: the structured hemisphere at that many
// cells per radius under a plate, tetgen's graded level under a ball
static bool hemisphere_mesh(const indenter* in, int level, tx_hemisphere_mesh* m) {
  if (in->radius <= 0) return tx_hemisphere_build_graded(RADIUS, level, GRADE, m);
  *m = (tx_hemisphere_mesh){0};
  char node[4300], ele[4300];
  snprintf(node, sizeof node, "%s/hemisphere/graded-%d.node", TX_ASSET_DIR, level);
  snprintf(ele, sizeof ele, "%s/hemisphere/graded-%d.ele", TX_ASSET_DIR, level);
  tx_tetmesh t;
  if (!tx_tetmesh_read(node, ele, &t)) return false;
  m->n = level, m->nv = t.nv, m->ne = t.ne, m->v = t.v, m->e = t.e;
  m->base = calloc((size_t)t.nv, sizeof(bool));
  if (!m->base) return tx_hemisphere_free(m), tx_set_error("organ-hemisphere: out of memory"), false;
  for (int i = 0; i < t.nv; i++) {
    m->base[i] = fabs(t.v[3 * i + 1]) < 1e-12;
    if (t.v[3 * i + 1] > t.v[3 * m->pole + 1]) m->pole = i;
  }
  return true;
}

// indent to each depth in turn, each ramped over half a settling time and
// then held for one, the force averaged over the last quarter
static bool indent(const tx_fem_def* d, const indenter* in, int n, run_result* r) {
  tx_hemisphere_mesh m;
  if (!hemisphere_mesh(in, n, &m)) return false;
  tx_fem* b = tx_fem_create(d, m.v, m.nv, m.e, m.ne);
  if (!b) {
    tx_hemisphere_free(&m);
    return false;
  }
  for (int i = 0; i < m.nv; i++)
    if (m.base[i]) tx_fem_fix(b, i);
  r->tets = m.ne;
  r->dt = tx_fem_dt(b);
  r->finite = true;
  double nu = d->poisson, wave = sqrt(YOUNG * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / d->density);
  int settle = (int)ceil(8 * RADIUS / wave / r->dt);
  if (d->model == TX_FEM_LINKS) settle = 400;
  double t0 = cpu_now();
  for (int l = 0; l < DEPTHS && r->finite; l++) {
    // the indenter's lowest point, from the last depth to this one
    double from = RADIUS - 0.02 * l * in->hertz_radius, to = RADIUS - 0.02 * (l + 1) * in->hertz_radius;
    for (int s = 1; s <= settle / 2 && r->finite; s++) {
      double y = from + (to - from) * s / (settle / 2);
      if (in->radius > 0) tx_fem_set_ball(b, (const double[3]){0, y + in->radius, 0}, in->radius);
      else tx_fem_set_plate(b, y);
      r->finite = tx_fem_step(b, 1);
    }
    r->finite = r->finite && tx_fem_step(b, settle - settle / 4) && tx_fem_step(b, settle / 4);
    r->force[l] = tx_fem_plate_force(b);
  }
  r->cpu = cpu_now() - t0;
  // the cap's surface nodes: the boundary's, off the base
  int faces = 0;
  const int* hull = tx_fem_hull(b, &faces);
  bool* cap = calloc((size_t)m.nv, sizeof(bool));
  double* x = malloc((size_t)m.nv * 3 * sizeof(double));
  r->np = 0;
  for (int k = 0; cap && k < 3 * faces; k++)
    if (!m.base[hull[k]] && !cap[hull[k]]) cap[hull[k]] = true, r->np++;
  r->phi = malloc((size_t)(r->np + 1) * sizeof(double));
  r->uy = malloc((size_t)(r->np + 1) * sizeof(double));
  bool ok = cap && x && r->phi && r->uy;
  if (ok) {
    tx_fem_positions(b, x);
    for (int i = 0, k = 0; i < m.nv; i++) {
      if (!cap[i]) continue;
      const double* p = m.v + 3 * i;
      r->phi[k] = atan2(sqrt(p[0] * p[0] + p[2] * p[2]), p[1]);
      r->uy[k++] = x[3 * i + 1] - p[1];
    }
  }
  free(cap), free(x);
  tx_fem_destroy(b);
  tx_hemisphere_free(&m);
  if (!ok) tx_set_error("organ-hemisphere: out of memory");
  return ok;
}

static void free_run(run_result* r) { free(r->phi), free(r->uy); }

enum { PROFILE_BINS = 721 };  // a profile sampled from the pole (0) to the base rim (pi / 2), every 0.125 degrees

// a run's profile in bins of its nodes' angle (their mean; an empty bin
// linear between its neighbours), so that meshes that do not nest compare
static void binned_profile(const run_result* r, double* out) {
  int count[PROFILE_BINS] = {0};
  for (int k = 0; k < PROFILE_BINS; k++) out[k] = 0;
  for (int i = 0; i < r->np; i++) {
    int k = (int)lround(r->phi[i] / (M_PI / 2) * (PROFILE_BINS - 1));
    k = k < 0 ? 0 : k >= PROFILE_BINS ? PROFILE_BINS - 1 : k;
    out[k] += r->uy[i], count[k]++;
  }
  int last = -1;
  for (int k = 0; k < PROFILE_BINS; k++) {
    if (!count[k]) continue;
    out[k] /= count[k];
    for (int j = last + 1; j < k; j++) out[j] = last < 0 ? out[k] : out[last] + (out[k] - out[last]) * (j - last) / (k - last);
    last = k;
  }
  for (int j = last + 1; j < PROFILE_BINS; j++) out[j] = last < 0 ? 0 : out[last];
}

// RMS over a run's cap nodes of the difference to a reference profile (bins,
// linear between them), over the depth
static double profile_error(const run_result* r, const double* ref, double depth) {
  double s = 0;
  for (int i = 0; i < r->np; i++) {
    double x = r->phi[i] / (M_PI / 2) * (PROFILE_BINS - 1);
    int j = (int)x < PROFILE_BINS - 2 ? (int)x : PROFILE_BINS - 2;
    s += pow(r->uy[i] - (ref[j] + (ref[j + 1] - ref[j]) * (x - j)), 2);
  }
  return r->np ? sqrt(s / r->np) / depth : NAN;
}
#endif

int tx_study_organ_hemisphere(const tx_study_args* a) {
  bool quick = false;
  double nu = 0.45, tip_mm = 5;
  for (int i = 0; i < a->nsets; i++) {
    const char* eq = strchr(a->sets[i], '=');
    double v;
    size_t k = eq ? (size_t)(eq - a->sets[i]) : 0;
    if (eq && k == 5 && strncmp(a->sets[i], "quick", 5) == 0) {
      if (!tx_parse_num(eq + 1, 0, 1, &v) || (v != 0 && v != 1)) return tx_bad_input("--set %s: expected 0 or 1", a->sets[i]);
      quick = v == 1;
    } else if (eq && k == 7 && strncmp(a->sets[i], "poisson", 7) == 0) {
      if (!tx_parse_num(eq + 1, 0, 0.49, &nu)) return tx_bad_input("--set %s: expected 0 to 0.49", a->sets[i]);
    } else if (eq && k == 11 && strncmp(a->sets[i], "indenter_mm", 11) == 0) {
      if (!tx_parse_num(eq + 1, 0, 20, &tip_mm) || (tip_mm > 0 && tip_mm < 1))
        return tx_bad_input("--set %s: expected 0 (a flat plate) or 1 to 20 mm", a->sets[i]);
    } else {
      return tx_bad_input("--set %s: unknown key (known: quick, poisson, indenter_mm)", a->sets[i]);
    }
  }
#if !TX_WITH_BULLET
  (void)num, (void)quick, (void)nu, (void)tip_mm;
  return tx_bad_input("study organ-hemisphere: this build has no Bullet (configured with TX_WITH_BULLET=OFF)");
#else
  // refinements at ratio 2: cells per radius under a plate, tetgen's graded
  // levels under a ball; quick: the coarsest three
  const int plate_levels[2][LEVELS] = {{2, 4, 8}, {1, 2, 4}}, ball_levels[2][LEVELS] = {{1, 2, 3}, {0, 1, 2}};
  const int* levels = (tip_mm > 0 ? ball_levels : plate_levels)[quick];
  const int link_iterations[LINK_RUNS] = {2, 5, 10, 20};
  const int link_n = levels[1];
  indenter in = {tip_mm * 1e-3, RADIUS};
  if (in.radius > 0) in.hertz_radius = in.radius * RADIUS / (in.radius + RADIUS);
  const double RH = in.hertz_radius;  // Hertz's R: d/R below is over it
  if (in.radius > 0)
    printf("study organ-hemisphere: R = %g cm, E = %g kPa, nu = %g, base fixed, a tool's tip (a rigid frictionless sphere of"
           " %g mm) at the pole; Hertz's R = %g mm%s\n\n",
           RADIUS * 1e2, YOUNG * 1e-3, nu, in.radius * 1e3, RH * 1e3, quick ? ", quick" : "");
  else
    printf("study organ-hemisphere: R = %g cm, E = %g kPa, nu = %g, base fixed, a rigid frictionless plate at the pole%s\n\n",
           RADIUS * 1e2, YOUNG * 1e-3, nu, quick ? ", quick" : "");

  tx_aside out;
  if (!tx_aside_begin(&out, a->out_dir, "organ-hemisphere.csv")) return tx_bad_input("--out %s", tx_error());
  FILE* csv = out.f;
  fprintf(csv, "model,refinement,tetrahedra,iterations,dt_s,cpu_s,d_over_r,force_n,hertz_n,force_error,profile_error,"
               "continuum_n,continuum_force_error,continuum_profile_error\n");

  run_result fem[LEVELS] = {{0}}, links[LINK_RUNS] = {{0}};
  tx_fem_def d = tx_fem_def_default();
  d.young = YOUNG, d.poisson = nu, d.mass_scaling = true;
  d.damping = 4 * sqrt(YOUNG * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / d.density) / RADIUS;  // about critical, lowest mode
  bool ok = true;
  for (int l = 0; l < LEVELS && ok; l++) {
    ok = indent(&d, &in, levels[l], &fem[l]);
    if (ok) printf("  FEM corotated, %s %d, %6d tetrahedra: %.2f s of CPU\n", in.radius > 0 ? "graded level" : "cells per radius",
                   levels[l], fem[l].tets, fem[l].cpu);
    fflush(stdout);
  }
  tx_fem_def dl = d;
  dl.model = TX_FEM_LINKS, dl.dt = 1e-3, dl.damping = 20, dl.mass_scaling = false;
  for (int k = 0; k < LINK_RUNS && ok; k++) {
    dl.iterations = link_iterations[k];
    ok = indent(&dl, &in, link_n, &links[k]);
  }
  if (!ok) {
    tx_aside_drop(&out);
    for (int l = 0; l < LEVELS; l++) free_run(&fem[l]);
    for (int k = 0; k < LINK_RUNS; k++) free_run(&links[k]);
    return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  }

  // the continuum (axisymmetric, 9-node elements): the finite body's own
  // answer, at the study's depths and at shallower ones where Hertz holds
  enum { SHALLOW = 3, ALL = SHALLOW + DEPTHS };
  const double shallow[SHALLOW] = {0.001, 0.003, 0.01};
  const int* axl = quick ? AXI_QUICK : AXI_FULL;
  double axi[LEVELS][ALL], axi_cpu[LEVELS], cont[ALL], cont_spread[ALL], uc[PROFILE_BINS];
  int axi_dofs[LEVELS];
  for (int l = 0; l < LEVELS; l++) {
    double t0 = cpu_now();
    tx_axisym* c = tx_axisym_create(RADIUS, YOUNG, nu, axl[l], AXI_GRADE);
    bool good = c != NULL;
    for (int i = 0; i < ALL && good; i++)
      good = tx_axisym_indent(c, (i < SHALLOW ? shallow[i] : 0.02 * (i - SHALLOW + 1)) * RH, in.radius, &axi[l][i]);
    axi_dofs[l] = c ? tx_axisym_dofs(c) : 0;
    if (good && l == LEVELS - 1)  // the finest at d / R = 0.1, the last depth
      for (int k = 0; k < PROFILE_BINS; k++) uc[k] = tx_axisym_surface_uz(c, M_PI / 2 * k / (PROFILE_BINS - 1));
    tx_axisym_destroy(c);
    axi_cpu[l] = cpu_now() - t0;
    if (!good) {
      tx_aside_drop(&out);
      for (int k = 0; k < LEVELS; k++) free_run(&fem[k]);
      for (int k = 0; k < LINK_RUNS; k++) free_run(&links[k]);
      return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
    }
  }
  printf("\n  the continuum (axisymmetric, 9-node elements, grading %g), the hemisphere's own answer: force (N)\n"
         "  %6s %10s", AXI_GRADE, "d/R", "Hertz");
  for (int l = 0; l < LEVELS; l++) printf("   n=%-3d %7s", axl[l], "");
  printf(" %6s %10s %8s %7s\n", "order", "reference", "spread", "/Hertz");
  json_t* jcont = json_array();
  for (int i = 0; i < ALL; i++) {
    double dr = i < SHALLOW ? shallow[i] : 0.02 * (i - SHALLOW + 1), h = tx_hertz_force(YOUNG, nu, RH, dr * RH);
    // Richardson where the three give an order; else the finest, its change from the one before as the spread
    double p = tx_observed_order(axi[0][i], axi[1][i], axi[2][i], 2);
    cont[i] = isfinite(p) && p > 0.5 ? tx_richardson(axi[1][i], axi[2][i], 2, p) : axi[2][i];
    cont_spread[i] = fmax(fabs(axi[2][i] - axi[1][i]), fabs(cont[i] - axi[2][i])) / cont[i];
    printf("  %6.3f %10.6f", dr, h);
    json_t* jl = json_array();
    for (int l = 0; l < LEVELS; l++) printf(" %13.7f", axi[l][i]), json_array_append_new(jl, num(axi[l][i]));
    printf(" %6.2f %10.6f %7.2f%% %+6.1f%%\n", p, cont[i], 100 * cont_spread[i], 100 * (cont[i] / h - 1));
    json_array_append_new(jcont, json_pack("{s:f,s:f,s:o,s:o,s:f,s:f,s:f}", "d_over_r", dr, "hertz_n", h, "force_n", jl,
                                           "observed_order", num(p), "reference_n", cont[i], "spread", cont_spread[i],
                                           "error_vs_hertz", cont[i] / h - 1));
  }
  printf("  (%d, %d, %d dofs; %.2f, %.2f, %.2f s of CPU)\n", axi_dofs[0], axi_dofs[1], axi_dofs[2], axi_cpu[0], axi_cpu[1],
         axi_cpu[2]);

  // FEM: force against Hertz at each depth and refinement
  const int top = LEVELS - 1;
  double depth_max = 0.1 * RH;
  printf("\n  force (N) against Hertz; FEM by refinement, and Richardson's limit from the three\n  %6s %10s", "d/R",
         "Hertz");
  for (int l = 0; l < LEVELS; l++) printf("   %s=%-2d %6s", in.radius > 0 ? "L" : "n", levels[l], "error");
  printf(" %6s %9s %6s\n", "order", "limit", "error");
  bool limits_within = true;
  bool all_finite = true;
  json_t* jdepths = json_array();
  for (int i = 0; i < DEPTHS; i++) {
    double dd = 0.02 * (i + 1) * RH, h = tx_hertz_force(YOUNG, nu, RH, dd);
    printf("  %6.2f %10.5f", dd / RH, h);
    json_t* jl = json_array();
    for (int l = 0; l < LEVELS; l++) {
      double e = fem[l].force[i] / h - 1;
      all_finite &= fem[l].finite && isfinite(fem[l].force[i]);
      printf(" %8.5f %5.1f%%", fem[l].force[i], 100 * e);
      json_array_append_new(jl, num(fem[l].force[i]));
    }
    double p = tx_observed_order(fem[0].force[i], fem[1].force[i], fem[2].force[i], 2);
    double lim = isfinite(p) ? tx_richardson(fem[1].force[i], fem[2].force[i], 2, p) : NAN;
    limits_within &= fabs(lim / h - 1) <= 0.10;
    printf(" %6.2f %9.5f %5.1f%%\n", p, lim, 100 * (lim / h - 1));
    json_array_append_new(jdepths, json_pack("{s:f,s:f,s:o,s:o,s:o}", "d_over_r", dd / RH, "hertz_n", h, "fem_force_n",
                                             jl, "observed_order", num(p), "richardson_limit_n", num(lim)));
  }
  // Richardson on the force at d / R = 0.1
  double f1 = fem[0].force[DEPTHS - 1], f2 = fem[1].force[DEPTHS - 1], f3 = fem[2].force[DEPTHS - 1];
  double order = tx_observed_order(f1, f2, f3, 2);
  double limit = isfinite(order) ? tx_richardson(f2, f3, 2, order) : NAN;
  double hertz_max = tx_hertz_force(YOUNG, nu, RH, depth_max);
  double finest_error = f3 / hertz_max - 1, limit_error = limit / hertz_max - 1;
  bool within = fabs(finest_error) <= 0.10;
  // what each part contributes: the finite body (the continuum against
  // Hertz's half space) and the 3-D tetrahedra (the finest against the continuum)
  printf("\n  what makes the finest FEM mesh differ from Hertz\n  %6s %12s %14s %12s\n", "d/R", "finite body",
         "tetrahedra", "together");
  bool continuum_within = true;
  double disc_max = 0;
  json_t* jparts = json_array();
  for (int i = 0; i < DEPTHS; i++) {
    double dd = 0.02 * (i + 1) * RH, h = tx_hertz_force(YOUNG, nu, RH, dd), c = cont[SHALLOW + i];
    double body = c / h - 1, tets = fem[top].force[i] / c - 1;
    continuum_within &= fabs(tets) <= 0.10;
    disc_max = fmax(disc_max, fabs(tets));
    printf("  %6.2f %+11.1f%% %+13.1f%% %+11.1f%%\n", dd / RH, 100 * body, 100 * tets, 100 * (fem[top].force[i] / h - 1));
    json_array_append_new(jparts, json_pack("{s:f,s:f,s:f,s:f}", "d_over_r", dd / RH, "finite_body", body,
                                            "tetrahedra", tets, "together", fem[top].force[i] / h - 1));
  }
  printf("  finest FEM mesh within 10%% of the converged continuum at every d/R <= 0.1: %s (largest %.1f%%)\n",
         continuum_within ? "yes" : "NO", 100 * disc_max);

  printf("\n  at d/R = 0.1: observed order %.2f, Richardson limit %.5f N (%+.1f%% from Hertz); finest mesh %+.1f%%:"
         " within 10%%: %s\n  Richardson's limit within 10%% of Hertz at every d/R <= 0.1: %s\n",
         order, limit, 100 * limit_error, 100 * finest_error, within ? "yes" : "NO", limits_within ? "yes" : "NO");

  // profiles against the finest FEM mesh, and error against CPU time
  double cpu_x[LEVELS + LINK_RUNS], err_y[LEVELS + LINK_RUNS];
  double finest[PROFILE_BINS];
  binned_profile(&fem[top], finest);
  printf("\n  error against run time (profile: RMS over the cap's surface against the finest FEM mesh and against\n"
         "  the continuum, over d; force: against Hertz and against the continuum, at d/R = 0.1)\n"
         "  %-10s %6s %10s %8s %10s %12s %10s %10s %10s\n",
         "model", "tets", "iterations", "dt us", "CPU s", "force error", "profile", "continuum", "profile");
  json_t* jruns = json_array();
  int np = 0;
  for (int l = 0; l < LEVELS; l++) {
    double fe = fem[l].force[DEPTHS - 1] / hertz_max - 1;
    double pe = l < top ? profile_error(&fem[l], finest, depth_max) : 0;
    double ce = fem[l].force[DEPTHS - 1] / cont[ALL - 1] - 1, cpe = profile_error(&fem[l], uc, depth_max);
    printf("  %-10s %6d %10s %8.1f %10.3f %11.1f%% %9.2f%% %+9.1f%% %9.2f%%\n", "FEM", fem[l].tets, "-", fem[l].dt * 1e6,
           fem[l].cpu, 100 * fe, 100 * pe, 100 * ce, 100 * cpe);
    char pe_text[32] = "";  // the finest is the reference: no error of its own
    if (l < top) snprintf(pe_text, sizeof pe_text, "%.6g", pe);
    for (int i = 0; i < DEPTHS; i++) {
      double dd = 0.02 * (i + 1) * RH, h = tx_hertz_force(YOUNG, nu, RH, dd);
      fprintf(csv, "fem_corotated,%d,%d,,%.6g,%.6g,%.2f,%.9g,%.9g,%.6g,%s,%.9g,%.6g,%.6g\n", levels[l], fem[l].tets, fem[l].dt, fem[l].cpu,
              dd / RH, fem[l].force[i], h, fem[l].force[i] / h - 1, pe_text, cont[SHALLOW + i],
              fem[l].force[i] / cont[SHALLOW + i] - 1, cpe);
    }
    json_array_append_new(jruns, json_pack("{s:s,s:i,s:i,s:f,s:f,s:o,s:o}", "model", "fem_corotated", "refinement",
                                           levels[l], "tetrahedra", fem[l].tets, "dt_s", fem[l].dt, "cpu_s", fem[l].cpu,
                                           "force_error_at_0_1", num(fe), "profile_error", l < top ? num(pe) : json_null()));
    json_object_update_new(json_array_get(jruns, json_array_size(jruns) - 1),
                           json_pack("{s:o,s:o}", "continuum_force_error_at_0_1", num(ce), "continuum_profile_error", num(cpe)));
    cpu_x[np] = fem[l].cpu, err_y[np++] = 100 * cpe;
  }
  int nfem = np;
  for (int k = 0; k < LINK_RUNS; k++) {
    double fe = links[k].force[DEPTHS - 1] / hertz_max - 1;
    double pe = profile_error(&links[k], finest, depth_max);
    all_finite &= links[k].finite;
    double ce = links[k].force[DEPTHS - 1] / cont[ALL - 1] - 1, cpe = profile_error(&links[k], uc, depth_max);
    printf("  %-10s %6d %10d %8.1f %10.3f %11.1f%% %9.2f%% %+9.1f%% %9.2f%%\n", "links", links[k].tets, link_iterations[k],
           links[k].dt * 1e6, links[k].cpu, 100 * fe, 100 * pe, 100 * ce, 100 * cpe);
    for (int i = 0; i < DEPTHS; i++) {
      double dd = 0.02 * (i + 1) * RH, h = tx_hertz_force(YOUNG, nu, RH, dd);
      fprintf(csv, "links,%d,%d,%d,%.6g,%.6g,%.2f,%.9g,%.9g,%.6g,%.6g,%.9g,%.6g,%.6g\n", link_n, links[k].tets,
              link_iterations[k], links[k].dt, links[k].cpu, dd / RH, links[k].force[i], h, links[k].force[i] / h - 1, pe,
              cont[SHALLOW + i], links[k].force[i] / cont[SHALLOW + i] - 1, cpe);
    }
    json_array_append_new(jruns, json_pack("{s:s,s:i,s:i,s:i,s:f,s:f,s:o,s:o}", "model", "links", "refinement",
                                           link_n, "tetrahedra", links[k].tets, "iterations", link_iterations[k], "dt_s",
                                           links[k].dt, "cpu_s", links[k].cpu, "force_error_at_0_1", num(fe),
                                           "profile_error", num(pe), "continuum_force_error_at_0_1", num(ce),
                                           "continuum_profile_error", num(cpe)));
    cpu_x[np] = links[k].cpu, err_y[np++] = 100 * cpe;
  }
  printf("\n  the links body has no E: its force is set by kLST, the iterations and the step, not by the tissue\n");
  bool falls = fabs(f2 / hertz_max - 1) < fabs(f1 / hertz_max - 1) && fabs(f3 / hertz_max - 1) < fabs(f2 / hertz_max - 1);
  printf("  FEM force error falls with refinement: %s; never a NaN: %s\n", falls ? "yes" : "NO", all_finite ? "yes" : "NO");

  for (int l = 0; l < LEVELS; l++) free_run(&fem[l]);
  for (int k = 0; k < LINK_RUNS; k++) free_run(&links[k]);
  if (!tx_aside_end(&out)) {
    json_decref(jdepths), json_decref(jruns), json_decref(jcont), json_decref(jparts);
    return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  }
  json_t* doc = json_pack("{s:s,s:b,s:{s:f,s:f,s:f,s:o,s:s},s:o,s:o,s:{s:o,s:o,s:o,s:f},s:b,s:b,s:b,s:b}", "study",
                          "organ-hemisphere", "quick", quick, "case", "radius_m", RADIUS, "young_pa", YOUNG, "poisson",
                          nu, "grading", num(in.radius > 0 ? NAN : GRADE), "hertz", "F = 4/3 E / (1 - nu^2) sqrt(R) d^(3/2)", "depths", jdepths,
                          "runs", jruns, "richardson_at_0_1", "observed_order", num(order), "limit_n", num(limit),
                          "limit_error", num(limit_error), "finest_error", finest_error, "fem_error_falls", falls,
                          "hertz_within_10_percent", within, "finite", all_finite,
                          "richardson_limits_within_10_percent", limits_within);
  if (doc) {
    json_object_update_new(json_object_get(doc, "case"), json_pack("{s:f,s:f,s:b}", "indenter_radius_m", in.radius,
                                                                   "hertz_radius_m", RH, "nodal_pressure", d.nodal_pressure));
    json_object_update_new(doc, json_pack("{s:{s:s,s:f,s:[i,i,i],s:o},s:o,s:b}", "continuum", "model",
                                          "axisymmetric, 9-node elements, exact frictionless contact", "grading",
                                          AXI_GRADE, "elements_per_side", axl[0], axl[1], axl[2], "depths", jcont,
                                          "parts", jparts, "fem_within_10_percent_of_continuum", continuum_within));
  } else
    json_decref(jcont), json_decref(jparts);
  if (!doc || tx_report_save(doc, a->out_dir, "organ-hemisphere.json")) {
    json_decref(doc);
    return fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "organ-hemisphere: out of memory"), 1;
  }
  json_decref(doc);

  char png[4200];
  snprintf(png, sizeof png, "%s/organ-hemisphere.png", a->out_dir);
  tx_plot_series s[] = {{"FEM (corotated), by refinement", cpu_x, err_y, nfem, true, 1},
                        {"links, by iterations", cpu_x + nfem, err_y + nfem, np - nfem, true, 2}};
  tx_plot p = {"Hemisphere indented to d/R = 0.1: profile error against run time", "CPU time (s)",
               "profile error against the converged continuum (% of d)", true, true, s, 2};
  bool plotted = tx_plot_png(png, &p) == 0;
  if (!plotted) fprintf(stderr, "tactus: %s\n", tx_error());
  printf("\nwrote %s/organ-hemisphere.json, .csv%s\n", a->out_dir, plotted ? ", .png" : "");
  return all_finite ? 0 : 1;
#endif
}
