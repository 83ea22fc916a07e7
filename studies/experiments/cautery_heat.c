#include "cautery_heat.h"

#include "../../model/error.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

double tx_heat_gauss_transient(double r, double t, double power, double s, double k, double alpha) {
  r = fmax(r, 1e-4 * s); // the bracket vanishes with r: its limit within 1e-8
  return power / (4 * M_PI * k * r) * (erfc(r / sqrt(2 * s * s + 4 * alpha * t)) - erfc(r / (s * M_SQRT2)));
}

double tx_heat_gauss_perfused(double r, double power, double s, double k, double l) {
  r = fmax(r, 1e-4 * s);
  double a = s * s / l, b = s * M_SQRT2;
  return power * exp(s * s / (2 * l * l)) / (8 * M_PI * k * r) *
         (exp(-r / l) * erfc((a - r) / b) - exp(r / l) * erfc((a + r) / b));
}

bool tx_heat_block(double half, int n, double** x, int* nodes, int** tet, int* ntet) {
  if (n < 2 || n > 400 || !(half > 0)) return tx_set_error("heat block: %d cells of half width %g m", n, half), false;
  int m = n + 1;
  *nodes = m * m * m, *ntet = 6 * n * n * n;
  *x = malloc(sizeof(double) * 3 * (size_t)*nodes);
  *tet = malloc(sizeof(int) * 4 * (size_t)*ntet);
  if (!*x || !*tet) {
    free(*x), free(*tet);
    *x = NULL, *tet = NULL;
    return tx_set_error("heat block: out of memory"), false;
  }
  double h = 2 * half / n;
  for (int k = 0; k < m; k++)
    for (int j = 0; j < m; j++)
      for (int i = 0; i < m; i++) {
        double* p = *x + 3 * ((size_t)(k * m + j) * m + i);
        p[0] = -half + i * h, p[1] = -half + j * h, p[2] = -half + k * h;
      }
  // Kuhn's six: from corner 000 to 111 along the axes in each order, so
  // that neighbouring cells share their faces' diagonals
  static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  int* t = *tet;
  for (int k = 0; k < n; k++)
    for (int j = 0; j < n; j++)
      for (int i = 0; i < n; i++)
        for (int p = 0; p < 6; p++) {
          int c[3] = {i, j, k};
          *t++ = (c[2] * m + c[1]) * m + c[0];
          for (int s = 0; s < 3; s++) {
            c[perm[p][s]]++;
            *t++ = (c[2] * m + c[1]) * m + c[0];
          }
        }
  return true;
}

tx_heat_case tx_heat_case_default(bool perfused) {
  tx_heat_case c = {.perfused = perfused,
                    .half_m = perfused ? 0.012 : 0.010,
                    .cells = 20,
                    .sigma_m = 0.0015,
                    .power_w = 0.5,
                    .t_end_s = perfused ? 600 : 10,
                    .r_eval_m = 0.006,
                    .tissue = tx_tissue_liver()};
  if (!perfused) c.tissue.perfusion = 0;
  return c;
}

static double exact(const tx_heat_case* c, double r) {
  const tx_tissue* t = &c->tissue;
  if (c->perfused) return tx_heat_gauss_perfused(r, c->power_w, c->sigma_m, t->k, sqrt(t->k / t->perfusion));
  return tx_heat_gauss_transient(r, c->t_end_s, c->power_w, c->sigma_m, t->k, t->k / (t->rho * t->c));
}

static double radius(const double* p) { return sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]); }

static double cpu_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

// the mesh and solver of a case; NULL and tx_error()
static tx_thermal* build(const tx_heat_case* c, double dt, double** x, int* n, int* nt) {
  int* tet = NULL;
  if (!tx_heat_block(c->half_m, c->cells, x, n, &tet, nt)) return NULL;
  tx_thermal* h = tx_thermal_create(*x, *n, tet, *nt, &c->tissue, NULL, dt);
  free(tet);
  if (!h) return free(*x), *x = NULL, NULL;
  double tol = 1e-9 * c->half_m;
  for (int i = 0; i < *n; i++) {
    const double* p = *x + 3 * i;
    if (fabs(fabs(p[0]) - c->half_m) < tol || fabs(fabs(p[1]) - c->half_m) < tol || fabs(fabs(p[2]) - c->half_m) < tol)
      tx_thermal_fix(h, i);
  }
  return h;
}

bool tx_heat_run(const tx_heat_case* c, bool keep, tx_heat_result* r) {
  memset(r, 0, sizeof *r);
  if (c->perfused && !(c->tissue.perfusion > 0)) return tx_set_error("heat: the perfused check needs a perfusion"), false;
  if (!(c->t_end_s > 0) || c->dt_s < 0 || !(c->r_eval_m > 0 && c->r_eval_m < c->half_m))
    return tx_set_error("heat: t_end, dt or r_eval out of range"), false;
  double t0 = cpu_now();
  // dt 0: one step of t_end, split by the solver into stable substeps
  int steps = c->dt_s > 0 ? (int)lround(c->t_end_s / c->dt_s) : 1;
  if (steps < 1) steps = 1;
  double *x = NULL;
  int n, nt;
  tx_thermal* h = build(c, c->t_end_s / steps, &x, &n, &nt);
  if (!h) return false;
  tx_thermal_source(h, (const double[3]){0, 0, 0}, c->sigma_m, c->power_w);
  for (int s = 0; s < steps; s++) tx_thermal_step(h);
  r->cpu_s = cpu_now() - t0;
  r->nodes = n, r->tets = nt, r->steps = steps * tx_thermal_substeps(h);
  r->h_m = 2 * c->half_m / c->cells, r->dt_s = c->t_end_s / r->steps;
  const double *t = tx_thermal_temperature(h), *v = tx_thermal_volume(h);
  double e2 = 0, x2 = 0, emax = 0, xmax = 0, ta = c->tissue.t_arterial;
  for (int i = 0; i < n; i++) {
    r->peak_k = fmax(r->peak_k, t[i] - ta);
    double rad = radius(x + 3 * i);
    if (rad > c->r_eval_m) continue;
    double ex = exact(c, rad), d = t[i] - ta - ex;
    e2 += v[i] * d * d, x2 += v[i] * ex * ex;
    emax = fmax(emax, fabs(d)), xmax = fmax(xmax, fabs(ex));
  }
  r->error = sqrt(e2 / x2), r->max_error = emax / xmax;
  if (keep) {
    r->theta = malloc(sizeof(double) * (size_t)n);
    if (r->theta)
      for (int i = 0; i < n; i++) r->theta[i] = t[i] - ta;
  }
  tx_thermal_destroy(h);
  free(x);
  if (keep && !r->theta) return tx_set_error("heat: out of memory"), false;
  return true;
}

double tx_heat_difference(const tx_heat_case* c, const double* a, const double* b) {
  double *x = NULL, *tmp = NULL;
  int n, nt, *tet = NULL;
  if (!tx_heat_block(c->half_m, c->cells, &x, &n, &tet, &nt)) return NAN;
  tx_thermal* h = tx_thermal_create(x, n, tet, nt, &c->tissue, NULL, 1); // for the nodal volumes
  free(tet), free(tmp);
  if (!h) return free(x), NAN;
  const double* v = tx_thermal_volume(h);
  double e2 = 0, x2 = 0;
  for (int i = 0; i < n; i++)
    if (radius(x + 3 * i) <= c->r_eval_m) e2 += v[i] * (a[i] - b[i]) * (a[i] - b[i]), x2 += v[i] * b[i] * b[i];
  tx_thermal_destroy(h);
  free(x);
  return sqrt(e2 / x2);
}
