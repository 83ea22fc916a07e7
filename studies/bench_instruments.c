// tactus bench instruments: the cost of one 1 kHz step of the instruments'
// ODE world (controllers/instruments/instrument_sim.h) with two articulated
// instruments (the needle holder and the thumb forceps, 3 bodies and 2 hinges
// each) and the curved needle. The hands circle 1 cm apart above the table,
// the grips open and close, and the needle holder's jaws pass over the
// needle, so contacts come and go as in use. Target (issue 14): p99 <= 200 us.
#include "bench_instruments.h"
#include "studies.h"

#include "../scenarios/command.h"

#include <tactus/config.h>
#include <tactus/stats.h>

#include <math.h>
#include <stdio.h>


#if TX_WITH_ODE && TX_WITH_URDFDOM && TX_WITH_ASSIMP
#include "../controllers/instruments/instrument_desc.h"
#include "../controllers/instruments/instrument_sim.h"

#include <tactus/model.h>

int tx_bench_instruments(double duration_s) {
  double seconds = duration_s > 0 ? duration_s : 20;
  const char* names[2] = {"needle_holder", "thumb_forceps"};
  tx_instrument_desc* d[2] = {0};
  for (int i = 0; i < 2; i++) {
    char path[2048];
    snprintf(path, sizeof path, "%s/instruments/%s.urdf", TX_ASSET_DIR, names[i]);
    if (!(d[i] = tx_instrument_desc_load(path))) {
      fprintf(stderr, "tactus: bench instruments: %s\n", tx_error());
      tx_instrument_desc_free(d[0]);
      return 1;
    }
  }
  tx_instrument_sim_params p = tx_instrument_sim_defaults();
  p.needle.enabled = true;
  const tx_urdf* u[2] = {d[0]->urdf, d[1]->urdf};
  double start[2][3] = {{0, -0.04, 0}, {0, -0.04, 0.03}};
  tx_instrument_world* w = tx_instrument_world_create(&p, u, 2, start);
  if (!w) {
    fprintf(stderr, "tactus: bench instruments: %s\n", tx_error());
    tx_instrument_desc_free(d[0]), tx_instrument_desc_free(d[1]);
    return 1;
  }
  static tx_hist h;
  tx_hist_clear(&h);
  long steps = lround(seconds * 1000), contacts = 0;
  for (long k = 0; k < steps; k++) {
    double t = k * 1e-3;
    tx_instrument_input in[2] = {
        {.pos = {0.02 + 0.01 * cos(t), -0.045 + 0.004 * sin(3 * t), 0.01 * sin(t)}, .quat = {1, 0, 0, 0},
         .grip = 0.25 + 0.25 * sin(2 * t)},
        {.pos = {0.01 * cos(t + 1), -0.04, 0.03 + 0.01 * sin(t + 1)}, .quat = {1, 0, 0, 0}, .grip = 0.07 + 0.07 * sin(5 * t)}};
    int64_t t0 = tx_mono_ns();
    tx_instrument_world_step(w, in, 1e-3);
    tx_hist_add(&h, tx_mono_ns() - t0);
    contacts += tx_instrument_world_contacts(w);
  }
  tx_percentiles q = tx_hist_percentiles(&h);
  printf("bench instruments: %ld ODE steps (dWorldStep, 1 ms) of 2 instruments (7 bodies with the needle, 4 hinges),"
         " %.1f contacts per step\n",
         steps, (double)contacts / steps);
  printf("  %-10s %10s %10s %10s\n", "step", "p50 us", "p99 us", "max us");
  printf("  %-10s %10.1f %10.1f %10.1f\n", "ode", q.p50 * 1e-3, q.p99 * 1e-3, q.max * 1e-3);
  printf("\ntargets:\n");
  char measured[64];
  snprintf(measured, sizeof measured, "p99 %.1f us", q.p99 * 1e-3);
  tx_bench_target("one ODE step, 2 instruments + needle, p99", measured, "<= 200 us", q.p99 * 1e-3 <= 200);
  printf("resets %d, needle grasps %d\n", tx_instrument_world_resets(w), tx_instrument_world_needle_grasps(w));
  tx_instrument_world_destroy(w);
  tx_instrument_desc_free(d[0]), tx_instrument_desc_free(d[1]);
  return 0;
}
#else
int tx_bench_instruments(double duration_s) {
  (void)duration_s;
  return tx_bad_input("bench instruments: built without ODE, urdfdom or assimp (TX_WITH_ODE, TX_WITH_URDFDOM, TX_WITH_ASSIMP)");
}
#endif
