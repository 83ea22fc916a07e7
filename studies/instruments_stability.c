// tactus study instruments-stability: how stiff the instruments' virtual
// coupling can be on the Touch-class simulated device at 1 kHz, against the
// stability bounds `tactus study haptic-stability` measures for a virtual
// wall (Colgate's 2 (b - |B|) / T and the exact boundary of the sampled
// loop); and the instruments' world under abuse: a 10 m/s hand, jaws slammed
// at the motor limit, a needle squeezed between two closed instruments, at
// ODE steps of 1e-4, 1e-3 and 1e-2 s. Writes instruments-stability.json,
// .csv and .png.
//
// The coupling loop: the hook rests on the table; the simulated device's hand
// presses it down with 1 N through the coupling (the soft lossless hand of the
// haptic-stability wall, 20 N/m); the device starts with a small downward kick. Each 1 ms
// the device's sample goes to the world, one ODE step, and the coupling force
// on the hand goes back to the device, held over the next period. With the
// tool held by the table the coupling is a virtual wall of stiffness k and
// damping B: the same sampled loop as the haptic-stability wall. A case is
// stable when the device's oscillation about its final rest (RMS over the
// last quarter of 2 s) is below that over the first quarter.
#include "studies.h"

#include "../scenarios/command.h"
#include "../views/aside.h"
#include "../views/plot.h"
#include "../views/report.h"

#include <tactus/config.h>

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if TX_WITH_ODE && TX_WITH_URDFDOM && TX_WITH_ASSIMP
#include "../controllers/haptics/sim_device.h"
#include "../controllers/instruments/instrument_desc.h"
#include "../controllers/instruments/instrument_sim.h"
#include "experiments/wall_stability.h"

#include <tactus/model.h>

#define SWEEP_MAX 64

static tx_instrument_desc* load(const char* name) {
  char path[2048];
  snprintf(path, sizeof path, "%s/instruments/%s.urdf", TX_ASSET_DIR, name);
  tx_instrument_desc* d = tx_instrument_desc_load(path);
  if (!d) fprintf(stderr, "tactus: %s\n", tx_error());
  return d;
}

// the RMS of the device's oscillation over the last quarter over that of the
// first: below 1 is stable; -1 when the world cannot be made
static double coupling_ratio(const tx_urdf* hook, const tx_sim_device_def* def, double k, double B, double seconds) {
  tx_instrument_sim_params p = tx_instrument_sim_defaults();
  p.coupling_k = k, p.coupling_b = B, p.table_height = 0;
  p.max_force = 1e3; // the device clamps what it outputs (def->max_force); the loop is what is measured
  double start[1][3] = {{0, 0.0025, 0}};
  tx_instrument_world* w = tx_instrument_world_create(&p, &hook, 1, start);
  tx_sim_device dev;
  if (!w || !tx_sim_device_init(&dev, def)) return tx_instrument_world_destroy(w), -1;
  // at rest the hand's 1 N press stretches the coupling 1/k: start there, kicked down
  double x0[3] = {0, 0.0025 - 1.0 / k, 0}, v0[3] = {0, -0.25 * (1.0 / k) * sqrt((k + def->hand_stiffness) / def->mass), 0};
  tx_sim_device_reset(&dev, x0, v0);
  double target[3] = {0, 0.0025 - 1.0 / k - 1.0 / def->hand_stiffness, 0};
  tx_sim_device_place_hand(&dev, target);
  int n = (int)lround(seconds / def->period);
  double* y = malloc(sizeof *y * (size_t)n);
  double f[3] = {0};
  for (int i = 0; i < n && y; i++) {
    tx_sim_device_step(&dev, f, target);
    tx_instrument_input in = {.quat = {1, 0, 0, 0}};
    memcpy(in.pos, dev.state.pos, sizeof in.pos);
    memcpy(in.vel, dev.state.vel, sizeof in.vel);
    tx_instrument_world_step(w, &in, def->period);
    tx_instrument_world_hand_force(w, 0, f);
    y[i] = dev.x[1];
  }
  tx_instrument_world_destroy(w);
  if (!y) return -1;
  double rest = 0, a = 0, b = 0;
  int q = n / 4;
  for (int i = n - q; i < n; i++) rest += y[i] / q;
  for (int i = 0; i < q; i++) a += (y[i] - rest) * (y[i] - rest), b += (y[n - q + i] - rest) * (y[n - q + i] - rest);
  free(y);
  return isfinite(a) && isfinite(b) && a > 0 ? sqrt(b / a) : 1e9;
}

