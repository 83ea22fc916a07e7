// tactus bench cloth: the skin's physics step at the papers' high density
// (102 x 102 = 10404 particles, 0.1 cm), rupture active and a HIP piercing
// it, against a 60 Hz frame; and the framework's overhead: the physics.skin
// controller run by the lockstep executor (reading the pose, publishing
// skin.x, skin.tri, skin.thickness and skin.torn, the finite check) against
// a bare loop that steps an identical cloth through the adapter alone.
// The two alternate in rounds of one simulated second, so that a busy
// machine slows both alike.
#include "bench_cloth.h"

#include "command.h"

#include "../../controllers/stats.h"

#include <tactus/config.h>

#include <stdio.h>
#include <string.h>

#if TX_WITH_BULLET
#include "../../controllers/physics/bullet/cloth.h"

#include <math.h>
#include <stdlib.h>

#define ROUND_STEPS 60  // one simulated second at 60 Hz
#define RATE_HZ 60.0
#define SPACING 0.001   // m, the journal paper's 0.1 cm
#define HIP_RADIUS 0.0005

// the HIP of every round: from 5 mm above the skin down at 1 cm/s, through it
static void hip_at(double t, double pos[7]) {
  memset(pos, 0, 7 * sizeof *pos);
  pos[1] = 0.005 - 0.01 * t;
  pos[3] = 1; // identity orientation
}

// a controller that writes the HIP's pose as device0.pose
typedef struct script {
  tx_port pose;
} script;

static int script_configure(tx_setup* s, void** self) {
  script* k = calloc(1, sizeof *k);
  if (!k) return -1;
  *self = k;
  k->pose = tx_setup_write(s, &(tx_component_def){"device0.pose", TX_F64, 1, 7, "m, 1"});
  return 0;
}
static void script_step(tx_ctx* c, void* self) {
  hip_at((double)tx_sim_ns(c) * 1e-9, tx_write(c, ((script*)self)->pose));
}
static void script_fini(void* self) { free(self); }
static const tx_controller_class script_class = {.type = "bench.hip_script",
                                                 .summary = "the HIP of bench cloth: down at 1 cm/s",
                                                 .configure = script_configure,
                                                 .step = script_step,
                                                 .fini = script_fini};

static int cmp_double(const void* a, const void* b) {
  double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}
