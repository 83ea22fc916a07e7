// Virtual-wall stability experiment on the simulated device.
#include "wall_stability.h"

#include "../../controllers/haptics/passivity.h"
#include "../../controllers/haptics/safety.h"

#include "../../model/error.h"

#include <math.h>
#include <stdio.h>

#define WINDOWS 8 // energy windows per run: the last two are the last quarter

tx_wall_case tx_wall_case_default(void) {
  tx_wall_case c = {
      .device = tx_sim_device_def_default(),
      .stiffness = 500,
      .damping = 0,
      .passivity = TX_WALL_PC_OFF,
      .push_force = 1,
      .kick = 0.25,
      .duration = 10,
  };
  // a soft spring that holds the device in the wall, and no damping of its
  // own, so that what is measured is the device's stability, not the hand's
  c.device.hand_stiffness = 20;
  c.device.hand_damping = 0;
  return c;
}

int tx_wall_case_check(const tx_wall_case* c) {
  if (tx_sim_device_def_check(&c->device)) return -1;
  const char* name = NULL;
  double v = 0;
  const char* rule = "";
  if (c->passivity != TX_WALL_PC_OFF && c->passivity != TX_WALL_PC_PORT && c->passivity != TX_WALL_PC_SPRING)
    name = "passivity", v = c->passivity, rule = "must be TX_WALL_PC_OFF, _PORT or _SPRING";
  else if (!(isfinite(c->stiffness) && c->stiffness > 0 && c->stiffness <= 1e7))
    name = "stiffness", v = c->stiffness, rule = "N/m, must be in (0, 1e7]";
  else if (!(isfinite(c->damping) && c->damping >= -1e3 && c->damping <= 1e3))
    name = "damping", v = c->damping, rule = "N s/m, must be in [-1e3, 1e3]";
  else if (!(isfinite(c->push_force) && c->push_force > 0 && c->push_force < c->device.max_force))
    name = "push_force", v = c->push_force, rule = "N, must be in (0, device max_force)";
  else if (!(c->device.hand_stiffness > 0))
    name = "device.hand_stiffness", v = c->device.hand_stiffness, rule = "N/m, must be > 0: the hand holds the device in the wall";
  else if (!(isfinite(c->kick) && c->kick > 0 && c->kick < 1))
    name = "kick", v = c->kick, rule = "must be in (0, 1): the device starts inside the wall";
  else if (!(isfinite(c->duration) && c->duration >= 8 * c->device.period && c->duration <= 1e3))
    name = "duration", v = c->duration, rule = "s, must be in [8 periods, 1000]";
  if (!name) return 0;
  tx_set_error("wall case: %s = %g %s", name, v, rule);
  return -1;
}

