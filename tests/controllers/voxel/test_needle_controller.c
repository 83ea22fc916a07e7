// voxel.needle through the loader, in lockstep with the haptics controller
// and scripted:insert: the shipped needle-voxel scenario runs, the force
// model resists the insertion and reaches the device, the drawable
// components have their shapes, and bad parameters are refused by name.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/voxel/recording.h"
#include "scenarios/loader.h"
#include "tests/scenario_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef TX_SOURCE_DIR
#error "TX_SOURCE_DIR must name the source tree"
#endif

static const void* latest_rows(tx_scenario* s, const char* name, uint32_t* rows) {
  tx_model* m = tx_system_model(s->system);
  tx_snapshot snap = tx_model_latest(m, tx_model_find(m, name));
  if (rows) *rows = snap.rows;
  return snap.data;
}

// the shipped scenario for 1.6 s: from 1 mm above at 0.2 s at 3 mm/s, the
// needle ends 3.2 mm deep (the needle runs before haptics in the scenario,
// so it sees the pose of one tick, 3 um, earlier)
static void shipped_scenario_inserts(void** state) {
  (void)state;
  tx_scenario* s = tx_scenario_load(TX_SOURCE_DIR "/scenarios/needle-voxel/needle-voxel.json", NULL);
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.6);
  const double* pose = latest_rows(s, "device0.pose", NULL);
  const double tick = 3e-6 + 1e-9; // m the hand moves in 1 ms
  assert_true(fabs(pose[1] - (0.001 - 0.003 * 1.4)) <= tick);
  const double* fm = latest_rows(s, "tool0.force_model", NULL);
  const double* nf = latest_rows(s, "needle.force", NULL);
  print_message("  3.2 mm deep: force %.4f N (stiffness %.4f, friction %.4f, cutting %.4f), K_yy %.1f N/m, depth %.2f mm\n",
                fm[1], nf[4], nf[7], nf[10], fm[6 + 4], nf[12] * 1e3);
  assert_true(fm[1] > 0);                      // resists: pushes the needle up, out
  assert_true(fabs(fm[4] - pose[1]) <= tick);  // x0 is the tip the force was computed at
  assert_true(fm[6 + 4] <= 0 && fm[6] == 0);   // K = -k a a^T along y only
  for (int a = 0; a < 3; a++) assert_true(fabs(nf[a] - (nf[3 + a] + nf[6 + a] + nf[9 + a])) < 1e-12);
  assert_true(fabs(nf[12] - 3.2e-3) <= 2 * tick);
  // what the device was sent is that force, within the device's safety limits
  const double* sent = latest_rows(s, "device0.force", NULL);
  assert_true(sent[1] > 0 && sent[1] <= 3.3 + 1e-9);
  // the drawables: 1000 spheres and damage, one needle segment from hub to tip
  uint32_t rows;
  const float* sp = latest_rows(s, "tissue.spheres", &rows);
  assert_int_equal(rows, 1000);
  assert_true(sp[3] > 0 && sp[3] <= 0.2178e-3f * 1.0000001f); // the scenario's radius, or less where damaged
  const float* dmg = latest_rows(s, "tissue.damage", &rows);
  assert_int_equal(rows, 1000);
  int damaged = 0;
  for (int i = 0; i < 1000; i++) damaged += dmg[i] > 0;
  const float* seg = latest_rows(s, "needle.segments", &rows);
  assert_int_equal(rows, 1);
  // drawn up to 16 ticks ago: the hub 40 mm above the tip
  assert_true(fabsf(seg[4] - (float)pose[1]) <= 17 * (float)tick && fabsf(seg[1] - seg[4] - 0.04f) < 1e-6f);
  assert_true(fabsf(seg[6] - 0.635e-3f) < 1e-9f);
  assert_true(result(s, "needle.peak_force_n") >= fm[1]);
  assert_true(result(s, "needle.voxels_cut") > 0 && damaged > 0);
  assert_int_equal(warnings(s, "needle.recovered"), 0);
  assert_int_equal(warnings(s, "haptics.force_non_finite"), 0);
  tx_scenario_free(s);
}

