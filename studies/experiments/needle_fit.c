// Fitting the voxel model to a recording: replay, RMS, Nelder-Mead.
#include "needle_fit.h"

#include "../../controllers/voxel/guard.h"

#include "../../model/error.h"

#include <tactus/model.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double spacing = 0.5e-3; // m, the fit's block: 5 mm over 10 voxels

tx_needle_fit_params tx_needle_fit_params_default(void) {
  return (tx_needle_fit_params){.spring = 20, .damping_ratio = 0.6, .radius = 0.2e-3, .mass = 1e-4,
                                .elasticity = 0.5, .damage_shrink = 0.5, .rupture_force = 0.3,
                                .cutting_force = 0.05, .friction = 0.3};
}

void tx_needle_fit_defs(const tx_needle_fit_params* p, tx_voxel_tissue_def* t, tx_voxel_needle_def* n) {
  *t = tx_voxel_tissue_def_default();
  for (int a = 0; a < 3; a++) t->block_size[a] = 10 * spacing, t->count[a] = 10;
  t->origin[0] = t->origin[2] = -5 * spacing;
  t->origin[1] = -10 * spacing; // top face at y = 0
  t->spring = p->spring;
  t->mass = p->mass;
  t->damper = 2 * p->damping_ratio * sqrt(p->spring * p->mass);
  t->radius = p->radius;
  t->elasticity = p->elasticity;
  t->damage_shrink = p->damage_shrink;
  t->skin = 0.2e-3;
  *n = tx_voxel_needle_def_default();
  n->rupture_force = p->rupture_force;
  n->cutting_force = p->cutting_force;
  n->friction = p->friction;
}

double tx_needle_fit_simulate(const tx_needle_fit_params* p, const tx_recording* rec, double* f) {
  tx_voxel_tissue_def td;
  tx_voxel_needle_def nd;
  tx_needle_fit_defs(p, &td, &nd);
  tx_voxel_tissue t;
  tx_voxel_needle n;
  tx_voxel_guard g;
  if (!tx_voxel_tissue_init(&t, &td)) return -1;
  if (!tx_voxel_needle_init(&n, &nd, &t)) return tx_voxel_tissue_fini(&t), -1;
  if (!tx_voxel_guard_init(&g, &t, 100)) return tx_voxel_needle_fini(&n), tx_voxel_tissue_fini(&t), -1;
  const double q[4] = {1, 0, 0, 0};
  double sum = 0;
  for (size_t k = 0; k < rec->count; k++) {
    const tx_recording_row* r = &rec->rows[k];
    double tip[3] = {0, -r->depth, 0};
    double dt = k ? r->t - rec->rows[k - 1].t : 1e-3;
    if (!tx_voxel_needle_step(&n, &t, tip, q, dt)) {
      sum = NAN;
      break;
    }
    tx_voxel_guard_check(&g, &t, &n);
    for (int a = 0; a < 3; a++) {
      double d = n.force[a] - r->f[a];
      if (f) f[3 * k + a] = n.force[a];
      sum += d * d;
    }
  }
  tx_voxel_guard_fini(&g);
  tx_voxel_needle_fini(&n);
  tx_voxel_tissue_fini(&t);
  if (!isfinite(sum)) return tx_set_error("needle fit: the replay failed"), -1;
  return sqrt(sum / (double)rec->count);
}

// ---------------------------------------------------------------------------
// transformed coordinates: every x maps to a valid parameter set

static double logit(double v, double lo, double hi) { return log((v - lo) / (hi - v)); }
static double logistic(double x, double lo, double hi) { return lo + (hi - lo) / (1 + exp(-x)); }

static void to_x(const tx_needle_fit_params* p, double x[TX_NEEDLE_FIT_PARAMS]) {
  x[0] = log(p->spring);
  x[1] = logit(p->damping_ratio, 0, 4);
  x[2] = logit(p->radius, 0.15 * spacing, 0.5 * spacing);
  x[3] = log(p->mass);
  x[4] = logit(p->elasticity, 0, 1);
  x[5] = logit(p->damage_shrink, 0, 0.95);
  x[6] = log(p->rupture_force);
  x[7] = log(p->cutting_force);
  x[8] = log(p->friction);
}

static void from_x(const double x[TX_NEEDLE_FIT_PARAMS], tx_needle_fit_params* p) {
  // bounded so that a wild trial stays a simulation, not an overflow
  p->spring = exp(fmin(fmax(x[0], log(1e-3)), log(1e5)));
  p->damping_ratio = logistic(x[1], 0, 4);
  p->radius = logistic(x[2], 0.15 * spacing, 0.5 * spacing);
  p->mass = exp(fmin(fmax(x[3], log(1e-9)), log(1e-1)));
  p->elasticity = logistic(x[4], 0, 1);
  p->damage_shrink = logistic(x[5], 0, 0.95);
  p->rupture_force = exp(fmin(fmax(x[6], log(1e-6)), log(1e3)));
  p->cutting_force = exp(fmin(fmax(x[7], log(1e-6)), log(1e3)));
  p->friction = exp(fmin(fmax(x[8], log(1e-4)), log(10)));
}

