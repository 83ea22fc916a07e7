// The virtual wall across a network: wall_stability.c's loop with the wall
// computed on the other side of a link and a round trip of n servo periods.
#include "net_wall.h"

#include "../../controllers/haptics/passivity.h"
#include "../../controllers/haptics/safety.h"

#include "../../model/error.h"

#include <math.h>
#include <string.h>

#define WINDOWS 8 // energy windows per run, as wall_stability.c

void tx_net_wall_force(double K, double B, double x, double v, double* force, double* stored) {
  if (x > 0) {
    double spring[9] = {-K, 0, 0, 0, 0, 0, 0, 0, 0}; // the wall as a force model publishes it: -K n n^T
    double fs[3] = {-K * x, 0, 0};
    *force = fs[0] - B * v;
    *stored = tx_spring_energy(spring, fs);
  } else {
    *force = 0;
    *stored = 0;
  }
}

bool tx_net_wall_run(const tx_wall_case* c, int delay_ticks, const tx_net_wall_link* link, tx_wall_result* out) {
  if (tx_wall_case_check(c)) return false;
  if (delay_ticks < 0 || delay_ticks > TX_NET_WALL_DELAY_MAX)
    return tx_set_error("network wall: delay of %d periods, must be in [0, %d]", delay_ticks, TX_NET_WALL_DELAY_MAX), false;
  tx_sim_device dev;
  if (!tx_sim_device_init(&dev, &c->device)) return false;
  double K = c->stiffness, B = c->damping, T = c->device.period, m = c->device.mass;
  double kh = c->device.hand_stiffness, keff = K + kh;
  double x_eq = c->push_force / K;
  double v0 = c->kick * x_eq * sqrt(keff / m);
  double e0 = 0.5 * m * v0 * v0;
  const double spring[9] = {-K, 0, 0, 0, 0, 0, 0, 0, 0};

  // as tx_wall_run: pressed in with push_force, moving inward
  tx_sim_device_reset(&dev, (double[3]){x_eq, 0, 0}, (double[3]){v0, 0, 0});
  tx_sim_device_place_hand(&dev, (double[3]){x_eq + c->push_force / kh, 0, 0});
  tx_device_info info;
  tx_sim_device_info(&dev, &info);
  tx_safety_limits limits = tx_safety_limits_from_device(&info);
  tx_haptic_path path;
  tx_haptic_path_init(&path, &limits, c->passivity != TX_WALL_PC_OFF,
                      c->passivity == TX_WALL_PC_SPRING ? TX_PASSIVITY_REF_SPRING : TX_PASSIVITY_REF_PORT, info.damping);
  double x_before = dev.state.pos[0] - dev.state.vel[0] * T;
  double stored0 = tx_spring_energy(spring, (double[3]){x_before > 0 ? -K * x_before : 0, 0, 0});
  path.passivity.energy = path.passivity.min_energy = stored0;
  path.stored = stored0;
  path.reference_energy = path.reference_min = c->passivity == TX_WALL_PC_SPRING ? 0 : stored0;
  path.held[0] = path.safety.last[0] = dev.state.pos[0] > 0 ? -K * dev.state.pos[0] : 0;

  // the answers in flight: slot k % (n + 1) holds the one computed from tick k
  double line_f[TX_NET_WALL_DELAY_MAX + 1], line_e[TX_NET_WALL_DELAY_MAX + 1];
  int slots = delay_ticks + 1;
  for (int i = 0; i < slots; i++) tx_net_wall_force(K, 0, x_eq, 0, &line_f[i], &line_e[i]); // the wall at rest

  uint64_t n = (uint64_t)llround(c->duration / T);
  uint64_t per_window = n / WINDOWS;
  double window_sum[WINDOWS] = {0};
  double depth_max = x_eq;
  uint64_t outside = 0;
  for (uint64_t k = 0; k < n; k++) {
    const tx_device_state* s = &dev.state;
    double f_k, e_k;
    if (link) {
      if (link->exchange(link->user, k, K, B, s->pos[0], s->vel[0], &f_k, &e_k)) return false;
    } else {
      tx_net_wall_force(K, B, s->pos[0], s->vel[0], &f_k, &e_k);
    }
    line_f[k % (uint64_t)slots] = f_k, line_e[k % (uint64_t)slots] = e_k;
    // what arrives now was computed n ticks ago (with n = 0, this tick's: tx_wall_run)
    uint64_t j = (k + 1) % (uint64_t)slots;
    tx_haptic_input in = {{line_f[j], 0, 0}, line_e[j], false, 0, 0};
    double f[3];
    tx_haptic_tick(&path, T, &in, s->pos, s->vel, f);
    tx_sim_device_step(&dev, f, NULL);

    double dx = dev.x[0] - x_eq;
    double energy = 0.5 * m * dev.v[0] * dev.v[0] + 0.5 * keff * dx * dx;
    uint64_t w = per_window ? k / per_window : 0;
    if (w < WINDOWS) window_sum[w] += energy;
    if (dev.x[0] > depth_max) depth_max = dev.x[0];
    if (dev.x[0] <= 0) outside++;
  }
  double last = (window_sum[WINDOWS - 2] + window_sum[WINDOWS - 1]) / (2.0 * (double)per_window);
  double st = 0, sy = 0, stt = 0, sty = 0;
  for (int w = 0; w < WINDOWS; w++) {
    double t = ((double)w + 0.5) * (double)per_window * T;
    double y = log(window_sum[w] / (double)per_window + 1e-300);
    st += t, sy += y, stt += t * t, sty += t * y;
  }
  *out = (tx_wall_result){
      .stable = last < e0,
      .energy_start = e0,
      .energy_end = last,
      .growth_rate = (WINDOWS * sty - st * sy) / (WINDOWS * stt - st * st),
      .depth_rest = x_eq,
      .depth_max = depth_max,
      .outside_s = (double)outside * T,
      .observed_min = path.reference_min,
      .control_ticks = path.passivity.activations,
      .clamped_ticks = path.safety.counts.clamped + dev.clamped,
      .rate_limited_ticks = path.safety.counts.rate_limited,
  };
  return true;
}

