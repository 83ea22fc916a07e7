// The band (controllers/band/band_sim.h) on the committed assets
// (assets/lagb/band_*): the distance joint holds its length within 1 % while
// the two parts are pulled apart at 5 N; the ring comes back to its curved
// rest shape after it was bent open and let go (1.5 s); the tube's tip driven through
// the buckle latches, and the latch holds against a pull; driven past the
// buckle outside its opening it does not latch; bad input is refused.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/band/band_sim.h"
#include "controllers/rotation.h"
#include "model/error.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double dist(const double a[3], const double b[3]) {
  return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

static tx_band* make(void) {
  tx_band_def d = tx_band_def_default();
  tx_band* b = tx_band_create(&d, TX_ASSETS "/lagb");
  if (!b) fprintf(stderr, "%s\n", tx_error());
  assert_non_null(b);
  return b;
}

// the tube's tip held where it is, the buckle pulled at 5 N straight away
// from it: the joint carries the 5 N (its length error is the joint's, not
// the parts' stretch, which the tube shows)
static void joint_holds_at_5n(void** state) {
  (void)state;
  tx_band* b = make();
  double tip[3], buckle[3], f[3];
  tx_band_body_position(b, TX_BAND_TUBE_TIP, tip);
  tx_band_body_position(b, TX_BAND_BUCKLE, buckle);
  double l = dist(tip, buckle);
  for (int a = 0; a < 3; a++) f[a] = 5 * (buckle[a] - tip[a]) / l;
  tx_band_drive(b, TX_BAND_TUBE_TIP, tip);
  tx_band_set_force(b, TX_BAND_BUCKLE, f);
  double worst = 0, rest = tx_band_joint_rest(b);
  double head0[3], head[3];
  tx_band_body_position(b, TX_BAND_TUBE_HEAD, head0);
  for (int s = 0; s < 60; s++) { // 1 s: the error peaks in the first 0.2 s
    assert_true(tx_band_step(b));
    worst = fmax(worst, fabs(tx_band_joint_length(b) / rest - 1));
  }
  tx_band_body_position(b, TX_BAND_TUBE_HEAD, head);
  printf("joint at 5 N: largest length error %.3g %% (rest %.3g mm); the tube's head moved %.1f mm\n", 100 * worst,
         rest * 1e3, dist(head, head0) * 1e3);
  assert_true(worst < 0.01);
  assert_true(dist(head, head0) > 0.005); // the pull did reach the joint: the tube stretched
  tx_band_destroy(b);
}

// the ring's shape: each node's distance to the ring's first node and to its
// last, which a rigid motion keeps, against the rest shape's
static double ring_shape_error(tx_band* b) {
  int n = tx_band_nodes(b, TX_BAND_RING);
  double* x = malloc(sizeof(double) * 3 * (size_t)n);
  assert_non_null(x);
  tx_band_positions(b, TX_BAND_RING, x);
  const double* r = tx_band_rest(b, TX_BAND_RING);
  double e = 0;
  for (int i = 0; i < n; i++)
    for (int k = 0; k < 2; k++) {
      int o = k ? n - 1 : 0;
      e = fmax(e, fabs(dist(x + 3 * i, x + 3 * o) - dist(r + 3 * i, r + 3 * o)));
    }
  free(x);
  return e;
}

