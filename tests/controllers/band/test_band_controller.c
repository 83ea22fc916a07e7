// physics.band through the loader, in lockstep: it publishes band.x/.tri
// (the two parts' nodes and their boundary faces: closed, outward) and band.state at rest;
// a substep far past the stable one faults, and the fault is counted and
// recovered, never published; a grasper closing across the tube's middle
// picks its triangles and lifts it, and opening lets go; the band at rest
// sleeps (not stepped, not published) until such a grasp wakes it; bad
// parameters and assets are refused with one line naming the key and the file.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "scenarios/loader.h"
#include "tests/scenario_support.h"

#include <tactus/components.h>
#include <tactus/config.h>
#include <tactus/events.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static tx_scenario* load(const char* params) {
  char text[2048];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":[{\"name\":\"band\",\"type\":\"physics.band\",\"rate_hz\":60,\"params\":{%s}}]}",
           params);
  return tx_scenario_load_text("test", text, strlen(text), NULL);
}

static int cmp_long(const void* a, const void* b) {
  long p = *(const long*)a, q = *(const long*)b;
  return (p > q) - (p < q);
}

static bool all_finite(tx_snapshot x) {
  const float* p = x.data;
  for (uint32_t i = 0; i < 3 * x.rows; i++)
    if (!isfinite(p[i])) return false;
  return true;
}

static void publishes_the_band(void** state) {
  (void)state;
  tx_scenario* s = load("");
  if (!s) fail_msg("%s", tx_error());
  run(s, 0.1);
  tx_snapshot x = latest_snapshot(s, "band.x"), t = latest_snapshot(s, "band.tri");
  assert_int_equal(x.rows, 150 + 164); // the ring's nodes, then the tube's
  assert_true(all_finite(x));
  // every face's nodes in range, and the surface closed: each edge in two faces, run both ways
  const int32_t* f = t.data;
  for (uint32_t i = 0; i < 3 * t.rows; i++) assert_true(f[i] >= 0 && f[i] < (int32_t)x.rows);
  long* e = malloc(sizeof(long) * 3 * t.rows);
  assert_non_null(e);
  for (uint32_t i = 0; i < t.rows; i++)
    for (int k = 0; k < 3; k++) e[3 * i + k] = (long)f[3 * i + k] * x.rows + f[3 * i + (k + 1) % 3];
  qsort(e, 3 * t.rows, sizeof(long), cmp_long);
  for (uint32_t i = 0; i < 3 * t.rows; i++) {
    long a = e[i] / x.rows, b = e[i] % x.rows, back = b * x.rows + a;
    assert_true(i == 0 || e[i] != e[i - 1]);                                  // no edge run twice the same way
    assert_non_null(bsearch(&back, e, 3 * t.rows, sizeof(long), cmp_long)); // and each run back by its neighbour
  }
  free(e);
  // the boundary's signed volume: the two parts' (5.17 and 1.35 cm^3), positive (outward)
  const float* p = x.data;
  double vol = 0;
  for (uint32_t i = 0; i < t.rows; i++) {
    const float *a = p + 3 * f[3 * i], *b = p + 3 * f[3 * i + 1], *c = p + 3 * f[3 * i + 2];
    vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6;
  }
  print_message("  band.x %u rows, band.tri %u rows, volume %.4g cm^3\n", x.rows, t.rows, vol * 1e6);
  assert_true(fabs(vol * 1e6 - 6.52) < 0.05);
  const tx_band_state* st = latest_snapshot(s, "band.state").data;
  assert_true(st->locked == 0);
  assert_true(fabs(st->joint_length - 0.003) < 3e-5 && fabs(st->joint_error) < 0.01);
  assert_true(st->tip_to_buckle > 0.05);
  assert_true(result(s, "band.substeps") == 667);
  assert_true(result(s, "band.faults") == 0);
  tx_scenario_free(s);
}

static void fault_is_recovered(void** state) {
  (void)state;
  tx_scenario* s = load("\"max_substep_s\":0.0002");
  if (!s) fail_msg("%s", tx_error());
  run(s, 0.1);
  assert_true(warnings(s, "band.numerical_fault") > 0);
  assert_true(result(s, "band.faults") > 0);
  assert_true(all_finite(latest_snapshot(s, "band.x")));
  tx_scenario_free(s);
}

