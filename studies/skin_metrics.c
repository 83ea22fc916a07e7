// The skin-paper metrics, from one run's ticks.
#include "skin_metrics.h"

#include <math.h>

// least squares of y on x over [a, b): slope and R^2
static void fit(const double* x, const double* y, int a, int b, double* slope, double* r2) {
  double n = b - a, sx = 0, sy = 0;
  for (int i = a; i < b; i++) sx += x[i], sy += y[i];
  double mx = sx / n, my = sy / n, sxx = 0, sxy = 0, syy = 0;
  for (int i = a; i < b; i++) {
    double dx = x[i] - mx, dy = y[i] - my;
    sxx += dx * dx, sxy += dx * dy, syy += dy * dy;
  }
  *slope = sxx > 0 ? sxy / sxx : NAN;
  *r2 = sxx > 0 && syy > 0 ? sxy * sxy / (sxx * syy) : NAN;
}

tx_skin_metrics tx_skin_measure(const tx_skin_series* s, double steady_from, double steady_to) {
  tx_skin_metrics m = {-1, -1, NAN, 0, NAN, NAN, NAN, 0, NAN, NAN, NAN};
  for (int i = 0; i < s->n && m.contact < 0; i++)
    if (s->contacts[i] > 0) m.contact = i;
  if (m.contact >= 0) {
    m.contact_pos = s->pos[m.contact];
    // through the skin, or out of contact once links have torn: the hole opened under the HIP
    for (int i = m.contact; i < s->n && m.rupture < 0; i++)
      if (s->pierced[i] > 0 || (s->contacts[i] == 0 && s->torn[i] > s->torn[m.contact])) m.rupture = i;
    int end = m.rupture >= 0 ? m.rupture : s->n;
    // the pushed phase: contact .. rupture
    for (int i = m.contact; i < end; i++)
      if (fabs(s->force[i]) > m.peak) m.peak = fabs(s->force[i]);
    if (end - m.contact >= 3) fit(s->pos, s->force, m.contact, end, &m.slope, &m.r2);
    for (int i = m.contact; i + 1 < end; i++) {
      double d = fabs(s->force[i + 1] - s->force[i]);
      if (d > m.max_step) m.max_step = d;
    }
    double sum = 0;
    int k = 0;
    for (int i = m.contact + 1; i + 1 < end; i++) {
      if (s->tangent && (s->t[i] < steady_from || s->t[i] > steady_to)) continue; // a slide: its steady part
      double d2 = s->force[i + 1] - 2 * s->force[i] + s->force[i - 1];
      sum += d2 * d2, k++;
    }
    if (k > 0 && m.peak > 0) m.roughness = sqrt(sum / k) / m.peak;
    // back to zero: the first zero-force tick from rupture on, against the skin publish it was computed on
    if (m.rupture >= 0) {
      for (int i = m.rupture > 0 ? m.rupture - 1 : 0; i < s->n; i++)
        if (s->force[i] == 0) {
          m.zero_after_s = s->t[i] - s->skin_t[i];
          break;
        }
    }
  }
  // sliding: means over 0.5 s windows of the steady part
  if (s->tangent) {
    double means[64], total = 0;
    int w = 0;
    for (double a = steady_from; a + 0.5 <= steady_to + 1e-9 && w < 64; a += 0.5) {
      double sum = 0;
      int k = 0;
      for (int i = 0; i < s->n; i++)
        if (s->t[i] >= a && s->t[i] < a + 0.5) sum += s->tangent[i], k++;
      if (k > 0) means[w++] = sum / k, total += sum / k;
    }
    if (w > 0) {
      m.tangent_mean = total / w;
      double var = 0;
      for (int i = 0; i < w; i++) var += (means[i] - m.tangent_mean) * (means[i] - m.tangent_mean);
      m.tangent_cv = w > 1 ? sqrt(var / (w - 1)) / fabs(m.tangent_mean) : 0;
    }
  }
  return m;
}

tx_convergence tx_converge(const double* q, int n, double ratio, double* err) {
  tx_convergence c = {TX_CONV_MISSING, NAN, NAN, false};
  for (int i = 0; err && i < n; i++) err[i] = NAN;
  bool all = n >= 3 && ratio > 1;
  for (int i = 0; all && i < n; i++) all = isfinite(q[i]);
  if (!all) return c;
  double d1 = q[n - 2] - q[n - 3], d2 = q[n - 1] - q[n - 2];
  // a step within rounding of the values is no step (a quantity fixed by construction)
  double tiny = 1e-9 * fmax(fabs(q[n - 1]), fmax(fabs(q[n - 2]), fabs(q[n - 3])));
  if (fabs(d1) <= tiny) d1 = 0;
  if (fabs(d2) <= tiny) d2 = 0;
  c.reference = q[n - 1];
  if (d1 == 0 && d2 == 0) c.status = TX_CONV_CONSTANT;
  else if (d1 * d2 <= 0) c.status = TX_CONV_OSCILLATING;
  else {
    c.p = log(d1 / d2) / log(ratio);
    c.status = c.p >= 0.5 ? TX_CONV_CONVERGING : c.p > 0 ? TX_CONV_SLOW : TX_CONV_DIVERGING;
    if (c.status == TX_CONV_CONVERGING) c.reference = q[n - 1] + d2 / (pow(ratio, c.p) - 1);
  }
  // the error at each level, and whether it falls at every refinement
  c.monotone = c.status == TX_CONV_CONVERGING && c.reference != 0;
  double prev = INFINITY;
  for (int i = 0; i < n; i++) {
    double e = c.reference != 0 ? fabs(q[i] - c.reference) / fabs(c.reference) : NAN;
    if (err) err[i] = e;
    if (!(e < prev)) c.monotone = false;
    prev = e;
  }
  return c;
}

const char* tx_conv_status_name(tx_conv_status s) {
  static const char* const names[] = {"converging", "constant", "oscillating", "diverging", "missing", "slow"};
  return (unsigned)s < sizeof names / sizeof names[0] ? names[s] : "?";
}