static void ring_returns_to_rest(void** state) {
  (void)state;
  tx_band* b = make();
  double p[3], c[3], ax[3];
  tx_band_body_position(b, TX_BAND_BUCKLE, p);
  tx_band_buckle(b, c, ax);
  // open the C: the buckle carried 3 cm outward from the ring's centre, over 0.25 s
  double out[3] = {p[0], p[1], 0}, len = hypot(p[0], p[1]), tail[3];
  tx_band_body_position(b, TX_BAND_RING_TAIL, tail);
  tx_band_drive(b, TX_BAND_RING_TAIL, tail);
  for (int s = 1; s <= 15; s++) {
    double q[3] = {p[0] + 0.03 * s / 15 * out[0] / len, p[1] + 0.03 * s / 15 * out[1] / len, p[2]};
    tx_band_drive(b, TX_BAND_BUCKLE, q);
    assert_true(tx_band_step(b));
  }
  double bent = ring_shape_error(b);
  tx_band_free(b, TX_BAND_BUCKLE);
  tx_band_free(b, TX_BAND_RING_TAIL);
  for (int s = 0; s < 90; s++) assert_true(tx_band_step(b)); // 1.5 s
  double back = ring_shape_error(b);
  printf("ring: bent open by %.1f mm, %.2f mm from its rest shape 1.5 s after release\n", bent * 1e3, back * 1e3);
  assert_true(bent > 0.01);
  assert_true(back < 0.02 * bent);
  tx_band_destroy(b);
}

// the tip driven to a point before the opening, then through it to a point
// beyond (off: sideways from the opening's centre, m); the buckle held
static bool thread_tip(tx_band* b, double off) {
  double c[3], ax[3], side[3], p[3];
  tx_band_buckle(b, c, ax);
  side[0] = 0, side[1] = 0, side[2] = 1; // the band's width: across the axis
  tx_band_body_position(b, TX_BAND_BUCKLE, p);
  tx_band_drive(b, TX_BAND_BUCKLE, p);
  double way[2][3];
  for (int a = 0; a < 3; a++) way[0][a] = c[a] - 0.02 * ax[a] + off * side[a], way[1][a] = c[a] + 0.01 * ax[a] + off * side[a];
  for (int w = 0; w < 2; w++)
    for (int s = 0; s < 200; s++) {
      double tip[3], q[3];
      tx_band_body_position(b, TX_BAND_TUBE_TIP, tip);
      double d = dist(tip, way[w]), v = 0.006; // m per step: 0.36 m/s
      if (d < 1e-4) break;
      for (int a = 0; a < 3; a++) q[a] = d > v ? tip[a] + (way[w][a] - tip[a]) * v / d : way[w][a];
      tx_band_drive(b, TX_BAND_TUBE_TIP, q);
      assert_true(tx_band_step(b));
      if (w == 0) assert_false(tx_band_locked(b));
      if (tx_band_locked(b)) return true; // the hand lets go at the click
    }
  return tx_band_locked(b);
}

static void latch_through_buckle(void** state) {
  (void)state;
  tx_band* b = make();
  assert_false(tx_band_locked(b));
  assert_true(thread_tip(b, 0.002));
  // let go of both, pull the tip back out at 5 N: the latch holds it
  double tip[3], buckle[3], c[3], ax[3];
  tx_band_free(b, TX_BAND_TUBE_TIP);
  tx_band_free(b, TX_BAND_BUCKLE);
  for (int s = 0; s < 6; s++) assert_true(tx_band_step(b));
  tx_band_body_position(b, TX_BAND_TUBE_TIP, tip);
  tx_band_body_position(b, TX_BAND_BUCKLE, buckle);
  double held = dist(tip, buckle);
  tx_band_buckle(b, c, ax);
  tx_band_set_force(b, TX_BAND_TUBE_TIP, (double[3]){-5 * ax[0], -5 * ax[1], -5 * ax[2]});
  tx_band_set_force(b, TX_BAND_BUCKLE, (double[3]){5 * ax[0], 5 * ax[1], 5 * ax[2]});
  for (int s = 0; s < 30; s++) {
    bool ok = tx_band_step(b);
    if (!ok) {
      tx_band_body_position(b, TX_BAND_TUBE_TIP, tip);
      printf("fault at %d: tip %g %g %g\n", s, tip[0], tip[1], tip[2]);
    }
    assert_true(ok);
  }
  tx_band_body_position(b, TX_BAND_TUBE_TIP, tip);
  tx_band_body_position(b, TX_BAND_BUCKLE, buckle);
  printf("latched: tip to buckle %.2f mm, %.2f mm after 0.5 s at 5 N\n", held * 1e3, dist(tip, buckle) * 1e3);
  assert_true(tx_band_locked(b));
  assert_true(fabs(dist(tip, buckle) - held) < 1e-3);
  tx_band_destroy(b);
}