// the whole scripted insertion, recorded: OUT/needle-recording.csv reads back
// strictly, and the shipped (fitted) tissue follows the reference curve it
// was fitted to within 10% of its peak, row by row
static void recording_follows_the_reference(void** state) {
  (void)state;
  char dir[] = "/tmp/tx-needle-XXXXXX", path[128];
  assert_non_null(mkdtemp(dir));
  tx_scenario* s = tx_scenario_load(TX_SOURCE_DIR "/scenarios/needle-voxel/needle-voxel.json", NULL);
  if (!s) fail_msg("%s", tx_error());
  tx_run_options o = {.duration_s = 3.8, .lockstep = true, .record_dir = dir};
  tx_run_result r;
  assert_int_equal(tx_system_run(s->system, &o, &r), 0);
  tx_scenario_free(s);
  snprintf(path, sizeof path, "%s/needle-recording.csv", dir);
  tx_recording got, ref;
  if (!tx_recording_read(&got, path)) fail_msg("%s", tx_error());
  assert_true(tx_recording_read(&ref, TX_SOURCE_DIR "/assets/needle/reference-insertion.csv"));
  assert_int_equal(got.count, 3800);
  int events[5] = {0};
  for (size_t k = 0; k < got.count; k++) events[got.rows[k].event]++;
  assert_true(events[TX_EVENT_CONTACT] >= 1 && events[TX_EVENT_PUNCTURE] >= 1 && events[TX_EVENT_RETRACT] == 1 &&
              events[TX_EVENT_EXIT] >= 1);
  double sum = 0, peak = 0;
  size_t n = 0;
  for (size_t k = 0; k < ref.count && k < got.count; k++) {
    assert_true(fabs(got.rows[k].t - ref.rows[k].t) < 1e-9);
    for (int a = 0; a < 3; a++) sum += pow(got.rows[k].f[a] - ref.rows[k].f[a], 2);
    peak = fmax(peak, fabs(ref.rows[k].f[1]));
    n++;
  }
  double rms = sqrt(sum / (double)n);
  print_message("  needle-voxel against the reference: RMS %.4f N, %.1f%% of the %.3f N peak\n", rms, 100 * rms / peak, peak);
  assert_true(rms <= 0.1 * peak);
  tx_recording_free(&got);
  tx_recording_free(&ref);
  unlink(path);
  snprintf(path, sizeof path, "%s/device0.bin", dir);
  unlink(path);
  snprintf(path, sizeof path, "%s/device0.csv", dir);
  unlink(path);
  assert_int_equal(rmdir(dir), 0);
}

static void bad_params_named(void** state) {
  (void)state;
  const struct { const char* params; const char* key; } cases[] = {
      {"\"tip\":\"sharp\"", "params.tip"},       {"\"gauge\":9", "params.gauge"},
      {"\"count_x\":0", "params.count_x"},       {"\"radius_m\":-1", "params.radius_m"},
      {"\"friction\":\"lots\"", "params.friction"}, {"\"elasticity\":1.5", "params.elasticity"},
      {"\"bogus\":1", "params.bogus"},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    char text[512];
    snprintf(text, sizeof text,
             "{\"name\":\"t\",\"controllers\":[{\"name\":\"needle\",\"type\":\"voxel.needle\",\"rate_hz\":1000,"
             "\"params\":{%s}},{\"name\":\"h\",\"type\":\"haptics\",\"rate_hz\":1000,\"params\":{\"device\":"
             "\"scripted:insert\",\"force_model\":\"tool0.force_model\"}}]}",
             cases[k].params);
    tx_scenario* s = tx_scenario_load_text("t.json", text, strlen(text), NULL);
    if (s) fail_msg("case %zu loaded", k);
    if (!strstr(tx_error(), cases[k].key)) fail_msg("case %zu: '%s' lacks '%s'", k, tx_error(), cases[k].key);
    assert_null(strchr(tx_error(), '\n'));
  }
}

// the recording is written in finish: one that cannot be (its temporary file
// is taken by a folder here) stops the run with the file's name
static void a_recording_that_cannot_be_written_stops_the_run(void** state) {
  (void)state;
  char dir[] = "/tmp/tx-needle-XXXXXX", taken[128];
  assert_non_null(mkdtemp(dir));
  snprintf(taken, sizeof taken, "%s/needle-recording.csv.tmp", dir);
  assert_int_equal(mkdir(taken, 0755), 0);
  tx_scenario* s = tx_scenario_load(TX_SOURCE_DIR "/scenarios/needle-voxel/needle-voxel.json", NULL);
  if (!s) fail_msg("%s", tx_error());
  tx_run_options o = {.duration_s = 0.1, .lockstep = true, .record_dir = dir};
  tx_run_result r;
  assert_int_equal(tx_system_run(s->system, &o, &r), 0);
  tx_scenario_free(s);
  print_message("  %s\n", r.halt_reason);
  assert_true(r.halted);
  char want[256];
  snprintf(want, sizeof want, "%s/needle-recording.csv: Is a directory", dir);
  if (!strstr(r.halt_reason, want)) fail_msg("'%s' lacks '%s'", r.halt_reason, want);
  char cmd[256];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  assert_int_equal(system(cmd), 0);
}

int main(void) {
  tx_register_builtin();
  const struct CMUnitTest tests[] = {cmocka_unit_test(shipped_scenario_inserts),
                                     cmocka_unit_test(recording_follows_the_reference),
                                     cmocka_unit_test(a_recording_that_cannot_be_written_stops_the_run),
                                     cmocka_unit_test(bad_params_named)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
