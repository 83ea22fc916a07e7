// tactus bench lagb (see bench_lagb.h).
#include "bench_lagb.h"
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

enum { SETUPS = 3, ROWS_MAX = 32 };
static const char* const setup_name[SETUPS] = {"no view", "mono", "stereo sbs"};
static const char* const setup_dir[SETUPS] = {"none", "mono", "stereo"};

typedef struct row {
  char name[64], type[64];
  double target, got[SETUPS];
} row;

int tx_bench_lagb(const char* out, double duration_s) {
  char path[PATH_MAX], dir[4096], sub[4200];
  if (tx_scenario_locate("lagb", path, sizeof path)) return tx_bad_input("bench lagb: %s", tx_error());
  if (tx_out_dir(out, "bench-lagb", dir, sizeof dir)) return TX_EXIT_BAD_INPUT;
  printf("bench lagb: the lagb scenario in real time with no view, with the offscreen view (png) and with its\n"
         "side-by-side stereo, one run each; the runs are in %s\n\n",
         dir);
  fflush(stdout);
  row rows[ROWS_MAX];
  int nrows = 0;
  double fps[SETUPS] = {0, 0, 0}, cpu_ms[SETUPS] = {0, 0, 0};
  for (int k = 0; k < SETUPS; k++) {
    tx_load_options o = {.view = k ? "png" : NULL, .stereo = k == 2 ? "sbs" : NULL};
    tx_scenario* sc = tx_scenario_load(path, &o);
    if (!sc) return tx_bad_input("bench lagb: %s", tx_error());
    snprintf(sub, sizeof sub, "%s/%s", dir, setup_dir[k]);
    tx_run_config cfg = {.scenario = "lagb", .duration_s = duration_s, .out = sub, .quiet = true, .no_record = true};
    json_t* report = NULL;
    int rc = tx_run_scenario(sc, &cfg, &report);
    tx_scenario_free(sc);
    if (rc) return json_decref(report), fprintf(stderr, "tactus: bench lagb: the %s run failed\n", setup_name[k]), rc;
    size_t i;
    json_t* c;
    json_array_foreach(json_object_get(report, "controllers"), i, c) {
      const char* name = json_string_value(json_object_get(c, "name"));
      const char* type = json_string_value(json_object_get(c, "type"));
      int r = 0;
      while (r < nrows && strcmp(rows[r].name, name ? name : "")) r++;
      if (r == nrows && nrows < ROWS_MAX) {
        snprintf(rows[r].name, sizeof rows[r].name, "%s", name ? name : "");
        snprintf(rows[r].type, sizeof rows[r].type, "%s", type ? type : "");
        rows[r].target = json_number_value(json_object_get(c, "target_hz"));
        for (int s = 0; s < SETUPS; s++) rows[r].got[s] = NAN;
        nrows++;
      }
      if (r < nrows) rows[r].got[k] = json_number_value(json_object_get(c, "achieved_hz"));
    }
    json_t* res = json_object_get(report, "results");
    double secs = json_number_value(json_object_get(report, "duration_s"));
    if (k && secs > 0) {
      fps[k] = json_number_value(json_object_get(res, "view.frames")) / secs;
      cpu_ms[k] = json_number_value(json_object_get(res, "view.frame_cpu_ms_mean"));
    }
    printf("  %-10s done: %.0f of 6 steps, band locked %s, host steal %.2f s\n", setup_name[k],
           json_number_value(json_object_get(res, "procedure.steps_done")),
           json_number_value(json_object_get(res, "band.locked")) > 0.5 ? "yes" : "no",
           json_number_value(json_object_get(report, "host_steal_s")));
    json_decref(report);
    fflush(stdout);
  }

  printf("\n  %-14s %-20s %9s %12s %12s %12s\n", "controller", "type", "target Hz", setup_name[0], setup_name[1],
         setup_name[2]);
  double physics_min = INFINITY, collision_min = INFINITY, haptics_min = INFINITY;
  for (int r = 0; r < nrows; r++) {
    printf("  %-14s %-20s %9.1f", rows[r].name, rows[r].type, rows[r].target);
    for (int k = 0; k < SETUPS; k++) isnan(rows[r].got[k]) ? printf(" %12s", "-") : printf(" %12.1f", rows[r].got[k]);
    printf("\n");
    for (int k = 0; k < SETUPS; k++) {
      if (!strncmp(rows[r].type, "physics.", 8)) physics_min = fmin(physics_min, rows[r].got[k]);
      if (!strncmp(rows[r].type, "collision.", 10)) collision_min = fmin(collision_min, rows[r].got[k]);
      if (!strncmp(rows[r].type, "haptics", 7)) haptics_min = fmin(haptics_min, rows[r].got[k]);
    }
  }
  printf("  %-14s %-20s %9.1f %12s %12.1f %12.1f   (frames a second; %.1f and %.1f ms of CPU each)\n", "frames",
         "views.graphics", 30.0, "-", fps[1], fps[2], cpu_ms[1], cpu_ms[2]);

  char m[64];
  printf("\ntargets (the lowest over the three runs; frames in their own runs):\n");
  snprintf(m, sizeof m, "%.1f Hz", physics_min);
  tx_bench_target("physics, every physics controller", m, ">= 20 Hz", physics_min >= 20);
  if (isfinite(collision_min)) {
    snprintf(m, sizeof m, "%.1f Hz", collision_min);
    tx_bench_target("collision, every collision controller", m, ">= 1000 Hz", collision_min >= 1000);
  } else {
    printf("  %-44s none in this scene (the graspers pick; collision.organ runs in lagb-organs)\n", "collision");
  }
  snprintf(m, sizeof m, "%.1f Hz", haptics_min);
  tx_bench_target("haptics, both hands", m, ">= 990 Hz", haptics_min >= 990);
  snprintf(m, sizeof m, "%.1f /s", fps[1]);
  tx_bench_target("graphics, mono", m, ">= 29.7 /s", fps[1] >= 29.7);
  snprintf(m, sizeof m, "%.1f /s", fps[2]);
  tx_bench_target("graphics, stereo (side by side)", m, ">= 29.7 /s", fps[2] >= 29.7);
  return 0;
}
