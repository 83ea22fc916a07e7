// Grasper picking in physics.organs, through the loader in lockstep on the
// coarse copy of the LAGB assets: physics.instruments' lap grasper
// (assets/instruments/lap_grasper.urdf), driven by a scripted hand, comes
// down to the liver's anterior surface with open jaws, closes on it, lifts
// it 1 cm, holds, opens and rises: one grasp event (at the surface, from
// hand 0) and then one release on organs.events; while held, the liver's
// surface between the jaws is lifted by about the lift, organs.grasp gives
// the nodes held and the liver's pull on the jaws, down towards its rest;
// released, the surface falls back. Two graspers pick at once, each its
// own. Bad grasp parameters are refused with one line naming the key.
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
#include <unistd.h>

#define COARSE TX_TEST_DIR "/coarse"
#define LIFT 0.01 // m

static double spot[3], spot2[3]; // the coarse liver's drawn vertices grasped by hand 0 and hand 1
static int spot_row, spot2_row;   // their rows of liver.x

// the coarse liver's highest drawn vertex within 12 mm of (x, z)
static void find_spot(double x, double z, double out[3], int* out_row) {
  FILE* f = fopen(COARSE "/liver.obj", "r");
  assert_non_null(f);
  char line[256];
  out[1] = -1;
  int row = 0;
  while (fgets(line, sizeof line, f)) {
    double p[3];
    if (line[0] != 'v' || line[1] != ' ' || sscanf(line + 2, "%lf %lf %lf", p, p + 1, p + 2) != 3) continue;
    if (hypot(p[0] - x, p[2] - z) < 0.012 && p[1] > out[1]) memcpy(out, p, 3 * sizeof(double)), *out_row = row;
    row++;
  }
  fclose(f);
  assert_true(out[1] > 0.03);
}

// a test class that keeps every event of organs.events
#define EVENTS_MAX 16
typedef struct listener {
  tx_port in;
  tx_event got[EVENTS_MAX];
  int n;
} listener;
static listener the_listener;
static int listen_configure(tx_setup* s, void** self) {
  *self = &the_listener;
  the_listener.in = tx_setup_listen(s, "organs.events");
  the_listener.n = 0;
  return 0;
}
static void listen_step(tx_ctx* c, void* self) {
  listener* l = self;
  tx_event e;
  while (tx_next_event(c, l->in, &e))
    if (l->n < EVENTS_MAX) l->got[l->n++] = e;
}
static const tx_controller_class listener_class = {
    .type = "test.organs_listener", .summary = "keeps organs.events", .configure = listen_configure, .step = listen_step};

static char hand[64], hand2[64]; // the scripted hands' waypoints (temporary files)

// The grasper's pivot 1 mm under the spot, 1 cm behind it along x (its
// jaws, along x, reach 1 cm past it): 2 cm above from the start with the
// jaws open (grip 0.6 rad), down by 0.4 s, closed by 0.7 s, lifted by 1.2 s,
// held to 1.8 s, opened by 1.9 s, risen 3 cm by 2.5 s.
static int write_hand(char* path, const double at[3], double lift) {
  snprintf(path, 64, "/tmp/tx_organs_grasp_XXXXXX.csv");
  int fd = mkstemps(path, 4);
  if (fd < 0) return -1;
  close(fd);
  FILE* f = fopen(path, "w");
  if (!f) return -1;
  const double x = at[0] - 0.01, y = at[1] - 0.001, z = at[2];
  fprintf(f, "t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad\n");
  const double rows[][3] = {{0, 0.02, 0.6},    {0.4, 0, 0.6},    {0.5, 0, 0.6},    {0.7, 0, 0},
                            {1.2, lift, 0},    {1.8, lift, 0},   {1.9, lift, 0.6}, {2.5, lift + 0.03, 0.6}};
  for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++)
    fprintf(f, "%g,%.9g,%.9g,%.9g,1,0,0,0,%g\n", rows[i][0], x, y + rows[i][1], z, rows[i][2]);
  fclose(f);
  return 0;
}

