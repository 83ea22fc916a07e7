// tactus bench cloth: the skin's physics step at the papers' high density
// (102 x 102 = 10404 particles, 0.1 cm), rupture active and a HIP piercing
// it, against a 60 Hz frame (XPBD, ten substeps of one iteration), and each
// solver alone on suturing-skin's 42 x 42 patch; and the framework's overhead: the physics.skin
// controller (reading the pose, publishing skin.x, skin.tri, skin.thickness
// and skin.torn, the finite check; timed by the executor, publishes
// included) against a bare loop that steps an identical cloth through the
// adapter alone. Both run in one lockstep run, stepped alternately at every
// 60 Hz tick, so that a busy machine slows both alike.
#include "bench_cloth.h"
#include "studies.h"

#include "../scenarios/command.h"

#include <tactus/stats.h>

#include <tactus/components.h>
#include <tactus/config.h>

#include <stdio.h>
#include <string.h>

#if TX_WITH_BULLET
#include "../controllers/physics/bullet/cloth.h"

#include <math.h>
#include <stdlib.h>

#define RATE_HZ 60.0
#define SPACING 0.001   // m, the journal paper's 0.1 cm
#define HIP_RADIUS 0.0005
#define PERIOD_S 1.0    // the HIP's motion repeats every second

// the HIP: from 5 mm above the skin down at 2 cm/s, through it, every second
static void hip_at(double t, double pos[7]) {
  memset(pos, 0, 7 * sizeof *pos);
  pos[1] = 0.005 - 0.02 * fmod(t, PERIOD_S);
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
  k->pose = tx_setup_write(s, &TX_COMPONENT_OF("device0.pose", tx_pose, 1));
  return 0;
}
static void script_step(tx_ctx* c, void* self) {
  hip_at((double)tx_sim_ns(c) * 1e-9, tx_write(c, ((script*)self)->pose));
}
static void script_fini(void* self) { free(self); }
static const tx_controller_class script_class = {.type = "bench.hip_script",
                                                 .summary = "the HIP of bench cloth: down at 2 cm/s, every second",
                                                 .configure = script_configure,
                                                 .step = script_step,
                                                 .fini = script_fini};

// the bare loop, as a controller only so that it shares the executor's
// ticks: it times the adapter's set_hip + step and nothing else
typedef struct bare {
  tx_cloth* cloth;
  tx_hist ns; // step times, ns
} bare;
static bare* bench_bare; // the bench's own, for the one run it makes

static int bare_configure(tx_setup* s, void** self) {
  (void)s;
  *self = bench_bare;
  return bench_bare ? 0 : -1;
}
static void bare_step(tx_ctx* c, void* self) {
  bare* b = self;
  double pose[7];
  hip_at((double)tx_sim_ns(c) * 1e-9, pose);
  int64_t t0 = tx_mono_ns();
  tx_cloth_set_hip(b->cloth, pose, HIP_RADIUS);
  tx_cloth_step(b->cloth, 1 / RATE_HZ);
  tx_hist_add(&b->ns, tx_mono_ns() - t0);
}
static const tx_controller_class bare_class = {.type = "bench.bare_cloth",
                                               .summary = "steps a cloth through the adapter alone, timed",
                                               .configure = bare_configure,
                                               .step = bare_step};

// a patch of res x res particles at the spacing (rupture at its default)
// stepped alone under the same HIP for the given simulated seconds, with the
// given solver (XPBD at its old real-time setting: ten substeps of one
// iteration); its step times. 0, or -1 with tx_error()
static int alone_steps(int res, double spacing, int solver, int coarse, int newton, double seconds, tx_hist* ns,
                       int* torn) {
  tx_cloth_def d = tx_cloth_def_default();
  d.res[0] = d.res[1] = res;
  d.coarse_block = coarse;
  d.newton_steps = newton;
  d.size[0] = d.size[1] = (res - 1) * spacing;
  d.solver = solver;
  if (solver == TX_CLOTH_XPBD) d.max_substep = 1.0 / 600;
  tx_cloth* c = tx_cloth_create(&d);
  if (!c) return -1;
  const int steps = (int)lround(seconds * RATE_HZ);
  for (int k = 0; k < steps; k++) {
    double pose[7];
    hip_at(k / RATE_HZ, pose);
    int64_t t0 = tx_mono_ns();
    tx_cloth_set_hip(c, pose, HIP_RADIUS);
    tx_cloth_step(c, 1 / RATE_HZ);
    tx_hist_add(ns, tx_mono_ns() - t0);
  }
  *torn = tx_cloth_torn(c);
  tx_cloth_destroy(c);
  return 0;
}

