// tactus bench suturing (see bench_suturing.h).
#include "bench_suturing.h"
#include "studies.h"

#include "../scenarios/command.h"
#include "../scenarios/loader.h"
#include "../scenarios/run.h"
#include "../model/error.h"

#include <jansson.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>


static double wall_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

// the scenario file, with an empty 1 kHz controller on a thread of its own
// when `idle`; NULL and the one-line message in tx_error()
static tx_scenario* load(const char* path, bool idle) {
  json_error_t e;
  json_t* root = json_load_file(path, JSON_REJECT_DUPLICATES, &e);
  if (!root) return tx_set_error("%s:%d: %s", path, e.line, e.text), NULL;
  if (idle) {
    json_array_append_new(json_object_get(root, "controllers"),
                          json_pack("{s:s,s:s,s:f,s:s,s:{s:f}}", "name", "idle", "type", "rates.worker", "rate_hz", 1000.0,
                                    "thread", "idle", "params", "work_us", 0.0));
    json_t* sim = json_object_get(json_object_get(root, "roles"), "sim");  // a scenario with roles gives each one
    if (sim) json_array_append_new(sim, json_string("idle"));
  }
  tx_load_options o = {0};
  tx_scenario* sc = tx_scenario_load_json(path, root, &o);
  json_decref(root);
  return sc;
}

int tx_bench_suturing(const char* out, double duration_s) {
  char path[PATH_MAX], dir[4096], sub[4200];
  if (tx_scenario_locate("suturing", path, sizeof path)) return tx_bad_input("bench suturing: %s", tx_error());
  if (tx_out_dir(out, "bench-suturing", dir, sizeof dir)) return TX_EXIT_BAD_INPUT;
  tx_scenario* sc = load(path, true);
  if (!sc) return tx_bad_input("bench suturing: %s", tx_error());
  printf("bench suturing: the suturing scenario in real time with an empty 1 kHz controller on a thread of its own\n"
         "beside it (rates.worker, work_us 0: what the machine alone costs a 1 kHz thread), then in lockstep;\n"
         "the runs are in %s\n\n",
         dir);
  fflush(stdout);

  // real time, every controller of the scenario and the empty one
  snprintf(sub, sizeof sub, "%s/realtime", dir);
  tx_run_config cfg = {.scenario = "suturing", .duration_s = duration_s, .out = sub, .quiet = true, .no_record = true};
  json_t* report = NULL;
  int rc = tx_run_scenario(sc, &cfg, &report);
  tx_scenario_free(sc);
  if (rc) return json_decref(report), fprintf(stderr, "tactus: bench suturing: the real-time run failed\n"), rc;
  printf("  %-12s %-20s %10s %12s %8s %8s %8s\n", "controller", "type", "target Hz", "achieved Hz", "off %", "missed",
         "of");
  bool within = true;
  double idle_missed = -1, haptics_missed = 0;
  size_t i;
  json_t* c;
  json_array_foreach(json_object_get(report, "controllers"), i, c) {
    const char* name = json_string_value(json_object_get(c, "name"));
    const char* type = json_string_value(json_object_get(c, "type"));
    double target = json_number_value(json_object_get(c, "target_hz")), got = json_number_value(json_object_get(c, "achieved_hz"));
    double missed = json_number_value(json_object_get(c, "missed")), steps = json_number_value(json_object_get(c, "steps"));
    double off = 100 * (got / target - 1);
    if (strcmp(name, "idle") == 0) idle_missed = missed;
    else within &= fabs(off) <= 1;
    if (strncmp(type, "haptics", 7) == 0) haptics_missed = fmax(haptics_missed, missed);
    printf("  %-12s %-20s %10.1f %12.3f %+8.2f %8.0f %8.0f\n", name, type, target, got, off, missed, steps);
  }
  printf("  (host steal over the run: %.2f s)\n", json_number_value(json_object_get(report, "host_steal_s")));
  json_decref(report);

  // lockstep: the scripted suture's own length against the wall clock
  sc = load(path, false);
  if (!sc) return tx_bad_input("bench suturing: %s", tx_error());
  double simulated = duration_s > 0 ? duration_s : sc->duration_s;
  snprintf(sub, sizeof sub, "%s/lockstep", dir);
  tx_run_config lock = {.scenario = "suturing", .duration_s = duration_s, .lockstep = true, .out = sub, .quiet = true,
                        .no_record = true};
  double t0 = wall_now();
  rc = tx_run_scenario(sc, &lock, NULL);
  double wall = wall_now() - t0;
  tx_scenario_free(sc);
  if (rc) return fprintf(stderr, "tactus: bench suturing: the lockstep run failed\n"), rc;
  printf("\n  lockstep: %.1f s of simulated time in %.2f s (%.2f times)\n", simulated, wall, wall / simulated);

  char m[64], l[64];
  printf("\ntargets:\n");
  tx_bench_target("every controller within 1 % of its rate", within ? "yes" : "no", "all", within);
  snprintf(m, sizeof m, "%.0f", haptics_missed);
  snprintf(l, sizeof l, "<= %.0f (the empty one)", idle_missed);
  tx_bench_target("haptics missed deadlines, the larger hand's", m, l, idle_missed >= 0 && haptics_missed <= idle_missed);
  snprintf(m, sizeof m, "%.2f x", wall / simulated);
  tx_bench_target("lockstep suture, wall over simulated time", m, "<= 2 x", wall <= 2 * simulated);
  return 0;
}