static void no_latch_outside_the_opening(void** state) {
  (void)state;
  tx_band* b = make();
  tx_band_def d = tx_band_def_default();
  assert_false(thread_tip(b, 2 * d.buckle_radius));
  double tip[3], c[3], ax[3];
  tx_band_body_position(b, TX_BAND_TUBE_TIP, tip);
  tx_band_buckle(b, c, ax);
  assert_true((tip[0] - c[0]) * ax[0] + (tip[1] - c[1]) * ax[1] + (tip[2] - c[2]) * ax[2] > 0.005); // it did go past
  tx_band_destroy(b);
}

static void fault_is_restored(void** state) {
  (void)state;
  tx_band* b = make();
  assert_true(tx_band_step(b));
  tx_band_save(b);
  double before = tx_band_joint_length(b), p[3];
  tx_band_body_position(b, TX_BAND_BUCKLE, p);
  p[0] += 100; // 100 m in one step: far past max_speed
  tx_band_drive(b, TX_BAND_BUCKLE, p);
  assert_false(tx_band_step(b));
  tx_band_restore(b);
  tx_band_free(b, TX_BAND_BUCKLE);
  assert_true(fabs(tx_band_joint_length(b) - before) < 1e-12);
  assert_true(tx_band_step(b));
  tx_band_destroy(b);
}

// placed by an origin and a rotation: every node, the buckle and the joint
// where the placement carries the unplaced band's, and it still latches;
// its centre line's first ring section is the ring's tail (the marked end)
static void placed_in_the_scene(void** state) {
  (void)state;
  tx_band* plain = make();
  tx_band_def d = tx_band_def_default();
  const double origin[3] = {0.1, -0.05, 0.2};
  memcpy(d.origin, origin, sizeof origin);
  tx_rotation_from_degrees((const double[3]){30, -20, 90}, d.rotation);
  tx_band* b = tx_band_create(&d, TX_ASSETS "/lagb");
  assert_non_null(b);
  double worst = 0;
  for (int part = 0; part < TX_BAND_PARTS; part++) {
    const double *x0 = tx_band_rest(plain, part), *x1 = tx_band_rest(b, part);
    for (int i = 0; i < tx_band_nodes(b, part); i++) {
      double want[3];
      for (int a = 0; a < 3; a++)
        want[a] = origin[a] + d.rotation[a][0] * x0[3 * i] + d.rotation[a][1] * x0[3 * i + 1] + d.rotation[a][2] * x0[3 * i + 2];
      worst = fmax(worst, dist(want, x1 + 3 * i));
    }
  }
  assert_true(worst < 1e-12);
  double c0[3], a0[3], c1[3], a1[3], want[3], wax[3];
  tx_band_buckle(plain, c0, a0);
  tx_band_buckle(b, c1, a1);
  for (int a = 0; a < 3; a++) {
    want[a] = origin[a] + d.rotation[a][0] * c0[0] + d.rotation[a][1] * c0[1] + d.rotation[a][2] * c0[2];
    wax[a] = d.rotation[a][0] * a0[0] + d.rotation[a][1] * a0[1] + d.rotation[a][2] * a0[2];
  }
  assert_true(dist(want, c1) < 1e-9 && dist(wax, a1) < 1e-9);
  assert_true(fabs(tx_band_joint_rest(b) - tx_band_joint_rest(plain)) < 1e-12);
  assert_int_equal(tx_band_sections(b, TX_BAND_RING), 25);
  assert_int_equal(tx_band_sections(b, TX_BAND_TUBE), 41);
  double tail[3], first[3];
  tx_band_body_position(b, TX_BAND_RING_TAIL, tail);
  double* pos = malloc(sizeof(double) * 3 * (size_t)tx_band_nodes(b, TX_BAND_RING));
  tx_band_positions(b, TX_BAND_RING, pos);
  tx_band_section_centre(b, TX_BAND_RING, 0, pos, first);
  free(pos);
  assert_true(dist(tail, first) < 1e-3); // the tail body sits at its end section's middle
  assert_true(thread_tip(b, 0.002));     // the placed buckle still takes the tip
  tx_band_destroy(b);
  tx_band_destroy(plain);
}