int tx_bench_cloth(double duration_s) {
  const double seconds = duration_s > 0 ? duration_s : 20;
  if (!tx_find_controller(script_class.type)) tx_register_controller(&script_class);
  if (!tx_find_controller(bare_class.type)) tx_register_controller(&bare_class);

  // the bare cloth, as physics.skin builds it for the same parameters
  static bare b; // its histogram is large: not on the stack
  b = (bare){0};
  // XPBD at ten substeps of one iteration, the solver this target was set for (the
  // implicit one at this density is measured alone below)
  tx_cloth_def d = tx_cloth_def_default();
  d.solver = TX_CLOTH_XPBD;
  d.max_substep = 1.0 / 600;
  d.res[0] = d.res[1] = (int)lround(0.1 / SPACING) + 2;
  d.size[0] = d.size[1] = (d.res[0] - 1) * SPACING;
  b.cloth = tx_cloth_create(&d);
  if (!b.cloth) {
    fprintf(stderr, "tactus: bench cloth: %s\n", tx_error());
    tx_cloth_destroy(b.cloth);
    return 1;
  }
  bench_bare = &b;

  // the framework's skin and the bare one at the same rate, the bare one first at every tick
  char text[1024];
  snprintf(text, sizeof text,
           "{\"name\":\"bench-cloth\",\"controllers\":["
           "{\"name\":\"hip\",\"type\":\"bench.hip_script\",\"rate_hz\":%g},"
           "{\"name\":\"bare\",\"type\":\"bench.bare_cloth\",\"rate_hz\":%g},"
           "{\"name\":\"skin\",\"type\":\"physics.skin\",\"rate_hz\":%g,"
           "\"params\":{\"spacing_m\":%g,\"hip_radius_m\":%g,\"solver\":\"xpbd\",\"max_substep_s\":%.17g}}]}",
           RATE_HZ, RATE_HZ, RATE_HZ, SPACING, HIP_RADIUS, d.max_substep);
  tx_scenario* sc = tx_scenario_load_text("bench-cloth", text, strlen(text), NULL);
  int rc = 0;
  if (!sc) {
    fprintf(stderr, "tactus: %s\n", tx_error());
    rc = 1;
  }
  printf("bench cloth: %d x %d = %d particles (0.1 cm), rupture at %g N/m over %g mm, XPBD (%d iteration, 1/600 s), HIP r = %g mm\n"
         "piercing at 2 cm/s every second; %g s at %g Hz in lockstep, the bare loop and physics.skin stepped "
         "alternately\n\n",
         d.res[0], d.res[1], d.res[0] * d.res[1], d.rupture_tension, d.rupture_length * 1e3, d.iterations, HIP_RADIUS * 1e3, seconds, RATE_HZ);
  tx_controller_stats st = {0};
  if (rc == 0) {
    tx_run_options o = {.duration_s = seconds, .lockstep = true};
    tx_run_result res;
    if (tx_system_run(sc->system, &o, &res)) {
      fprintf(stderr, "tactus: bench cloth: %s\n", tx_error());
      rc = 1;
    }
    for (int i = 0; rc == 0 && i < tx_system_count(sc->system); i++)
      if (strcmp(tx_system_name(sc->system, i), "skin") == 0) st = tx_system_stats(sc->system, i);
  }
  if (rc == 0) {
    tx_percentiles p = tx_hist_percentiles(&b.ns);
    int torn = tx_cloth_torn(b.cloth);
    printf("  %-58s %9s %9s %9s\n", "one physics step", "p50 ms", "p99 ms", "max ms");
    printf("  %-58s %9.3f %9.3f %9.3f\n", "bare loop: adapter step (Bullet, contact, rupture)", p.p50 * 1e-6,
           p.p99 * 1e-6, p.max * 1e-6);
    printf("  %-58s %9.3f %9.3f %9.3f\n", "framework: physics.skin step, publishes included", st.step_ns.p50 * 1e-6,
           st.step_ns.p99 * 1e-6, st.step_ns.max * 1e-6);
    printf("  %llu steps each; links torn in the bare cloth: %d\n", (unsigned long long)st.steps, torn);
    printf("\ntargets:\n");
    char measured[96];
    double hz50 = 1e9 / p.p50, hz99 = 1e9 / p.p99;
    snprintf(measured, sizeof measured, "p50 %.2f ms (%.0f Hz), p99 %.2f ms (%.0f Hz)", p.p50 * 1e-6, hz50,
             p.p99 * 1e-6, hz99);
    tx_bench_target("10404-particle step with rupture, 1/p99", measured, ">= 60 Hz", hz99 >= 60 && torn > 0);
    double over = 100 * (st.step_ns.p50 / p.p50 - 1);
    snprintf(measured, sizeof measured, "%.3f / %.3f ms = %+.2f%%", st.step_ns.p50 * 1e-6, p.p50 * 1e-6, over);
    tx_bench_target("framework overhead, step medians", measured, "<= 5%", over <= 5);
    if (torn == 0) printf("  (no link tore: the rupture path was not exercised)\n");

    // each solver alone: physics.skin's default patch (42 x 42, 2.5 mm), suturing-skin's as it
    // ships (62 x 62, 1/600 m, the two-level CG, one Newton step), and the implicit one at 0.1 cm
    // for at most 2 s (it is not real time there)
    static tx_hist hs[4]; // large: not on the stack
    int torn2[4] = {0, 0, 0, 0};
    static const char* const name[4] = {"42 x 42, implicit (default: one substep, Newton + PCG)",
                                        "42 x 42, XPBD (ten substeps of one iteration)",
                                        "102 x 102, implicit",
                                        "62 x 62, implicit, two-level CG, 1 Newton (suturing-skin)"};
    static const int res_of[4] = {42, 42, 0, 62}, coarse_of[4] = {0, 0, 0, 6}, newton_of[4] = {2, 2, 2, 1};
    printf("\n  %-58s %9s %9s %9s\n", "one 60 Hz step, each solver alone", "p50 ms", "p99 ms", "max ms");
    for (int k = 0; k < 4 && rc == 0; k++) {
      memset(&hs[k], 0, sizeof hs[k]);
      if (alone_steps(res_of[k] ? res_of[k] : d.res[0], k == 2 ? SPACING : k == 3 ? 0.1 / 60 : 0.0025,
                      k == 1 ? TX_CLOTH_XPBD : TX_CLOTH_IMPLICIT, coarse_of[k], newton_of[k],
                      k != 2 ? seconds : fmin(seconds, 2), &hs[k], &torn2[k])) {
        fprintf(stderr, "tactus: bench cloth: %s\n", tx_error());
        rc = 1;
        break;
      }
      tx_percentiles q = tx_hist_percentiles(&hs[k]);
      printf("  %-58s %9.3f %9.3f %9.3f\n", name[k], q.p50 * 1e-6, q.p99 * 1e-6, q.max * 1e-6);
      if (k == 0) {
        snprintf(measured, sizeof measured, "p50 %.2f ms, p99 %.2f ms (%.0f Hz)", q.p50 * 1e-6, q.p99 * 1e-6,
                 1e9 / q.p99);
        tx_bench_target("1764-particle implicit step, 1/p99", measured, ">= 60 Hz", 1e9 / q.p99 >= 60 && torn2[0] > 0);
      }
      if (k == 3) {
        snprintf(measured, sizeof measured, "p50 %.2f ms, p99 %.2f ms (%.0f Hz)", q.p50 * 1e-6, q.p99 * 1e-6,
                 1e9 / q.p99);
        tx_bench_target("suturing-skin's 3844-particle step, 1/p99", measured, ">= 60 Hz", 1e9 / q.p99 >= 60 && torn2[3] > 0);
      }
    }
    printf("  (the executor's own cost per tick, a few us, is in `tactus bench overhead`)\n");
  }
  bench_bare = NULL;
  tx_scenario_free(sc);
  tx_cloth_destroy(b.cloth);
  return rc;
}

#else

int tx_bench_cloth(double duration_s) {
  (void)duration_s;
  return tx_bad_input("bench cloth: this build has no Bullet (configured with TX_WITH_BULLET=OFF)");
}

#endif