typedef struct search {
  const tx_recording* rec;
  int evals, max_evals;
  double best;
  double best_x[TX_NEEDLE_FIT_PARAMS];
  int64_t t0;
  tx_needle_fit_progress cb;
  void* user;
} search;

static double cost(search* s, const double x[TX_NEEDLE_FIT_PARAMS]) {
  tx_needle_fit_params p;
  from_x(x, &p);
  double rms = tx_needle_fit_simulate(&p, s->rec, NULL);
  if (rms < 0) rms = INFINITY; // a trial that cannot run is the worst
  s->evals++;
  if (rms < s->best) {
    s->best = rms;
    memcpy(s->best_x, x, sizeof s->best_x);
  }
  if (s->cb) s->cb(s->evals, (double)(tx_mono_ns() - s->t0) * 1e-9, s->best, s->user);
  return rms;
}

bool tx_needle_fit(const tx_recording* rec, tx_needle_fit_params* p, int max_evals, tx_needle_fit_progress cb,
                   void* user, tx_needle_fit_result* out) {
  enum { N = TX_NEEDLE_FIT_PARAMS };
  if (rec->count < 2) return tx_set_error("needle fit: the recording has fewer than 2 rows"), false;
  if (max_evals < N + 1) return tx_set_error("needle fit: at least %d evaluations", N + 1), false;
  search s = {rec, 0, max_evals, INFINITY, {0}, tx_mono_ns(), cb, user};
  double simplex[N + 1][N], fv[N + 1];
  to_x(p, simplex[0]);
  for (int a = 0; a < N; a++) {
    if (!isfinite(simplex[0][a])) return tx_set_error("needle fit: a starting parameter is out of its range"), false;
  }
  fv[0] = cost(&s, simplex[0]);
  // the first simplex: each coordinate moved by 0.5 (a factor of 1.65 for the logarithms)
  for (int i = 1; i <= N; i++) {
    memcpy(simplex[i], simplex[0], sizeof simplex[0]);
    simplex[i][i - 1] += 0.5;
    fv[i] = cost(&s, simplex[i]);
  }
  // Nelder-Mead with the standard coefficients (reflect 1, expand 2, contract 1/2, shrink 1/2)
  while (s.evals < max_evals) {
    // order: best first
    for (int i = 1; i <= N; i++)
      for (int j = i; j > 0 && fv[j] < fv[j - 1]; j--) {
        double tf = fv[j];
        fv[j] = fv[j - 1], fv[j - 1] = tf;
        double tx[N];
        memcpy(tx, simplex[j], sizeof tx);
        memcpy(simplex[j], simplex[j - 1], sizeof tx);
        memcpy(simplex[j - 1], tx, sizeof tx);
      }
    if (fv[N] - fv[0] <= 1e-6 * fv[0]) break; // flat: converged
    double c[N] = {0}, xr[N], xe[N], xc[N];
    for (int i = 0; i < N; i++)
      for (int a = 0; a < N; a++) c[a] += simplex[i][a] / N;
    for (int a = 0; a < N; a++) xr[a] = c[a] + (c[a] - simplex[N][a]);
    double fr = cost(&s, xr);
    if (fr < fv[0]) {
      for (int a = 0; a < N; a++) xe[a] = c[a] + 2 * (c[a] - simplex[N][a]);
      double fe = s.evals < max_evals ? cost(&s, xe) : INFINITY;
      if (fe < fr) memcpy(simplex[N], xe, sizeof xe), fv[N] = fe;
      else memcpy(simplex[N], xr, sizeof xr), fv[N] = fr;
    } else if (fr < fv[N - 1]) {
      memcpy(simplex[N], xr, sizeof xr), fv[N] = fr;
    } else {
      bool outside = fr < fv[N];
      for (int a = 0; a < N; a++) xc[a] = outside ? c[a] + 0.5 * (xr[a] - c[a]) : c[a] + 0.5 * (simplex[N][a] - c[a]);
      double fc = s.evals < max_evals ? cost(&s, xc) : INFINITY;
      if (fc < (outside ? fr : fv[N])) {
        memcpy(simplex[N], xc, sizeof xc), fv[N] = fc;
      } else {
        for (int i = 1; i <= N && s.evals < max_evals; i++) {
          for (int a = 0; a < N; a++) simplex[i][a] = simplex[0][a] + 0.5 * (simplex[i][a] - simplex[0][a]);
          fv[i] = cost(&s, simplex[i]);
        }
      }
    }
  }
  if (!isfinite(s.best)) return tx_set_error("needle fit: no trial could be simulated"), false;
  from_x(s.best_x, p);
  out->rms = s.best;
  out->evaluations = s.evals;
  out->seconds = (double)(tx_mono_ns() - s.t0) * 1e-9;
  out->peak = 0;
  for (size_t k = 0; k < rec->count; k++) {
    const double* f = rec->rows[k].f;
    out->peak = fmax(out->peak, sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
  }
  return true;
}