void tx_wall_force(double K, double B, double x, double v, double* force, double* stored) {
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

bool tx_wall_run_delayed(const tx_wall_case* c, int delay_ticks, const tx_wall_link* link, tx_wall_result* out) {
  if (tx_wall_case_check(c)) return false;
  if (delay_ticks < 0 || delay_ticks > TX_WALL_DELAY_MAX)
    return tx_set_error("wall: delay of %d periods, must be in [0, %d]", delay_ticks, TX_WALL_DELAY_MAX), false;
  tx_sim_device dev;
  if (!tx_sim_device_init(&dev, &c->device)) return false;
  double K = c->stiffness, B = c->damping, T = c->device.period, m = c->device.mass;
  double kh = c->device.hand_stiffness;
  double keff = K + kh; // stiffness of the oscillation about the resting depth
  double x_eq = c->push_force / K;
  double v0 = c->kick * x_eq * sqrt(keff / m);
  double e0 = 0.5 * m * v0 * v0;
  const double spring[9] = {-K, 0, 0, 0, 0, 0, 0, 0, 0}; // the wall as a force model publishes it: -K n n^T

  // start at rest depth moving inward; the hand's spring pushes with push_force there
  tx_sim_device_reset(&dev, (double[3]){x_eq, 0, 0}, (double[3]){v0, 0, 0});
  tx_sim_device_place_hand(&dev, (double[3]){x_eq + c->push_force / kh, 0, 0});
  // the force path of the haptics controller, with the limits it would take
  // from this device
  tx_device_info info;
  tx_sim_device_info(&dev, &info);
  tx_safety_limits limits = tx_safety_limits_from_device(&info);
  tx_haptic_path path;
  tx_haptic_path_init(&path, &limits, c->passivity != TX_WALL_PC_OFF,
                      c->passivity == TX_WALL_PC_SPRING ? TX_PASSIVITY_REF_SPRING : TX_PASSIVITY_REF_PORT, info.damping);
  // as if the device had been pressed in from outside: the port has absorbed
  // the spring's store (the reading one period before the start gives it),
  // and the wall's force at the start was held over the period before
  double x_before = dev.state.pos[0] - dev.state.vel[0] * T;
  double stored0 = tx_spring_energy(spring, (double[3]){x_before > 0 ? -K * x_before : 0, 0, 0});
  path.passivity.energy = path.passivity.min_energy = stored0;
  path.stored = stored0;
  path.reference_energy = path.reference_min = c->passivity == TX_WALL_PC_SPRING ? 0 : stored0;
  path.held[0] = path.safety.last[0] = dev.state.pos[0] > 0 ? -K * dev.state.pos[0] : 0;

  // the answers in flight: slot k % (n + 1) holds the one computed from tick k
  double line_f[TX_WALL_DELAY_MAX + 1], line_e[TX_WALL_DELAY_MAX + 1];
  int slots = delay_ticks + 1;
  for (int i = 0; i < slots; i++) tx_wall_force(K, 0, x_eq, 0, &line_f[i], &line_e[i]); // the wall at rest

  uint64_t n = (uint64_t)llround(c->duration / T);
  uint64_t per_window = n / WINDOWS;
  double window_sum[WINDOWS] = {0};
  double depth_max = x_eq;
  uint64_t outside = 0;
  for (uint64_t k = 0; k < n; k++) {
    // the wall, from what the encoder reports: F(k) = -K x(k) - B (x(k) - x(k-1)) / T
    const tx_device_state* s = &dev.state;
    double f_k, e_k;
    if (link) {
      if (link->exchange(link->user, k, K, B, s->pos[0], s->vel[0], &f_k, &e_k)) return false;
    } else {
      tx_wall_force(K, B, s->pos[0], s->vel[0], &f_k, &e_k);
    }
    line_f[k % (uint64_t)slots] = f_k, line_e[k % (uint64_t)slots] = e_k;
    // what arrives now was computed n ticks ago (with n = 0, this tick's: tx_wall_run)
    uint64_t j = (k + 1) % (uint64_t)slots;
    tx_haptic_input in = {{line_f[j], 0, 0}, line_e[j], false, 0, 0};
    double f[3];
    tx_haptic_tick(&path, T, &in, s->pos, s->vel, f);
    tx_sim_device_step(&dev, f, NULL);

    // the oscillation energy about the resting depth, from the true state
    double dx = dev.x[0] - x_eq;
    double energy = 0.5 * m * dev.v[0] * dev.v[0] + 0.5 * keff * dx * dx;
    uint64_t w = per_window ? k / per_window : 0;
    if (w < WINDOWS) window_sum[w] += energy;
    if (dev.x[0] > depth_max) depth_max = dev.x[0];
    if (dev.x[0] <= 0) outside++;
  }
  // decay or growth: the last quarter against the start
  double last = (window_sum[WINDOWS - 2] + window_sum[WINDOWS - 1]) / (2.0 * (double)per_window);
  // least-squares slope of log window energy over window centres
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

tx_wall_search tx_wall_largest_stable_delayed(const tx_wall_case* c, int delay_ticks, double k_lo, double k_hi, double rel_tol) {
  tx_wall_search s = {.k = k_lo};
  tx_wall_case t = *c;
  tx_wall_result r;
  if (!(k_lo > 0 && k_hi >= k_lo && k_hi <= 1e7 && rel_tol > 0)) {
    tx_set_error("wall search: need 0 < k_lo <= k_hi <= 1e7 N/m and rel_tol > 0, got %g, %g, %g", k_lo, k_hi, rel_tol);
    s.lo_unstable = true;
    return s;
  }
  double stable = 0, unstable = 0;
  for (double k = k_lo;; k *= 1.25) { // a sweep first: a limit cycle can make a stiffer wall look stable again
    if (k > k_hi) k = k_hi;
    t.stiffness = k;
    if (!tx_wall_run_delayed(&t, delay_ticks, NULL, &r)) return s.lo_unstable = true, s;
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
    if (!tx_wall_run_delayed(&t, delay_ticks, NULL, &r)) break;
    s.cases++;
    if (r.stable) stable = t.stiffness;
    else unstable = t.stiffness;
  }
  s.k = stable;
  s.k_unstable = unstable;
  return s;
}

bool tx_wall_run(const tx_wall_case* c, tx_wall_result* out) { return tx_wall_run_delayed(c, 0, NULL, out); }

tx_wall_search tx_wall_largest_stable(const tx_wall_case* c, double k_lo, double k_hi, double rel_tol) {
  return tx_wall_largest_stable_delayed(c, 0, k_lo, k_hi, rel_tol);
}

// Jury's test for the monic cubic z^3 + a2 z^2 + a1 z + a0: every root
// strictly inside the unit circle
static bool jury3(double a2, double a1, double a0) {
  return 1 + a2 + a1 + a0 > 0 && 1 - a2 + a1 - a0 > 0 && fabs(a0) < 1 && fabs(1 - a0 * a0) > fabs(a1 - a0 * a2);
}

bool tx_wall_exact_stable(const tx_sim_device* dev, double K, double B) {
  const double *phi = dev->phi, *gam = dev->gam;
  double T = dev->def.period, kb = K + B / T, bt = B / T;
  // state (x(k), v(k), x(k-1)); F(k) = -K x(k) - B (x(k) - x(k-1)) / T, held over the period
  double a[3][3] = {{phi[0] - gam[0] * kb, phi[1], gam[0] * bt}, {phi[2] - gam[1] * kb, phi[3], gam[1] * bt}, {1, 0, 0}};
  double tr = a[0][0] + a[1][1] + a[2][2];
  double minors = a[0][0] * a[1][1] - a[0][1] * a[1][0] + a[0][0] * a[2][2] - a[0][2] * a[2][0] + a[1][1] * a[2][2] -
                  a[1][2] * a[2][1];
  double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
               a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  return jury3(-tr, minors, -det);
}

double tx_wall_exact_bound(const tx_sim_device_def* d, double B) {
  tx_sim_device dev;
  if (!isfinite(B) || !tx_sim_device_init(&dev, d)) return NAN;
  // up in doublings from a stiffness far below any bound, then bisection
  double lo = 0, hi = 1e-3;
  while (hi <= 1e12 && tx_wall_exact_stable(&dev, hi, B)) lo = hi, hi *= 2;
  if (lo == 0 || hi > 1e12) return lo;
  while (hi - lo > 1e-12 * hi) {
    double mid = 0.5 * (lo + hi);
    if (tx_wall_exact_stable(&dev, mid, B)) lo = mid;
    else hi = mid;
  }
  return lo;
}

double tx_wall_colgate_bound(double b, double B, double T) {
  if (!(T > 0)) return NAN;
  double k = 2 * (b - fabs(B)) / T;
  return k > 0 ? k : 0;
}