typedef struct sweep {
  double k[SWEEP_MAX], ratio[SWEEP_MAX];
  int n;
  double k_max; // the largest stable k found
} sweep;

// up in x1.25 steps to the first unstable k, then bisection to 1 %
static int find_k_max(const tx_urdf* hook, const tx_sim_device_def* def, double B, double seconds, sweep* s) {
  s->n = 0;
  double lo = 0, hi = 0;
  for (double k = 50; k < 1e5 && s->n < SWEEP_MAX; k *= 1.25) {
    double r = coupling_ratio(hook, def, k, B, seconds);
    if (r < 0) return -1;
    s->k[s->n] = k, s->ratio[s->n++] = r;
    if (r < 1) lo = k;
    else {
      hi = k;
      break;
    }
  }
  while (hi > 0 && hi - lo > 0.01 * lo && s->n < SWEEP_MAX) {
    double k = (lo + hi) / 2, r = coupling_ratio(hook, def, k, B, seconds);
    if (r < 0) return -1;
    s->k[s->n] = k, s->ratio[s->n++] = r;
    if (r < 1) lo = k;
    else hi = k;
  }
  s->k_max = lo;
  return 0;
}

// ---- abuse

typedef struct abuse {
  const char* name;
  double dt;
  double max_force; // N, the largest coupling force on a hand
  double jaw_excess; // rad, the furthest any jaw went past its limits
  int not_finite, resets, steps;
} abuse;

