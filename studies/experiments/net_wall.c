// The virtual wall across a network: the exact stability boundary of
// wall_stability.c's loop (tx_wall_run_delayed) with a round trip of n servo
// periods.
#include "net_wall.h"

#include "../../model/error.h"

#include <math.h>

// Schur-Cohn: every root of sum a[i] z^i (degree deg, a[deg] != 0) strictly
// inside the unit circle; a is overwritten
static bool schur_stable(double* a, int deg) {
  for (int d = deg; d > 0; d--) {
    double lead = a[d], tail = a[0];
    if (!(fabs(tail) < fabs(lead))) return false;
    // (lead p(z) - tail p*(z)) / z, scaled by its leading coefficient
    double b[TX_WALL_DELAY_MAX + 4];
    for (int k = 1; k <= d; k++) b[k - 1] = lead * a[k] - tail * a[d - k];
    double scale = b[d - 1];
    for (int k = 0; k < d; k++) a[k] = b[k] / scale;
  }
  return true;
}

bool tx_net_wall_exact_stable(const tx_sim_device* dev, double K, double B, int n) {
  const double *phi = dev->phi, *gam = dev->gam;
  double T = dev->def.period, kb = K + B / T, bt = B / T;
  // F applied at k: -(kb x(k-n) - bt x(k-n-1)); with (x, v)(k+1) = phi (x, v)(k) + gam F:
  // P(z) = z^(n+1) [(z - phi0)(z - phi3) - phi1 phi2] + (kb z - bt) [gam0 (z - phi3) + phi1 gam1]
  double a[TX_WALL_DELAY_MAX + 4] = {0};
  int deg = n + 3;
  a[n + 3] += 1;
  a[n + 2] += -(phi[0] + phi[3]);
  a[n + 1] += phi[0] * phi[3] - phi[1] * phi[2];
  double c1 = gam[0], c0 = -gam[0] * phi[3] + phi[1] * gam[1]; // gam0 z + c0
  a[2] += kb * c1;
  a[1] += kb * c0 - bt * c1;
  a[0] += -bt * c0;
  return schur_stable(a, deg);
}

double tx_net_wall_exact_bound(const tx_sim_device_def* d, double B, int delay_ticks) {
  tx_sim_device dev;
  if (delay_ticks < 0 || delay_ticks > TX_WALL_DELAY_MAX)
    return tx_set_error("network wall: delay of %d periods, must be in [0, %d]", delay_ticks, TX_WALL_DELAY_MAX), NAN;
  if (!isfinite(B) || !tx_sim_device_init(&dev, d)) return NAN;
  double lo = 0, hi = 1e-3;
  while (hi <= 1e12 && tx_net_wall_exact_stable(&dev, hi, B, delay_ticks)) lo = hi, hi *= 2;
  if (lo == 0 || hi > 1e12) return lo;
  while (hi - lo > 1e-9 * hi) {
    double mid = 0.5 * (lo + hi);
    if (tx_net_wall_exact_stable(&dev, mid, B, delay_ticks)) lo = mid;
    else hi = mid;
  }
  return lo;
}