static int setup(void** state) {
  (void)state;
  find_spot(0.06, 0.06, spot, &spot_row);
  find_spot(-0.05, 0.06, spot2, &spot2_row); // 11 cm from it along x: the coarse tetrahedra (2 to 3 cm) carry no vertex of both
  if (!tx_find_controller(listener_class.type) && tx_register_controller(&listener_class)) return -1;
  return write_hand(hand, spot, LIFT) || write_hand(hand2, spot2, LIFT / 2);
}

static int teardown(void** state) {
  (void)state;
  unlink(hand);
  unlink(hand2);
  return 0;
}

// params: the organs' picking parameters (JSON members, after "grasp")
static tx_scenario* load(const char* params) {
  char text[4096];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":["
           "{\"name\":\"haptics\",\"type\":\"haptics\",\"rate_hz\":1000,"
           "\"params\":{\"device\":\"scripted:%s\",\"force_model\":\"instrument0.force_model\"}},"
           "{\"name\":\"instruments\",\"type\":\"physics.instruments\",\"rate_hz\":1000,"
           "\"params\":{\"instrument0\":\"lap_grasper\",\"table_height_m\":-1,\"gravity_m_s2\":0}},"
           "{\"name\":\"organs\",\"type\":\"physics.organs\",\"rate_hz\":30,"
           "\"params\":{\"assets\":\"" COARSE "\",\"tool_radius_m\":0%s}},"
           "{\"name\":\"listener\",\"type\":\"test.organs_listener\",\"rate_hz\":30}]}",
           hand, params);
  return tx_scenario_load_text("test", text, strlen(text), NULL);
}

static double height(tx_scenario* s, int row) {
  tx_snapshot x = latest_snapshot(s, "liver.x");
  assert_true((int)x.rows > row);
  return ((const float*)x.data)[3 * row + 1];
}
static double spot_height(tx_scenario* s) { return height(s, spot_row); }