static void watch(tx_instrument_world* w, const tx_urdf* const* u, int n, abuse* r) {
  for (int i = 0; i < n; i++) {
    double f[3], pos[3], q[4];
    tx_instrument_world_hand_force(w, i, f);
    r->max_force = fmax(r->max_force, sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
    for (int l = 0; l < u[i]->nlinks; l++) {
      tx_instrument_world_link(w, i, l, pos, q);
      if (!isfinite(pos[0] + pos[1] + pos[2] + q[0] + q[1] + q[2] + q[3] + f[0] + f[1] + f[2])) r->not_finite++;
    }
    for (int j = 0; j < u[i]->njoints; j++) {
      double a = tx_instrument_world_joint(w, i, j);
      if (!isfinite(a)) r->not_finite++;
      else r->jaw_excess = fmax(r->jaw_excess, fmax(u[i]->joints[j].lower - a, a - u[i]->joints[j].upper));
    }
  }
  double np[3], nq[4];
  tx_instrument_world_needle(w, np, nq);
  if (!isfinite(np[0] + np[1] + np[2] + nq[0])) r->not_finite++;
  r->steps++;
}

// case 0: a hand swinging at up to 10 m/s; 1: jaws slammed between the motor
// limits; 2: a needle squeezed between two closed needle holders
static int run_abuse(int which, double dt, const tx_urdf* holder, abuse* r) {
  static const char* names[] = {"hand at 10 m/s", "jaws slammed at the motor limit", "needle squeezed between two instruments"};
  *r = (abuse){.name = names[which], .dt = dt, .jaw_excess = -1};
  tx_instrument_sim_params p = tx_instrument_sim_defaults();
  p.needle.enabled = true;
  int n = which == 2 ? 2 : 1;
  const tx_urdf* u[2] = {holder, holder};
  double nx = p.needle.pos[0], y = p.table_height + 0.0018; // the jaws' half-width above the table
  double start[2][3] = {{nx - p.needle.radius - 0.04, y, 0}, {nx + p.needle.radius + 0.04, y, 0}};
  tx_instrument_world* w = tx_instrument_world_create(&p, u, n, start);
  if (!w) return -1;
  double seconds = 1.0;
  int steps = (int)lround(seconds / dt);
  for (int k = 0; k < steps; k++) {
    double t = k * dt;
    tx_instrument_input in[2] = {{.quat = {1, 0, 0, 0}}, {.quat = {0, 0, 1, 0}}}; // the second faces the first
    memcpy(in[0].pos, start[0], sizeof in[0].pos);
    memcpy(in[1].pos, start[1], sizeof in[1].pos);
    if (which == 0) { // x = 0.5 sin(20 t): 10 m/s through the middle, over the needle and the table
      in[0].pos[0] += 0.5 * sin(20 * t), in[0].vel[0] = 10 * cos(20 * t);
      in[0].pos[1] -= 0.01 * (1 + sin(7 * t)), in[0].vel[1] = -0.07 * cos(7 * t);
      in[0].grip = 0.3;
    } else if (which == 1) { // slammed open and shut every 20 ms, far past both limits
      in[0].grip = ((int)(t / 0.02)) % 2 ? 10 : -10;
    } else { // both closed, driven 1 cm through the needle from both sides
      double u2 = fmin(1, t / 0.5);
      in[0].pos[0] += u2 * 0.05, in[1].pos[0] -= u2 * 0.05;
    }
    tx_instrument_world_step(w, in, dt);
    watch(w, u, n, r);
  }
  r->resets = tx_instrument_world_resets(w);
  tx_instrument_world_destroy(w);
  return 0;
}

static json_t* num(double v) { return isfinite(v) ? json_real(v) : json_null(); }

int tx_study_instruments_stability(const tx_study_args* a) {
  bool quick = false;
  for (int i = 0; i < a->nsets; i++) {
    if (strcmp(a->sets[i], "quick=1") == 0) quick = true;
    else if (strcmp(a->sets[i], "quick=0") != 0) return tx_bad_input("--set %s: the only key is quick (0 or 1)", a->sets[i]);
  }
  tx_instrument_desc* hook = load("hook_cautery");
  tx_instrument_desc* holder = hook ? load("needle_holder") : NULL;
  if (!holder) return tx_instrument_desc_free(hook), 1;
  // the device and hand of haptic-stability's wall: a soft, lossless hand
  // (20 N/m, no damping), so that the bounds are the same loop's
  tx_sim_device_def def = tx_wall_case_default().device;
  def.quantum = 0; // the exact boundary linearises the encoder away
  double coupling_b = tx_instrument_sim_defaults().coupling_b, k_default = tx_instrument_sim_defaults().coupling_k;
  double Bs[2] = {0, coupling_b};
  static sweep sw[2];
  double seconds = quick ? 1 : 2;
  printf("instruments-stability: the virtual coupling on the sim device (m = %g kg, b = %g N s/m, T = %g ms), the hook "
         "held by the table\n",
         def.mass, def.damping, def.period * 1e3);
  printf("  %-18s %14s %14s %14s %10s\n", "coupling damping", "Colgate N/m", "exact N/m", "measured N/m", "/exact");
  double colgate[2], exact[2];
  for (int i = 0; i < 2; i++) {
    if (find_k_max(hook->urdf, &def, Bs[i], seconds, &sw[i])) {
      fprintf(stderr, "tactus: %s\n", tx_error());
      return tx_instrument_desc_free(hook), tx_instrument_desc_free(holder), 1;
    }
    colgate[i] = tx_wall_colgate_bound(def.damping, Bs[i], def.period);
    exact[i] = tx_wall_exact_bound(&def, Bs[i]);
    printf("  B = %-14g %14.1f %14.1f %14.1f %10.3f\n", Bs[i], colgate[i], exact[i], sw[i].k_max, sw[i].k_max / exact[i]);
  }

  double dts[3] = {1e-4, 1e-3, 1e-2};
  int ndt = quick ? 1 : 3;
  if (quick) dts[0] = 1e-3;
  abuse rows[9];
  int nrows = 0;
  printf("\n  %-42s %8s %12s %12s %10s %8s\n", "abuse", "dt s", "max force N", "jaw past rad", "not finite", "resets");
  for (int c = 0; c < 3; c++)
    for (int d = 0; d < ndt; d++) {
      if (run_abuse(c, dts[d], holder->urdf, &rows[nrows])) {
        fprintf(stderr, "tactus: %s\n", tx_error());
        return tx_instrument_desc_free(hook), tx_instrument_desc_free(holder), 1;
      }
      abuse* r = &rows[nrows++];
      printf("  %-42s %8g %12.4f %12.4f %10d %8d\n", r->name, r->dt, r->max_force, r->jaw_excess, r->not_finite, r->resets);
    }
  double clamp = tx_instrument_sim_defaults().max_force;

  // outputs, each written aside and renamed when whole
  tx_aside out;
  if (!tx_aside_begin(&out, a->out_dir, "instruments-stability.csv")) return tx_instrument_desc_free(hook), tx_instrument_desc_free(holder), tx_bad_input("--out %s", tx_error());
  FILE* csv = out.f;
  fprintf(csv, "coupling_damping_n_s_m,coupling_stiffness_n_m,oscillation_ratio\n");
  json_t* couplings = json_array();
  for (int i = 0; i < 2; i++) {
    json_t* pts = json_array();
    for (int j = 0; j < sw[i].n; j++) {
      fprintf(csv, "%g,%.6g,%.6g\n", Bs[i], sw[i].k[j], sw[i].ratio[j]);
      json_array_append_new(pts, json_pack("{s:f,s:o}", "k_n_m", sw[i].k[j], "ratio", num(sw[i].ratio[j])));
    }
    json_array_append_new(couplings, json_pack("{s:f,s:f,s:f,s:f,s:o,s:o}", "coupling_damping_n_s_m", Bs[i],
                                               "k_max_theory", colgate[i], "k_max_exact", exact[i], "k_max_measured",
                                               sw[i].k_max, "measured_over_exact", num(sw[i].k_max / exact[i]), "sweep", pts));
  }
  if (!tx_aside_end(&out))
    return tx_instrument_desc_free(hook), tx_instrument_desc_free(holder), fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  json_t* cases = json_array();
  for (int i = 0; i < nrows; i++)
    json_array_append_new(cases, json_pack("{s:s,s:f,s:f,s:f,s:i,s:i,s:i}", "case", rows[i].name, "dt_s", rows[i].dt,
                                           "max_force_n", rows[i].max_force, "jaw_past_limit_rad", rows[i].jaw_excess,
                                           "not_finite", rows[i].not_finite, "resets", rows[i].resets, "steps", rows[i].steps));
  json_t* doc = json_pack("{s:s,s:{s:f,s:f,s:f},s:f,s:f,s:o,s:o}", "study", "instruments-stability", "device", "mass_kg",
                          def.mass, "damping_n_s_m", def.damping, "period_s", def.period, "coupling_stiffness_default_n_m",
                          k_default, "force_clamp_n", clamp, "coupling", couplings, "abuse", cases);
  int rc = 0;
  if (!doc || tx_report_save(doc, a->out_dir, "instruments-stability.json")) fprintf(stderr, "tactus: %s\n", doc ? tx_error() : "out of memory"), rc = 1;
  json_decref(doc);
  tx_plot_series s[2] = {{"coupling damping 0", sw[0].k, sw[0].ratio, sw[0].n, true, 9},
                         {"coupling damping 1 N s/m (default)", sw[1].k, sw[1].ratio, sw[1].n, true, 10}};
  char title[200], png[4200];
  snprintf(title, sizeof title, "Virtual coupling at %g kHz: oscillation left after 2 s (below 1: stable); exact bounds %.0f and %.0f N/m",
           1e-3 / def.period, exact[0], exact[1]);
  tx_plot pl = {title, "coupling stiffness k (N/m)", "oscillation RMS, last quarter / first", true, true, s, 2};
  snprintf(png, sizeof png, "%s/instruments-stability.png", a->out_dir);
  if (rc == 0 && tx_plot_png(png, &pl) != 0) fprintf(stderr, "tactus: %s\n", tx_error());

  printf("\ntargets:\n");
  bool all = true;
  for (int i = 0; i < 2; i++) {
    double off = fabs(sw[i].k_max / exact[i] - 1) * 100;
    printf("  B = %g: measured within 5%% of the exact boundary: %.1f%% off %s\n", Bs[i], off, off <= 5 ? "met" : "MISSED");
    all = all && off <= 5;
  }
  printf("  default coupling %g N/m inside the measured bound %.0f N/m (B = %g): %s\n", k_default, sw[1].k_max, coupling_b,
         k_default < sw[1].k_max ? "met" : "MISSED");
  bool clean = true;
  for (int i = 0; i < nrows; i++) clean = clean && rows[i].not_finite == 0 && rows[i].max_force <= clamp * (1 + 1e-9);
  printf("  every abuse case: no NaN, no force above the %g N clamp: %s\n", clamp, clean ? "met" : "MISSED");
  printf("ODE solver messages (LCP failures, recovered): %d\n", tx_instrument_ode_messages());
  tx_instrument_desc_free(hook);
  tx_instrument_desc_free(holder);
  (void)all;
  return rc;
}
#else
int tx_study_instruments_stability(const tx_study_args* a) {
  (void)a;
  return tx_bad_input("study instruments-stability: built without ODE, urdfdom or assimp (TX_WITH_ODE, TX_WITH_URDFDOM, TX_WITH_ASSIMP)");
}
#endif