// a test class: jaws (jaws.pose, tx_instrument_pose) at jaws_at along
// jaws_q's x: open until jaws_t0 + 0.1 s, closed by + 0.2 s, lifted LIFT by
// + 0.7 s, held to + 1.0 s, open again by + 1.1 s. It keeps the band's grasp
// and release events, band.centre's rows `row` and `row - 6` as they were at
// + 0.95 s, and band.x's sequence number at jaws_t0 - 0.3 s and - 0.05 s
#define LIFT 0.01 // m
typedef struct jaws_probe {
  tx_port pose, centre, events, x;
  int row, grasps, releases;
  double held[3], near[3]; // m, the centre line's rows at 0.95 s
  uint64_t seq_early, seq_late;
} jaws_probe;
static jaws_probe probe;
static double jaws_at[3], jaws_q[4], jaws_t0;
static int jaws_configure(tx_setup* s, void** self) {
  probe.pose = tx_setup_write(s, &TX_COMPONENT_OF("jaws.pose", tx_instrument_pose, 1));
  probe.centre = tx_setup_read(s, "band.centre");
  probe.events = tx_setup_listen(s, "band.events");
  probe.x = tx_setup_read(s, "band.x");
  probe.grasps = probe.releases = 0;
  probe.seq_early = probe.seq_late = 0;
  probe.held[1] = NAN;
  *self = &probe;
  return 0;
}
static double ramp(double t, double a, double b) { return t <= a ? 0 : t >= b ? 1 : (t - a) / (b - a); }
static void jaws_step(tx_ctx* c, void* self) {
  jaws_probe* p = self;
  double t = (double)tx_sim_ns(c) * 1e-9 - jaws_t0;
  uint64_t seq = tx_read(c, p->x).seq;
  if (t >= -0.3 && !p->seq_early) p->seq_early = seq;
  if (t >= -0.05 && !p->seq_late) p->seq_late = seq;
  tx_instrument_pose* j = tx_write(c, p->pose);
  memcpy(j->pos, jaws_at, sizeof jaws_at);
  j->pos[1] += LIFT * ramp(t, 0.2, 0.7);
  memcpy(j->quat, jaws_q, sizeof jaws_q);
  j->jaw = 0.6 * (1 - ramp(t, 0.1, 0.2)) + 0.6 * ramp(t, 1.0, 1.1);
  tx_event e;
  while (tx_next_event(c, p->events, &e)) p->grasps += e.kind == TX_EVENT_GRASP, p->releases += e.kind == TX_EVENT_RELEASE;
  tx_snapshot cs = tx_read(c, p->centre);
  if (cs.seq && t >= 0.95 && isnan(p->held[1]))
    for (int a = 0; a < 3; a++)
      p->held[a] = ((const float*)cs.data)[3 * p->row + a], p->near[a] = ((const float*)cs.data)[3 * (p->row - 6) + a];
}
static const tx_controller_class jaws_class = {
    .type = "test.band_jaws", .summary = "jaws across the tube", .configure = jaws_configure, .step = jaws_step};

// the jaws, 20 mm long, closed across the tube's middle (band.centre's row
// three quarters along) with their middle on it, neither end in reach: they
// pick the surface triangles within 3 mm of their line; lifted 1 cm, that
// part of the tube goes up with them (the picked nodes' moves spread over
// the band's 667 substeps, so none outruns max_speed: no fault); with the
// buckle held, the band between it and the jaws (band.centre's rows run
// from the buckle) follows part of the way through its solver; opened, the
// jaws let go: one grasp, one release
static tx_scenario* grasp_the_tube(double t0, double* lifted, double* beside) {
  if (!tx_find_controller(jaws_class.type)) assert_int_equal(tx_register_controller(&jaws_class), 0);
  tx_scenario* s = load("");
  if (!s) fail_msg("%s", tx_error());
  run(s, 0.02);
  tx_snapshot cs = latest_snapshot(s, "band.centre");
  const float* cl = cs.data;
  const int row = (int)cs.rows - (int)cs.rows / 4;
  double c0[3], t[3], up[3] = {0, 1, 0}, across[3], near0[3];
  for (int a = 0; a < 3; a++)
    c0[a] = cl[3 * row + a], t[a] = cl[3 * row + 3 + a] - cl[3 * row - 3 + a], near0[a] = cl[3 * (row - 6) + a];
  tx_scenario_free(s);
  // across the tube and level: its tangent times up
  across[0] = t[1] * up[2] - t[2] * up[1], across[1] = t[2] * up[0] - t[0] * up[2], across[2] = t[0] * up[1] - t[1] * up[0];
  double n = sqrt(across[0] * across[0] + across[1] * across[1] + across[2] * across[2]);
  assert_true(n > 0);
  for (int a = 0; a < 3; a++) across[a] /= n;
  // the quaternion taking x to across: (1 + x.across, x times across), normalised
  double q[4] = {1 + across[0], 0, -across[2], across[1]}, qn = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  assert_true(qn > 1e-6);
  for (int a = 0; a < 4; a++) jaws_q[a] = q[a] / qn;
  for (int a = 0; a < 3; a++) jaws_at[a] = c0[a] - 0.01 * across[a];
  probe.row = row;
  jaws_t0 = t0;

  const char* text = "{\"name\":\"t\",\"controllers\":["
                     "{\"name\":\"jaws\",\"type\":\"test.band_jaws\",\"rate_hz\":60},"
                     "{\"name\":\"band\",\"type\":\"physics.band\",\"rate_hz\":60,\"params\":{\"grasp\":[\"jaws.pose\"],\"hold_buckle\":true}}]}";
  s = tx_scenario_load_text("test", text, strlen(text), NULL);
  if (!s) fail_msg("%s", tx_error());
  run(s, t0 + 1.3);
  *lifted = probe.held[1] - c0[1], *beside = probe.near[1] - near0[1];
  return s;
}