// each run starts the scenario over (its controllers' init), so each
// question is a scenario of its own: held at 1.8 s, and let go by 2.6 s
static void grasper_lifts_the_liver(void** state) {
  (void)state;
  tx_scenario* s = load(",\"grasp\":[\"instrument0.pose\"]");
  if (!s) fail_msg("%s", tx_error());
  the_listener.n = 0;
  run(s, 1.8);
  assert_int_equal(the_listener.n, 1);
  const tx_event g = the_listener.got[0];
  print_message("  grasp by hand %u at (%.1f, %.1f, %.1f) mm, jaws %.3f rad, %.2f s; the spot (%.1f, %.1f, %.1f) mm\n",
                g.source, g.grasp.point[0] * 1e3, g.grasp.point[1] * 1e3, g.grasp.point[2] * 1e3, g.grasp.jaw,
                g.sim_ns * 1e-9, spot[0] * 1e3, spot[1] * 1e3, spot[2] * 1e3);
  assert_int_equal(g.kind, TX_EVENT_GRASP);
  assert_int_equal(g.source, 0);
  assert_true(g.grasp.jaw <= 0.1);
  assert_true(g.sim_ns > 500000000 && g.sim_ns <= 700000000); // as the jaws close, not while open
  assert_true(hypot(hypot(g.grasp.point[0] - spot[0], g.grasp.point[1] - spot[1]), g.grasp.point[2] - spot[2]) < 0.01);
  const double lifted = spot_height(s) - spot[1]; // gravity off: the asset is the rest
  const tx_organ_grasp* r = latest_snapshot(s, "organs.grasp").data;
  const double* pivot = latest(s, "instrument0.pose");
  print_message("  held at 1.8 s: the spot lifted %.2f mm (the hand %.0f mm, the pivot %.2f mm); %g nodes, %g "
                "triangles; pull (%.3f, %.3f, %.3f) N\n",
                lifted * 1e3, LIFT * 1e3, (pivot[1] - (spot[1] - 0.001)) * 1e3, r->nodes, r->triangles, r->f[0], r->f[1],
                r->f[2]);
  assert_true(fabs(lifted - LIFT) < 0.0015); // with the jaws, which follow the hand through the coupling
  // the surface around follows part of the way (the solver, not the jaws)
  float* rest = malloc(sizeof(float) * 3 * 400);
  FILE* obj = fopen(COARSE "/liver.obj", "r");
  assert_non_null(obj);
  char line[256];
  int nv = 0;
  while (fgets(line, sizeof line, obj) && nv < 400)
    if (line[0] == 'v' && line[1] == ' ' && sscanf(line + 2, "%f %f %f", rest + 3 * nv, rest + 3 * nv + 1, rest + 3 * nv + 2) == 3) nv++;
  fclose(obj);
  tx_snapshot x = latest_snapshot(s, "liver.x");
  assert_int_equal((int)x.rows, nv);
  int part = 0;
  for (int v = 0; v < nv; v++) {
    double up = ((const float*)x.data)[3 * v + 1] - rest[3 * v + 1];
    if (up > 0.001 && up < LIFT - 0.001) part++;
  }
  free(rest);
  print_message("  %d drawn vertices lifted part of the way (1 to 9 mm)\n", part);
  assert_true(part >= 3);
  assert_true(r->nodes >= 3 && r->triangles >= 1);
  assert_true(r->f[1] < 0 && -r->f[1] > 0.5 * sqrt(r->f[0] * r->f[0] + r->f[1] * r->f[1] + r->f[2] * r->f[2]));
  assert_true(fabs(r->x[0] - pivot[0]) < 1e-3 && fabs(r->x[1] - pivot[1]) < 1e-3);
  tx_scenario_free(s);

  s = load(",\"grasp\":[\"instrument0.pose\"]");
  if (!s) fail_msg("%s", tx_error());
  the_listener.n = 0;
  run(s, 2.6);
  for (int i = 0; i < the_listener.n; i++)
    print_message("  event %d: kind %u from %u at %.3f s\n", i, the_listener.got[i].kind, the_listener.got[i].source,
                  the_listener.got[i].sim_ns * 1e-9);
  assert_int_equal(the_listener.n, 2);
  assert_int_equal(the_listener.got[0].kind, TX_EVENT_GRASP);
  assert_int_equal(the_listener.got[1].kind, TX_EVENT_RELEASE);
  assert_int_equal(the_listener.got[1].source, 0);
  assert_true(the_listener.got[1].sim_ns > 1800000000 && the_listener.got[1].sim_ns <= 1900000000);
  r = latest_snapshot(s, "organs.grasp").data;
  const double after = spot_height(s) - spot[1];
  print_message("  released: 0.7 s later the spot is %.2f mm above its rest; pull %.3g N\n", after * 1e3, r->f[1]);
  assert_true(r->nodes == 0 && r->f[0] == 0 && r->f[1] == 0 && r->f[2] == 0);
  assert_true(after < 0.5 * LIFT); // falling back
  assert_true(result(s, "organs.grasps") == 1 && result(s, "organs.grasp_releases") == 1);
  assert_true(result(s, "organs.grasp_nodes_max") >= 3 && result(s, "organs.grasp_force_max_n") > 0);
  print_message("  carried at most %.2f mm\n", result(s, "organs.grasp_carried_max_m") * 1e3);
  assert_true(fabs(result(s, "organs.grasp_carried_max_m") - LIFT) < 0.0015);
  assert_int_equal(warnings(s, "organs.numerical_fault"), 0);
  assert_int_equal(warnings(s, "organs.bad_jaws"), 0);
  tx_scenario_free(s);
}

