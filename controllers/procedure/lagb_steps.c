// Phases 2 and 3 of gastric banding as steps (lagb_steps.h).
#include "lagb_steps.h"

#include <math.h>

static const char* const ids[TX_LAGB_STEPS] = {"2a", "2b", "2c", "3a", "3b", "3c"};
static const char* const names[TX_LAGB_STEPS] = {
    "retract the liver",
    "divide the pars flaccida",
    "open a window at the angle of His",
    "pass a grasper behind the stomach",
    "pull the band around",
    "lock the band",
};
// bit j of after[i]: step i comes after step j
static const unsigned after[TX_LAGB_STEPS] = {
    0,
    1u << TX_LAGB_RETRACT,
    1u << TX_LAGB_RETRACT,
    (1u << TX_LAGB_PARS) | (1u << TX_LAGB_HIS),
    1u << TX_LAGB_BEHIND,
    1u << TX_LAGB_AROUND,
};

const char* tx_lagb_step_id(int step) { return step >= 0 && step < TX_LAGB_STEPS ? ids[step] : "?"; }
const char* tx_lagb_step_name(int step) { return step >= 0 && step < TX_LAGB_STEPS ? names[step] : "?"; }

bool tx_lagb_steps_ended(const tx_lagb_steps* s, int step) {
  return s->step[step].status == TX_STEP_DONE || s->step[step].status == TX_STEP_SKIPPED;
}

// the steps whose predecessors have all ended begin at t
static void begin_ready(tx_lagb_steps* s, double t) {
  for (int i = 0; i < TX_LAGB_STEPS; i++) {
    if (s->step[i].status != TX_STEP_NOT_REACHED) continue;
    bool ready = true;
    for (int j = 0; j < TX_LAGB_STEPS; j++)
      if ((after[i] >> j & 1u) && !tx_lagb_steps_ended(s, j)) ready = false;
    if (ready) s->step[i] = (tx_procedure_step_state){TX_STEP_UNDER_WAY, t, NAN};
  }
}

void tx_lagb_steps_start(tx_lagb_steps* s, double t) {
  for (int i = 0; i < TX_LAGB_STEPS; i++) s->step[i] = (tx_procedure_step_state){TX_STEP_NOT_REACHED, NAN, NAN};
  begin_ready(s, t);
}

// the steps `step` comes after, directly or not, that have not ended: skipped
static void skip_before(tx_lagb_steps* s, int step, double t) {
  for (int j = 0; j < TX_LAGB_STEPS; j++) {
    if (!(after[step] >> j & 1u)) continue;
    skip_before(s, j, t);
    if (tx_lagb_steps_ended(s, j)) continue;
    if (isnan(s->step[j].t_start_s)) s->step[j].t_start_s = t;
    s->step[j].status = TX_STEP_SKIPPED, s->step[j].t_end_s = t;
  }
}

bool tx_lagb_steps_done_at(tx_lagb_steps* s, int step, double t) {
  if (step < 0 || step >= TX_LAGB_STEPS || tx_lagb_steps_ended(s, step)) return false;
  skip_before(s, step, t);
  if (isnan(s->step[step].t_start_s)) s->step[step].t_start_s = t;
  s->step[step].status = TX_STEP_DONE, s->step[step].t_end_s = t;
  begin_ready(s, t);
  return true;
}

int tx_lagb_steps_current(const tx_lagb_steps* s) {
  for (int i = 0; i < TX_LAGB_STEPS; i++)
    if (s->step[i].status == TX_STEP_UNDER_WAY) return i;
  return TX_LAGB_STEPS;
}

int tx_lagb_steps_done(const tx_lagb_steps* s) {
  int n = 0;
  for (int i = 0; i < TX_LAGB_STEPS; i++) n += s->step[i].status == TX_STEP_DONE;
  return n;
}

static void sub3(const double a[3], const double b[3], double o[3]) { o[0] = a[0] - b[0], o[1] = a[1] - b[1], o[2] = a[2] - b[2]; }
static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void cross3(const double a[3], const double b[3], double o[3]) {
  o[0] = a[1] * b[2] - a[2] * b[1], o[1] = a[2] * b[0] - a[0] * b[2], o[2] = a[0] * b[1] - a[1] * b[0];
}

// +1 or -1 when segment pq crosses triangle abc (the sign of pq along the
// triangle's normal), 0 when it misses (Moller and Trumbore's test)
static int crossing(const double p[3], const double q[3], const double a[3], const double b[3], const double c[3]) {
  double d[3], e1[3], e2[3], h[3], s[3], qv[3];
  sub3(q, p, d), sub3(b, a, e1), sub3(c, a, e2);
  cross3(d, e2, h);
  double det = dot3(e1, h);
  if (fabs(det) < 1e-18) return 0;
  sub3(p, a, s);
  double u = dot3(s, h) / det;
  if (u < 0 || u > 1) return 0;
  cross3(s, e1, qv);
  double v = dot3(d, qv) / det;
  if (v < 0 || u + v > 1) return 0;
  double t = dot3(e2, qv) / det;
  if (t < 0 || t >= 1) return 0; // [0, 1): a crossing at a joint of the polyline counts once
  return det < 0 ? 1 : -1; // det = -(q - p) . (e1 x e2): the right-hand rule
}

int tx_lagb_linking(const float* loop, int n, const double* axis, int m) {
  if (n < 3 || m < 2) return 0;
  double o[3] = {0, 0, 0};
  for (int i = 0; i < n; i++)
    for (int a = 0; a < 3; a++) o[a] += loop[3 * i + a] / n;
  int sum = 0;
  for (int i = 0; i < n; i++) {
    const float *fa = loop + 3 * i, *fb = loop + 3 * ((i + 1) % n);
    const double a[3] = {fa[0], fa[1], fa[2]}, b[3] = {fb[0], fb[1], fb[2]};
    for (int j = 0; j + 1 < m; j++) sum += crossing(axis + 3 * j, axis + 3 * (j + 1), o, a, b);
  }
  return sum;
}

double tx_lagb_along(const double* axis, int m, const double p[3], double* off) {
  double best = INFINITY, at = 0, run = 0;
  for (int j = 0; j + 1 < m; j++) {
    const double *a = axis + 3 * j, *b = axis + 3 * (j + 1);
    double ab[3], ap[3];
    sub3(b, a, ab), sub3(p, a, ap);
    double l2 = dot3(ab, ab), len = sqrt(l2);
    double t = l2 > 0 ? fmin(fmax(dot3(ap, ab) / l2, 0), 1) : 0;
    double d[3] = {ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]};
    double d2 = dot3(d, d);
    if (d2 < best) best = d2, at = run + t * len;
    run += len;
  }
  if (off) *off = m >= 2 ? sqrt(best) : NAN;
  return m >= 2 ? at : NAN;
}