// a capsule beside the tube, and the tube's tip carried across it: no node
// ever inside it, and the tube does come to rest against it
static void kept_off_an_obstacle(void** state) {
  (void)state;
  tx_band_def d = tx_band_def_default();
  const double n[3] = {M_SQRT1_2, -M_SQRT1_2, 0}; // across the tube, in its plane
  const double mid[3] = {0.040, 0.070, 0};        // on the tube's centre line
  const double r = 0.004, off = 0.008;
  d.obstacles = 1;
  for (int a = 0; a < 3; a++) d.obstacle[0][a] = mid[a] + off * n[a], d.obstacle[0][3 + a] = mid[a] + off * n[a];
  d.obstacle[0][2] = -0.05, d.obstacle[0][5] = 0.05, d.obstacle[0][6] = r;
  tx_band* b = tx_band_create(&d, TX_ASSETS "/lagb");
  assert_non_null(b);
  double tip[3];
  tx_band_body_position(b, TX_BAND_TUBE_TIP, tip);
  double inside = INFINITY, nearest = INFINITY;
  double* pos = malloc(sizeof(double) * 3 * (size_t)tx_band_nodes(b, TX_BAND_TUBE));
  for (int s = 0; s < 30; s++) {
    double to[3];
    for (int a = 0; a < 3; a++) to[a] = tip[a] + fmin(s + 1, 20) * 0.0015 * n[a]; // 30 mm across, in 20 steps
    tx_band_drive(b, TX_BAND_TUBE_TIP, to);
    assert_true(tx_band_step(b));
    tx_band_positions(b, TX_BAND_TUBE, pos);
    for (int i = 0; i < tx_band_nodes(b, TX_BAND_TUBE); i++) {
      double dx = pos[3 * i] - d.obstacle[0][0], dy = pos[3 * i + 1] - d.obstacle[0][1];
      double rr = sqrt(dx * dx + dy * dy);
      inside = fmin(inside, rr), nearest = fmin(nearest, rr);
    }
  }
  free(pos);
  printf("obstacle r = %.1f mm: nearest node %.4f mm from its axis\n", r * 1e3, nearest * 1e3);
  assert_true(inside >= r * (1 - 1e-6)); // never inside
  assert_true(nearest < r + 0.0005);     // and pressed against it
  tx_band_destroy(b);
  // bad obstacles are refused
  d.obstacle[0][6] = 0;
  assert_null(tx_band_create(&d, TX_ASSETS "/lagb"));
  d.obstacle[0][6] = r, d.rotation[0][0] = 2;
  assert_null(tx_band_create(&d, TX_ASSETS "/lagb"));
  assert_non_null(strstr(tx_error(), "rotation"));
}

static void bad_input(void** state) {
  (void)state;
  tx_band_def d = tx_band_def_default();
  assert_null(tx_band_create(&d, "/nonexistent"));
  assert_non_null(strstr(tx_error(), "/nonexistent/band_ring.node"));
  d.part[TX_BAND_TUBE].poisson = 0.5;
  assert_null(tx_band_create(&d, TX_ASSETS "/lagb"));
  assert_non_null(strstr(tx_error(), "band_tube"));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(joint_holds_at_5n),          cmocka_unit_test(ring_returns_to_rest),
      cmocka_unit_test(latch_through_buckle),       cmocka_unit_test(no_latch_outside_the_opening),
      cmocka_unit_test(fault_is_restored),          cmocka_unit_test(bad_input),
      cmocka_unit_test(placed_in_the_scene),        cmocka_unit_test(kept_off_an_obstacle),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
