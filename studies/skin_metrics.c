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