static double median(double* v, int n) {
  qsort(v, (size_t)n, sizeof *v, cmp_double);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static void print_target(const char* what, const char* measured, const char* limit, bool ok) {
  printf("  %-44s %-30s %-10s %s\n", what, measured, limit, ok ? "met" : "MISSED");
}

int tx_bench_cloth(double duration_s) {
  const int rounds = duration_s > 0 ? (int)ceil(duration_s / 2) : 10; // two simulated seconds a round
  if (!tx_find_controller(script_class.type)) tx_register_controller(&script_class);

  // the framework: physics.skin at 60 Hz beside the script, in lockstep
  char text[1024], err[512];
  snprintf(text, sizeof text,
           "{\"name\":\"bench-cloth\",\"controllers\":["
           "{\"name\":\"hip\",\"type\":\"bench.hip_script\",\"rate_hz\":%g},"
           "{\"name\":\"skin\",\"type\":\"physics.skin\",\"rate_hz\":%g,"
           "\"params\":{\"spacing_m\":%g,\"hip_radius_m\":%g}}]}",
           RATE_HZ, RATE_HZ, SPACING, HIP_RADIUS);
  tx_scenario* sc = tx_scenario_load_text("bench-cloth", text, strlen(text), NULL, err, sizeof err);
  if (!sc) return fprintf(stderr, "tactus: %s\n", err), 1;
  int skin_index = -1;
  for (int i = 0; i < tx_system_count(sc->system); i++)
    if (strcmp(tx_system_name(sc->system, i), "skin") == 0) skin_index = i;

  // the bare loop: the same cloth through the adapter, as physics.skin builds it
  tx_cloth_def d = tx_cloth_def_default();
  d.res[0] = d.res[1] = (int)lround(0.1 / SPACING) + 2;
  d.size[0] = d.size[1] = (d.res[0] - 1) * SPACING;
  tx_cloth* bare = tx_cloth_create(&d);
  tx_samples bare_ns;
  double* bare_wall = calloc((size_t)rounds, sizeof *bare_wall);
  double* fw_wall = calloc((size_t)rounds, sizeof *fw_wall);
  double* fw_p50 = calloc((size_t)rounds, sizeof *fw_p50);
  double* bare_p50 = calloc((size_t)rounds, sizeof *bare_p50);
  double fw_p99 = 0, fw_max = 0;
  if (!bare || !tx_samples_init(&bare_ns, (uint64_t)rounds * ROUND_STEPS) || !bare_wall || !fw_wall || !fw_p50 ||
      !bare_p50) {
    fprintf(stderr, "tactus: bench cloth: %s\n", bare ? "out of memory" : tx_error());
    tx_scenario_free(sc);
    tx_cloth_destroy(bare);
    return 1;
  }
  printf("bench cloth: %d x %d = %d particles (0.1 cm), rupture at strain %g, %d iterations, HIP r = %g mm\n"
         "piercing at 1 cm/s; %d rounds of %d steps at %g Hz, bare loop and framework alternating\n\n",
         d.res[0], d.res[1], d.res[0] * d.res[1], d.rupture_strain, d.iterations, HIP_RADIUS * 1e3, rounds,
         ROUND_STEPS, RATE_HZ);

  int rc = 0;
  for (int r = 0; r < rounds && rc == 0; r++) {
    // bare: pose, step, and nothing else
    tx_samples round_ns;
    tx_samples_init(&round_ns, ROUND_STEPS);
    int64_t t0 = tx_mono_ns();
    for (int k = 0; k < ROUND_STEPS; k++) {
      double pose[7];
      hip_at(k / RATE_HZ, pose);
      int64_t s0 = tx_mono_ns();
      tx_cloth_set_hip(bare, pose, HIP_RADIUS);
      tx_cloth_step(bare, 1 / RATE_HZ);
      int64_t ns = tx_mono_ns() - s0;
      tx_samples_add(&bare_ns, ns);
      tx_samples_add(&round_ns, ns);
    }
    bare_wall[r] = (double)(tx_mono_ns() - t0) / ROUND_STEPS;
    bare_p50[r] = tx_samples_percentiles(&round_ns).p50;
    tx_samples_free(&round_ns);

    // framework: the executor runs the same second
    tx_run_options o = {.duration_s = ROUND_STEPS / RATE_HZ, .lockstep = true};
    tx_run_result res;
    t0 = tx_mono_ns();
    if (tx_system_run(sc->system, &o, &res, err, sizeof err)) {
      fprintf(stderr, "tactus: bench cloth: %s\n", err);
      rc = 1;
      break;
    }
    tx_controller_stats st = tx_system_stats(sc->system, skin_index);
    fw_wall[r] = (double)(tx_mono_ns() - t0) / (double)st.steps;
    fw_p50[r] = st.step_ns.p50;
    if (st.step_ns.p99 > fw_p99) fw_p99 = st.step_ns.p99;
    if (st.step_ns.max > fw_max) fw_max = st.step_ns.max;
  }
  if (rc == 0) {
    tx_percentiles b = tx_samples_percentiles(&bare_ns);
    int torn = tx_cloth_torn(bare);
    double mb = median(bare_p50, rounds), mf = median(fw_p50, rounds);
    double wb = median(bare_wall, rounds), wf = median(fw_wall, rounds);
    printf("  %-62s %9s %9s %9s\n", "measure (one physics step)", "p50 ms", "p99 ms", "max ms");
    printf("  %-62s %9.3f %9.3f %9.3f\n", "bare loop: adapter step (Bullet, contact, rupture)", b.p50 * 1e-6,
           b.p99 * 1e-6, b.max * 1e-6);
    printf("  %-62s %9.3f %9.3f %9.3f\n", "framework: physics.skin step + publishes (worst round p99)", mf * 1e-6,
           fw_p99 * 1e-6, fw_max * 1e-6);
    printf("  %-62s %9.3f %9s %9s\n", "bare loop: wall time per step (median of rounds)", wb * 1e-6, "-", "-");
    printf("  %-62s %9.3f %9s %9s\n", "framework: wall time per step, whole executor (median of rounds)", wf * 1e-6,
           "-", "-");
    printf("  links torn in the bare cloth: %d (rupture happened)\n", torn);
    printf("\ntargets:\n");
    char measured[96];
    double hz50 = 1e9 / b.p50, hz99 = 1e9 / b.p99;
    snprintf(measured, sizeof measured, "p50 %.2f ms (%.0f Hz), p99 %.2f ms (%.0f Hz)", b.p50 * 1e-6, hz50,
             b.p99 * 1e-6, hz99);
    print_target("10404-particle step with rupture, 1/p99", measured, ">= 60 Hz", hz99 >= 60);
    double over = 100 * (wf / wb - 1), over_step = 100 * (mf / mb - 1);
    snprintf(measured, sizeof measured, "%.3f / %.3f ms = %+.2f%%", wf * 1e-6, wb * 1e-6, over);
    print_target("framework overhead, wall per step", measured, "<= 5%", over <= 5);
    snprintf(measured, sizeof measured, "%.3f / %.3f ms = %+.2f%%", mf * 1e-6, mb * 1e-6, over_step);
    print_target("framework overhead, step medians", measured, "<= 5%", over_step <= 5);
    if (torn == 0) printf("  (no link tore: the rupture path was not exercised)\n");
  }
  free(bare_wall);
  free(fw_wall);
  free(fw_p50);
  free(bare_p50);
  tx_samples_free(&bare_ns);
  tx_cloth_destroy(bare);
  tx_scenario_free(sc);
  return rc;
}

#else

int tx_bench_cloth(double duration_s) {
  (void)duration_s;
  return tx_bad_input("bench cloth: this build has no Bullet (configured with TX_WITH_BULLET=OFF)");
}

#endif