// two graspers at once (device1 holds instrument1): hand 0 lifts its spot
// 1 cm, hand 1 its own, 11 cm away, 5 mm; each grasp is its hand's (source,
// row of organs.grasp), and each spot goes up with its own jaws
static void two_graspers_at_once(void** state) {
  (void)state;
  char text[4096];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":["
           "{\"name\":\"haptics\",\"type\":\"haptics\",\"rate_hz\":1000,"
           "\"params\":{\"device\":\"scripted:%s\",\"force_model\":\"instrument0.force_model\"}},"
           "{\"name\":\"haptics1\",\"type\":\"haptics\",\"rate_hz\":1000,"
           "\"params\":{\"device\":\"scripted:%s\",\"hand\":1,\"force_model\":\"instrument1.force_model\"}},"
           "{\"name\":\"instruments\",\"type\":\"physics.instruments\",\"rate_hz\":1000,"
           "\"params\":{\"instrument0\":\"lap_grasper\",\"instrument1\":\"lap_grasper\",\"table_height_m\":-1,"
           "\"gravity_m_s2\":0}},"
           "{\"name\":\"organs\",\"type\":\"physics.organs\",\"rate_hz\":30,"
           "\"params\":{\"assets\":\"" COARSE "\",\"tool_radius_m\":0,\"grasp\":[\"instrument0.pose\",\"instrument1.pose\"]}},"
           "{\"name\":\"listener\",\"type\":\"test.organs_listener\",\"rate_hz\":30}]}",
           hand, hand2);
  tx_scenario* s = tx_scenario_load_text("test", text, strlen(text), NULL);
  if (!s) fail_msg("%s", tx_error());
  the_listener.n = 0;
  run(s, 1.8);
  assert_int_equal(the_listener.n, 2);
  bool by[2] = {false, false};
  for (int i = 0; i < 2; i++) {
    assert_int_equal(the_listener.got[i].kind, TX_EVENT_GRASP);
    assert_true(the_listener.got[i].source < 2);
    by[the_listener.got[i].source] = true;
  }
  assert_true(by[0] && by[1]);
  tx_snapshot g = latest_snapshot(s, "organs.grasp");
  assert_int_equal(g.rows, 2);
  const tx_organ_grasp* r = g.data;
  const double up0 = height(s, spot_row) - spot[1], up1 = height(s, spot2_row) - spot2[1];
  print_message("  hand 0: %g nodes, spot up %.2f mm, pull %.3f N down; hand 1: %g nodes, spot up %.2f mm, pull %.3f N down\n",
                r[0].nodes, up0 * 1e3, -r[0].f[1], r[1].nodes, up1 * 1e3, -r[1].f[1]);
  assert_true(fabs(r[0].x[0] - (spot[0] - 0.01)) < 1e-3 && fabs(r[1].x[0] - (spot2[0] - 0.01)) < 1e-3); // each row its own pivot
  assert_true(r[0].nodes >= 3 && r[1].nodes >= 3);
  assert_true(fabs(up0 - LIFT) < 0.0015 && fabs(up1 - LIFT / 2) < 0.0015);
  assert_true(r[0].f[1] < 0 && isfinite(r[1].f[0] + r[1].f[1] + r[1].f[2]));
  assert_true(result(s, "organs.grasps") == 2);
  tx_scenario_free(s);
}

static void expect_refused(const char* params, const char* needle) { assert_refused(load(params), needle); }

static void bad_grasp_parameters(void** state) {
  (void)state;
  expect_refused(",\"grasp\":[\"instrument0.pose\"],\"grasp_closed_rad\":0.3", "grasp_open_rad");
  expect_refused(",\"grasp\":[\"instrument0.pose\",\"instrument0.pose\"]", "grasp");
  expect_refused(",\"grasp\":[\"instrument1.pose\"]", "instrument1.pose");
  expect_refused(",\"grasp\":[\"instrument0.pose\"],\"grasp_reach_m\":-1", "grasp_reach_m");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(grasper_lifts_the_liver),
      cmocka_unit_test(two_graspers_at_once),
      cmocka_unit_test(bad_grasp_parameters),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
