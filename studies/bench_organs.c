// tactus bench organs: the physics.organs step against the target,
// >= 30 Hz with the liver and the stomach (about 6,000 tetrahedra) on one
// core. Each mode runs in lockstep at 30 Hz (one thread) while a controller
// presses the tool sphere into the liver and slides it; the step's CPU time
// is the controller's own (its results step_p50_ms and step_p99_ms).
#include "bench_organs.h"
#include "studies.h"

#include "../scenarios/command.h"

#include <tactus/components.h>
#include <tactus/config.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if TX_WITH_BULLET

#define RATE_HZ 30.0

// the probe: from 2 cm above the liver's anterior surface (y = 55 mm at
// x = z = 60 mm) down 1 cm into it over 1 s, then sliding 2.5 cm along x and back
static void probe_at(double t, double pos[7]) {
  memset(pos, 0, 7 * sizeof *pos);
  double s = fmod(t, 4.0);
  pos[0] = 0.06 - (s > 1 ? 0.025 * (s < 2.5 ? (s - 1) / 1.5 : (4 - s) / 1.5) : 0);
  pos[1] = 0.08 - 0.035 * fmin(s, 1.0);
  pos[2] = 0.06;
  pos[3] = 1;
}

static int probe_configure(tx_setup* s, void** self) {
  tx_port* p = malloc(sizeof *p);
  if (!p) return -1;
  *p = tx_setup_write(s, &TX_COMPONENT_OF("device0.pose", tx_pose, 1));
  *self = p;
  return 0;
}
static void probe_step(tx_ctx* c, void* self) { probe_at((double)tx_sim_ns(c) * 1e-9, tx_write(c, *(tx_port*)self)); }
static void probe_fini(void* self) { free(self); }
static const tx_controller_class probe_class = {.type = "bench.organ_probe",
                                                .summary = "the probe of bench organs: presses the liver and slides",
                                                .configure = probe_configure,
                                                .step = probe_step,
                                                .fini = probe_fini};

static double result_of(tx_scenario* sc, const char* key) {
  for (int i = 0; i < tx_system_results(sc->system); i++)
    if (strcmp(tx_system_result_key(sc->system, i), key) == 0) return tx_system_result(sc->system, i);
  return NAN;
}

int tx_bench_organs(double duration_s) {
  double seconds = duration_s > 0 ? duration_s : 4;
  if (!tx_find_controller(probe_class.type)) tx_register_controller(&probe_class);
  printf("bench organs: the committed liver and stomach (assets/lagb, 5793 tetrahedra), physics.organs at %g Hz, "
         "1 ms substeps, a 5 mm probe pressing 1 cm into the liver and sliding; %g s in lockstep per mode; "
         "CPU time of the step on its thread\n\n",
         RATE_HZ, seconds);
  printf("  %-34s %9s %9s %9s %9s %7s\n", "mode", "p50 ms", "p99 ms", "steps/s", "added m", "faults");
  const char* modes[] = {"fem", "fem", "links"};
  const char* models[] = {"neohookean", "corotated", "neohookean"};
  double hz99[3] = {0};
  int rc = 0;
  for (int m = 0; m < 3 && rc == 0; m++) {
    char text[1024];
    snprintf(text, sizeof text,
             "{\"name\":\"bench-organs\",\"controllers\":["
             "{\"name\":\"probe\",\"type\":\"bench.organ_probe\",\"rate_hz\":%g},"
             "{\"name\":\"organs\",\"type\":\"physics.organs\",\"rate_hz\":%g,"
             "\"params\":{\"mode\":\"%s\",\"model\":\"%s\"}}]}",
             RATE_HZ, RATE_HZ, modes[m], models[m]);
    tx_scenario* sc = tx_scenario_load_text("bench-organs", text, strlen(text), NULL);
    if (!sc) {
      fprintf(stderr, "tactus: bench organs: %s\n", tx_error());
      return 1;
    }
    tx_run_options o = {.duration_s = seconds, .lockstep = true};
    tx_run_result res;
    if (tx_system_run(sc->system, &o, &res)) {
      fprintf(stderr, "tactus: bench organs: %s\n", tx_error());
      rc = 1;
    } else {
      double p50 = result_of(sc, "organs.step_p50_ms"), p99 = result_of(sc, "organs.step_p99_ms");
      char name[64];
      snprintf(name, sizeof name, "%s%s%s", modes[m], m < 2 ? ", " : "", m < 2 ? models[m] : "");
      printf("  %-34s %9.2f %9.2f %9.1f %9.2f %7.0f\n", name, p50, p99, 1e3 / p50, result_of(sc, "organs.added_mass"),
             result_of(sc, "organs.faults"));
      hz99[m] = 1e3 / p99;
      if (result_of(sc, "organs.faults") != 0) rc = 1;
    }
    tx_scenario_free(sc);
  }
  if (rc == 0) {
    printf("\ntargets (a step within its 1/30 s period at the 99th percentile):\n");
    char measured[64];
    snprintf(measured, sizeof measured, "%.1f Hz at p99", hz99[0]);
    tx_bench_target("fem (Neo-Hookean): liver and stomach, one core", measured, ">= 30 Hz", hz99[0] >= 30);
    snprintf(measured, sizeof measured, "%.1f Hz at p99", hz99[2]);
    tx_bench_target("links: liver and stomach, one core", measured, ">= 30 Hz", hz99[2] >= 30);
  }
  return rc;
}

#else

int tx_bench_organs(double duration_s) {
  (void)duration_s;
  fprintf(stderr, "tactus: bench organs: this build has no Bullet (TX_WITH_BULLET=OFF)\n");
  return 2;
}

#endif
