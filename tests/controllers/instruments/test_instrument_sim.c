// Instruments on ODE: bodies placed at link x inertial origin with their geoms
// where the URDF puts them; the root follows the device through the virtual
// coupling; the jaws follow the grip within their limits; contacts keep the
// instruments out of the table and out of each other; the coupling force
// never passes its clamp.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "controllers/instruments/instrument_desc.h"
#include "controllers/instruments/instrument_sim.h"
#include "tactus/model.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static tx_instrument_desc* load(const char* name) {
  char path[1024];
  snprintf(path, sizeof path, "%s/%s.urdf", TX_ASSET_DIR, name);
  tx_instrument_desc* d = tx_instrument_desc_load(path);
  if (!d) fail_msg("%s", tx_error());
  return d;
}

static tx_instrument_input at(double x, double y, double z, double grip) {
  return (tx_instrument_input){.pos = {x, y, z}, .quat = {1, 0, 0, 0}, .grip = grip};
}

static double dist(const double a[3], const double b[3]) {
  return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

// the link frames come back where the URDF put them, for a jaw whose centre
// of mass is far from its frame (the needle holder's half: 52 mm behind the pivot)
static void test_links_start_where_the_urdf_puts_them(void** state) {
  (void)state;
  tx_instrument_desc* d = load("needle_holder");
  tx_instrument_sim_params p = tx_instrument_sim_defaults();
  const tx_urdf* u = d->urdf;
  double start[1][3] = {{0.01, 0.02, 0.03}};
  tx_instrument_world* w = tx_instrument_world_create(&p, &u, 1, start);
  assert_non_null(w);
  for (int l = 0; l < u->nlinks; l++) {
    double pos[3], q[4];
    tx_instrument_world_link(w, 0, l, pos, q);
    assert_true(dist(pos, start[0]) < 1e-12); // every link frame is at the pivot
    assert_true(fabs(q[0] - 1) < 1e-12);
  }
  for (int j = 0; j < u->njoints; j++) assert_true(fabs(tx_instrument_world_joint(w, 0, j)) < 1e-12);
  tx_instrument_world_destroy(w);
  tx_instrument_desc_free(d);
}

// weightless, the root settles on a still device; the force on the hand goes to zero
static void test_coupling_pulls_the_root_to_the_device(void** state) {
  (void)state;
  tx_instrument_desc* d = load("lap_grasper");
  tx_instrument_sim_params p = tx_instrument_sim_defaults();
  memset(p.gravity, 0, sizeof p.gravity);
  const tx_urdf* u = d->urdf;
  double start[1][3] = {{0, 0, 0}};
  tx_instrument_world* w = tx_instrument_world_create(&p, &u, 1, start);
  tx_instrument_input in = at(0.005, 0.002, 0, 0);
  double f[3];
  tx_instrument_world_step(w, &in, 1e-3);
  tx_instrument_world_hand_force(w, 0, f);
  // at the first step the hand feels k x offset, back towards the tool: -200 N/m x 5 mm = -1 N in x
  assert_true(fabs(f[0] + 200 * 0.005) < 1e-9 && fabs(f[1] + 200 * 0.002) < 1e-9);
  for (int i = 0; i < 3000; i++) tx_instrument_world_step(w, &in, 1e-3);
  double pos[3], q[4];
  tx_instrument_world_link(w, 0, 0, pos, q);
  tx_instrument_world_hand_force(w, 0, f);
  print_message("  after 3 s: %.3g mm from the device, %.3g N\n", 1e3 * dist(pos, in.pos), sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
  assert_true(dist(pos, in.pos) < 1e-5);
  assert_true(fabs(f[0]) < 2e-3 && fabs(f[1]) < 2e-3);
  tx_instrument_world_destroy(w);
  tx_instrument_desc_free(d);
}

// with gravity the hand carries the instrument's weight: m g through the coupling
static void test_hand_carries_the_weight(void** state) {
  (void)state;
  tx_instrument_desc* d = load("needle_holder");
  tx_instrument_sim_params p = tx_instrument_sim_defaults();
  const tx_urdf* u = d->urdf;
  double start[1][3] = {{0, 0, 0}};
  tx_instrument_world* w = tx_instrument_world_create(&p, &u, 1, start);
  tx_instrument_input in = at(0, 0, 0, 0);
  for (int i = 0; i < 4000; i++) tx_instrument_world_step(w, &in, 1e-3);
  double f[3];
  tx_instrument_world_hand_force(w, 0, f);
  double mg = tx_instrument_desc_mass(d) * 9.81;
  print_message("  hand force %.4f N down, m g = %.4f N\n", -f[1], mg);
  assert_true(fabs(-f[1] - mg) < 0.02 * mg);
  tx_instrument_world_destroy(w);
  tx_instrument_desc_free(d);
}

// the jaws follow the grip (the angle between them), and stop at their limits
static void test_jaws_follow_the_grip_within_limits(void** state) {
  (void)state;
  tx_instrument_desc* d = load("lap_grasper");
  tx_instrument_sim_params p = tx_instrument_sim_defaults();
  memset(p.gravity, 0, sizeof p.gravity);
  const tx_urdf* u = d->urdf;
  double start[1][3] = {{0, 0, 0}};
  tx_instrument_world* w = tx_instrument_world_create(&p, &u, 1, start);
  tx_instrument_input in = at(0, 0, 0, 0.6);
  for (int i = 0; i < 500; i++) tx_instrument_world_step(w, &in, 1e-3);
  for (int j = 0; j < 2; j++) assert_true(fabs(tx_instrument_world_joint(w, 0, j) - 0.3) < 0.01);
  // the upper jaw's tip went up (+z), the lower's down
  double pu[3], qu[4], tip[3] = {0.02, 0, 0}, r[3];
  tx_instrument_world_link(w, 0, tx_urdf_link_index(u, "jaw_upper"), pu, qu);
  // rotate the tip by qu: z grows for the upper jaw
  double t[3] = {2 * (qu[2] * tip[2] - qu[3] * tip[1]), 2 * (qu[3] * tip[0] - qu[1] * tip[2]), 2 * (qu[1] * tip[1] - qu[2] * tip[0])};
  r[2] = tip[2] + qu[0] * t[2] + qu[1] * t[1] - qu[2] * t[0];
  assert_true(r[2] > 0.005);
  in.grip = 10; // far past the limit
  double most = 0;
  for (int i = 0; i < 1000; i++) {
    tx_instrument_world_step(w, &in, 1e-3);
    for (int j = 0; j < 2; j++) most = fmax(most, tx_instrument_world_joint(w, 0, j));
  }
  print_message("  grip 10 rad: widest jaw %.4f rad, limit %.4f\n", most, u->joints[0].upper);
  assert_true(most < u->joints[0].upper + 0.01 && most > u->joints[0].upper - 0.01);
  in.grip = 0; // slammed shut: the jaws meet, and neither passes the other
  double least = 1;
  for (int i = 0; i < 1000; i++) {
    tx_instrument_world_step(w, &in, 1e-3);
    for (int j = 0; j < 2; j++) least = fmin(least, tx_instrument_world_joint(w, 0, j));
  }
  assert_true(least > -0.01);
  for (int j = 0; j < 2; j++) assert_true(fabs(tx_instrument_world_joint(w, 0, j)) < 0.01);
  tx_instrument_world_destroy(w);
  tx_instrument_desc_free(d);
}

// pressed 2 cm into the table, the instrument stays on it and the hand feels it push back
static void test_table_holds_the_instrument(void** state) {
  (void)state;
  tx_instrument_desc* d = load("hook_cautery");
  tx_instrument_sim_params p = tx_instrument_sim_defaults();
  p.table_height = 0;
  const tx_urdf* u = d->urdf;
  double start[1][3] = {{0, 0.01, 0}};
  tx_instrument_world* w = tx_instrument_world_create(&p, &u, 1, start);
  tx_instrument_input in = at(0, -0.005, 0, 0);
  for (int i = 0; i < 2000; i++) tx_instrument_world_step(w, &in, 1e-3);
  double pos[3], q[4], f[3];
  tx_instrument_world_link(w, 0, 0, pos, q);
  tx_instrument_world_hand_force(w, 0, f);
  print_message("  shaft axis at y = %.3f mm (radius 2.5 mm), hand pushed up by %.3f N, %d contacts\n", 1e3 * pos[1], f[1],
                tx_instrument_world_contacts(w));
  assert_true(tx_instrument_world_contacts(w) > 0);
  assert_true(pos[1] > 0.0025 - 0.0005); // the 5 mm shaft lies on the table, at most 0.5 mm in
  assert_true(f[1] > 200 * 0.007 * 0.9); // the coupling spring stretched by the 7.5 mm the table keeps
  tx_instrument_world_destroy(w);
  tx_instrument_desc_free(d);
}

// two instruments driven into each other touch and stay apart
static void test_instruments_collide(void** state) {
  (void)state;
  tx_instrument_desc* a = load("lap_grasper");
  tx_instrument_desc* b = load("lap_grasper");
  tx_instrument_sim_params p = tx_instrument_sim_defaults();
  memset(p.gravity, 0, sizeof p.gravity);
  const tx_urdf* u[2] = {a->urdf, b->urdf};
  double start[2][3] = {{0, 0, 0}, {-0.1, 0.02, 0}};
  tx_instrument_world* w = tx_instrument_world_create(&p, u, 2, start);
  // hand 1 pushes its shaft down through the other's shaft
  tx_instrument_input in[2] = {at(0, 0, 0, 0), at(-0.1, -0.02, 0, 0)};
  for (int i = 0; i < 2000; i++) tx_instrument_world_step(w, in, 1e-3);
  double p0[3], p1[3], q[4], f[3];
  tx_instrument_world_link(w, 0, 0, p0, q);
  tx_instrument_world_link(w, 1, 0, p1, q);
  tx_instrument_world_hand_force(w, 1, f);
  print_message("  %d contacts, deepest %.3f mm, hand 1 feels %.3f N up\n", tx_instrument_world_contacts(w),
                1e3 * tx_instrument_world_depth(w), f[1]);
  assert_true(tx_instrument_world_contacts(w) > 0);
  assert_true(tx_instrument_world_depth(w) < 0.001);
  assert_true(f[1] > 0.5);
  // the lower instrument is pushed down, out of its hand's reach
  tx_instrument_world_hand_force(w, 0, f);
  assert_true(f[1] < -0.5);
  tx_instrument_world_destroy(w);
  tx_instrument_desc_free(a);
  tx_instrument_desc_free(b);
}

// a hand a metre away pulls with the clamp, no more; a NaN hand pulls on nothing
static void test_force_clamp_and_nan(void** state) {
  (void)state;
  tx_instrument_desc* d = load("metzenbaum_scissors");
  tx_instrument_sim_params p = tx_instrument_sim_defaults();
  const tx_urdf* u = d->urdf;
  double start[1][3] = {{0, 0, 0}};
  tx_instrument_world* w = tx_instrument_world_create(&p, &u, 1, start);
  tx_instrument_input in = at(1, 0, 0, 0);
  double most = 0, f[3];
  for (int i = 0; i < 200; i++) {
    tx_instrument_world_step(w, &in, 1e-3);
    tx_instrument_world_hand_force(w, 0, f);
    most = fmax(most, sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
  }
  assert_true(most <= p.max_force * (1 + 1e-12) && most > 0.99 * p.max_force);
  in.pos[0] = NAN;
  tx_instrument_world_step(w, &in, 1e-3);
  tx_instrument_world_hand_force(w, 0, f);
  double pos[3], q[4];
  tx_instrument_world_link(w, 0, 0, pos, q);
  assert_true(isfinite(pos[0]) && isfinite(pos[1]) && isfinite(pos[2]) && f[0] == 0);
  assert_int_equal(tx_instrument_world_bad_inputs(w), 1);
  assert_int_equal(tx_instrument_world_resets(w), 0);
  tx_instrument_world_destroy(w);
  tx_instrument_desc_free(d);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_links_start_where_the_urdf_puts_them),
      cmocka_unit_test(test_coupling_pulls_the_root_to_the_device),
      cmocka_unit_test(test_hand_carries_the_weight),
      cmocka_unit_test(test_jaws_follow_the_grip_within_limits),
      cmocka_unit_test(test_table_holds_the_instrument),
      cmocka_unit_test(test_instruments_collide),
      cmocka_unit_test(test_force_clamp_and_nan),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