static void grasper_picks_the_tube(void** state) {
  (void)state;
  double lifted, beside;
  tx_scenario* s = grasp_the_tube(0, &lifted, &beside);
  print_message("  held: the tube's centre there %.2f mm up (the jaws %.0f mm), 6 sections along %.2f mm; "
                "%g nodes held, pull %.3g N; %d grasp, %d release\n",
                1e3 * lifted, 1e3 * LIFT, 1e3 * beside, result(s, "band.grasp_nodes_max"),
                result(s, "band.grasp_force_max_n"), probe.grasps, probe.releases);
  assert_true(fabs(lifted - LIFT) < 0.1 * LIFT);
  assert_true(beside > 0.05 * LIFT && beside < lifted - 0.05 * LIFT);
  assert_int_equal(probe.grasps, 1);
  assert_int_equal(probe.releases, 1);
  assert_true(result(s, "band.grasps") == 1);
  assert_true(result(s, "band.grasp_nodes_max") >= 4);
  assert_true(result(s, "band.faults") == 0);
  assert_true(all_finite(latest_snapshot(s, "band.x")));
  tx_scenario_free(s);
}

// the same grasp 1 s later: at rest, the band sleeps from 0.5 s (nothing
// stepped or published: band.x's sequence number stands still), the jaws'
// grasp wakes it, and the tube is lifted as when it never slept
static void sleeps_until_a_grasp(void** state) {
  (void)state;
  double lifted, beside;
  tx_scenario* s = grasp_the_tube(1.0, &lifted, &beside);
  print_message("  asleep %.3f s, %g wake; band.x seq %llu at 0.7 s, %llu at 0.95 s; lifted %.2f mm, 6 sections along %.2f mm\n",
                result(s, "band.asleep_s"), result(s, "band.wakes"), (unsigned long long)probe.seq_early,
                (unsigned long long)probe.seq_late, 1e3 * lifted, 1e3 * beside);
  assert_true(probe.seq_early > 0 && probe.seq_late == probe.seq_early);
  assert_true(result(s, "band.asleep_s") > 0.5 - 1e-9); // 0.5 s to 1.1 s, when the jaws close
  assert_true(result(s, "band.wakes") == 1);
  assert_true(fabs(lifted - LIFT) < 0.1 * LIFT);
  assert_true(beside > 0.05 * LIFT && beside < lifted - 0.05 * LIFT);
  assert_int_equal(probe.grasps, 1);
  assert_true(result(s, "band.faults") == 0);
  tx_scenario_free(s);
}

static void expect_refused(const char* params, const char* needle) { assert_refused(load(params), needle); }

static void bad_parameters_and_assets(void** state) {
  (void)state;
  expect_refused("\"tube_poisson\":0.5", "tube_poisson");
  expect_refused("\"buckle_radius_m\":0", "buckle_radius_m");
  expect_refused("\"assets\":\"/nonexistent/lagb\"", "/nonexistent/lagb/band_ring.node");
  expect_refused("\"pull\":\"nothing.here\"", "nothing.here");
  expect_refused("\"grasp\":[\"jaws.pose\"],\"grasp_triangle_reach_m\":-1", "grasp_triangle_reach_m");
  expect_refused("\"sleep_speed_m_s\":-0.001", "sleep_speed_m_s");
  expect_refused("\"sleep_after_s\":0", "sleep_after_s");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(publishes_the_band),
      cmocka_unit_test(fault_is_recovered),
      cmocka_unit_test(grasper_picks_the_tube),
      cmocka_unit_test(sleeps_until_a_grasp),
      cmocka_unit_test(bad_parameters_and_assets),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