tx_wall_search tx_net_wall_largest_stable(const tx_wall_case* c, int delay_ticks, double k_lo, double k_hi, double rel_tol) {
  tx_wall_search s = {.k = k_lo};
  tx_wall_case t = *c;
  tx_wall_result r;
  if (!(k_lo > 0 && k_hi >= k_lo && k_hi <= 1e7 && rel_tol > 0)) {
    tx_set_error("network wall search: need 0 < k_lo <= k_hi <= 1e7 N/m and rel_tol > 0, got %g, %g, %g", k_lo, k_hi, rel_tol);
    s.lo_unstable = true;
    return s;
  }
  double stable = 0, unstable = 0;
  for (double k = k_lo;; k *= 1.25) { // a sweep first: a limit cycle can make a stiffer wall look stable again
    if (k > k_hi) k = k_hi;
    t.stiffness = k;
    if (!tx_net_wall_run(&t, delay_ticks, NULL, &r)) return s.lo_unstable = true, s;
    s.cases++;
    if (!r.stable) {
      unstable = k;
      break;
    }
    stable = k;
    if (k >= k_hi) break;
  }
  if (stable == 0) return s.lo_unstable = true, s.k_unstable = unstable, s;
  if (unstable == 0) return s.k = stable, s.hi_stable = true, s;
  while (unstable / stable - 1 > rel_tol) {
    t.stiffness = sqrt(stable * unstable);
    if (!tx_net_wall_run(&t, delay_ticks, NULL, &r)) break;
    s.cases++;
    if (r.stable) stable = t.stiffness;
    else unstable = t.stiffness;
  }
  s.k = stable;
  s.k_unstable = unstable;
  return s;
}

// Schur-Cohn: every root of sum a[i] z^i (degree deg, a[deg] != 0) strictly
// inside the unit circle; a is overwritten
static bool schur_stable(double* a, int deg) {
  for (int d = deg; d > 0; d--) {
    double lead = a[d], tail = a[0];
    if (!(fabs(tail) < fabs(lead))) return false;
    // (lead p(z) - tail p*(z)) / z, scaled by its leading coefficient
    double b[TX_NET_WALL_DELAY_MAX + 4];
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
  double a[TX_NET_WALL_DELAY_MAX + 4] = {0};
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
  if (delay_ticks < 0 || delay_ticks > TX_NET_WALL_DELAY_MAX)
    return tx_set_error("network wall: delay of %d periods, must be in [0, %d]", delay_ticks, TX_NET_WALL_DELAY_MAX), NAN;
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
