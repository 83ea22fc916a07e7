// Punctures: the thread, pulled by its head, passes in order through two
// points that move (a skin that breathes), slides through them and never
// leaves one (each within r of the thread at every step), in both models; a
// bite (an entry, then an exit) runs through the tissue, not under the skin;
// friction through a puncture adds to the force on the hand; bad lists are
// refused; stepping with punctures never allocates.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "tests/alloc_count.h"
#include "controllers/physics/skin_grid.h"
#include "controllers/thread/thread.h"
#include "model/error.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

// the distance from p to the thread's polyline (its whole links)
static double polyline_distance(const tx_thread* t, const double p[3]) {
  double best = INFINITY;
  const uint8_t* cut = tx_thread_severed(t);
  for (int i = 0; i + 1 < tx_thread_node_count(t); i++) {
    if (cut[i]) continue;
    const double *a = tx_thread_position(t, i), *b = tx_thread_position(t, i + 1);
    double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ee = e[0] * e[0] + e[1] * e[1] + e[2] * e[2], u = 0, d = 0;
    if (ee > 0) u = fmin(1, fmax(0, ((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1] + (p[2] - a[2]) * e[2]) / ee));
    for (int c = 0; c < 3; c++) d += pow(a[c] + u * e[c] - p[c], 2);
    best = fmin(best, sqrt(d));
  }
  return best;
}

// two punctures at x = 5 and 15 mm, each bobbing 0.4 mm in y at 2 Hz (out
// of phase); the head goes along +x through both (0.1 m/s for 0.2 s), then
// up and on (to (30, 10, 0) mm in 0.2 s): the thread bends through them
static void puncture_points(double time, double p[6]) {
  p[0] = 0.005, p[1] = 0.0004 * sin(4 * PI * time), p[2] = 0;
  p[3] = 0.015, p[4] = -0.0004 * sin(4 * PI * time), p[5] = 0;
}
static void head_at(double time, double h[3], bool straight) {
  if (time <= 0.2 || straight) {
    h[0] = 0.1 * time, h[1] = 0;
  } else {
    double f = fmin(1, (time - 0.2) / 0.2);
    h[0] = 0.02 + 0.01 * f, h[1] = 0.01 * f;
  }
  h[2] = 0;
}

typedef struct drag_result {
  double worst;       // m, the largest distance of a passed puncture from the thread
  int passed_at[2];   // steps at which each was passed
  double arc_end[2];  // m
  double force_mean;  // N, the mean magnitude of the force the hand feels (tx_thread_tension) while pulled through
  double strain;      // the largest link strain at the end of any step
} drag_result;

static drag_result drag(tx_thread_model model, double friction, bool count, bool straight, int iterations) {
  tx_thread_def d = tx_thread_def_default();
  d.model = model;
  d.nodes = 61;
  d.length = 0.06;
  d.direction[0] = -1; // the thread trails behind the head
  d.puncture_friction = friction;
  d.gravity = 0;
  d.damping = 5;
  d.iterations = iterations;
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  drag_result r = {0, {-1, -1}, {0, 0}, 0, 0};
  double fsum = 0;
  int fn = 0;
  if (count) counting = 1;
  for (int k = 1; k <= 400; k++) {
    double time = k * 1e-3, p[6], h[3];
    puncture_points(time, p);
    head_at(time, h, straight);
    assert_int_equal(tx_thread_set_punctures(t, p, NULL, 2), TX_THREAD_OK);
    assert_int_equal(tx_thread_set_head(t, h), TX_THREAD_OK);
    assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
    r.strain = fmax(r.strain, tx_thread_max_strain(t));
    int passed = tx_thread_punctures_passed(t);
    for (int j = 0; j < passed; j++) {
      if (r.passed_at[j] < 0) r.passed_at[j] = k;
      r.worst = fmax(r.worst, polyline_distance(t, p + 3 * j));
    }
    if (time > 0.25) { // pulled through both, up and aside
      double f[3], K[9];
      tx_thread_tension(t, 0, 100, f, K);
      fsum += sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
      fn++;
    }
  }
  counting = 0;
  for (int j = 0; j < 2; j++) r.arc_end[j] = tx_thread_puncture_arc(t, j);
  r.force_mean = fsum / fn;
  tx_thread_destroy(t);
  return r;
}

static void test_slides_through_two_moving_punctures(void** state) {
  (void)state;
  for (int model = 0; model < 2; model++) {
    drag_result r = drag((tx_thread_model)model, 0, model == 0, false, 2);
    print_message("%s: passed at steps %d, %d; arcs at the end %.2f, %.2f mm; worst distance %.3g mm\n",
                  model ? "rod" : "ftl", r.passed_at[0], r.passed_at[1], r.arc_end[0] * 1e3, r.arc_end[1] * 1e3,
                  r.worst * 1e3);
    // in order, as the head goes through: x = 5 mm at step 50, 15 mm at 150
    assert_true(r.passed_at[0] >= 50 && r.passed_at[0] <= 52);
    assert_true(r.passed_at[1] >= 150 && r.passed_at[1] <= 152);
    // never left: within r = 0.25 mm at every step
    assert_true(r.worst <= 0.00025);
    // pulled through: the thread's point at the first puncture is the one
    // about the head's path beyond it away (>= 15 mm along x plus the rise), and
    // the first lies further along the thread than the second
    assert_true(r.arc_end[0] > 0.025 && r.arc_end[0] < 0.06);
    assert_true(r.arc_end[1] > 0.015 && r.arc_end[1] < r.arc_end[0] - 0.009);
  }
#ifndef TX_NO_ALLOC_COUNT
  assert_int_equal(allocations, 0);
#endif
}

// A taut thread bent through one puncture loads it as a rope loads a
// pulley: T (u_A + u_H), u the unit vectors from the point to the pinned tail
// A and to the head H, and T = k (|AP| + |PH| - L), the follow-the-leader
// tension of a thread of length L drawn over that path (frictionless: the
// same all along), with stiffness k |u_A + u_H|^2 along the pull. The tail is
// pinned 40 mm behind the head; the head goes through P, 30.41 mm from A, on
// 9 mm along -y (slack: 39.41 mm of path) or to 12 mm (2.41 mm over 40), and
// holds. Slack, the thread pulls nothing. Taut, it is laid straight along the
// path (ftl_taut), so this checks the chain from the puncture's passing to
// the load to rounding; before that, the kinematic passes slid this thread
// out of P step by step and pulled with what they left at the pin.
static void pull_through(tx_thread* t, const double P[3], double depth, int steps) {
  for (int s = 1; s <= steps; s++) {
    double time = s * 1e-3, h[3];
    double a = fmin(1, time / 0.1), b = fmin(1, fmax(0, (time - 0.1) / 0.1));
    for (int c = 0; c < 3; c++) h[c] = a * P[c];
    h[1] -= b * depth;
    assert_int_equal(tx_thread_set_punctures(t, P, NULL, 1), TX_THREAD_OK);
    assert_int_equal(tx_thread_set_head(t, h), TX_THREAD_OK);
    assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  }
}

static void test_taut_thread_loads_its_puncture_as_a_pulley(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  d.nodes = 81;
  d.length = 0.04;
  d.direction[0] = -1;
  d.pin_tail = true;
  const double A[3] = {-0.04, 0, 0}, P[3] = {-0.01, -0.005, 0}, H[3] = {-0.01, -0.017, 0}, k = 200;
  double load[3], k_load, la = 0, lh = 0, want[3], err = 0, w2 = 0;
  tx_thread* t = tx_thread_create(&d); // slack
  assert_non_null(t);
  pull_through(t, P, 0.009, 300);
  assert_int_equal(tx_thread_puncture_loads(t, k, 10, load, &k_load), 1);
  print_message("slack: load (%g, %g) N\n", load[0], load[1]);
  assert_true(load[0] == 0 && load[1] == 0 && k_load == 0);
  tx_thread_destroy(t);
  t = tx_thread_create(&d); // taut
  pull_through(t, P, 0.012, 300);
  assert_int_equal(tx_thread_punctures_passed(t), 1);
  assert_int_equal(tx_thread_puncture_loads(t, k, 10, load, &k_load), 1);
  for (int c = 0; c < 3; c++) la += pow(A[c] - P[c], 2), lh += pow(H[c] - P[c], 2);
  la = sqrt(la), lh = sqrt(lh);
  const double T = k * (la + lh - d.length);
  for (int c = 0; c < 3; c++) want[c] = T * ((A[c] - P[c]) / la + (H[c] - P[c]) / lh);
  for (int c = 0; c < 3; c++) err += pow(load[c] - want[c], 2), w2 += want[c] * want[c];
  print_message("taut: puncture load (%.4f, %.4f) N, as a pulley (%.4f, %.4f) N (T = %.4f N): off by %.2g; "
                "stiffness %.1f N/m (k |u_A + u_H|^2: %.1f); its point %.3f mm from the head\n", load[0], load[1],
                want[0], want[1], T, sqrt(err / w2), k_load, k * w2 / (T * T), tx_thread_puncture_arc(t, 0) * 1e3);
  assert_true(sqrt(err / w2) < 1e-9);
  assert_float_equal(k_load, k * w2 / (T * T), 1e-9 * k_load);
  // still through P, 12 mm from the head along the path: along the thread, stretched alike, lh L / (la + lh)
  assert_float_equal(tx_thread_puncture_arc(t, 0), lh * d.length / (la + lh), 1e-12);
  tx_thread_destroy(t);
}

// friction through the punctures: the hand feels the friction of each
// puncture the thread slid through in a step on top of the tension. ftl
// slides at every step; the rod sticks until the pull has stretched the
// strand on one side past the other's (thread.c, decide_slides), so it
// slides in some steps: the friction felt is up to 2 x 0.02 N and more than
// half of it on average. (A friction that only the constraints carried
// reached the head as a quarter of it at 2 iterations: it held any drift of
// the light nodes and stretched the link through the puncture instead.)
static void test_friction_raises_the_head_force(void** state) {
  (void)state;
  for (int model = 0; model < 2; model++) {
    // pulled straight on through both
    drag_result free_ = drag((tx_thread_model)model, 0, false, true, 2), held = drag((tx_thread_model)model, 0.02, false, true, 2);
    print_message("%s: force on the hand %.4g N without friction, %.4g N with 0.02 N a puncture\n",
                  model ? "rod" : "ftl", free_.force_mean, held.force_mean);
    double felt = held.force_mean - free_.force_mean;
    if (model == TX_THREAD_FTL)
      assert_true(fabs(felt - 0.04) < 1e-9);
    else
      assert_true(felt > 0.02 && felt < 0.04 + 1e-3);
    assert_true(held.worst <= 0.00025); // still never leaves one
  }
}

// A puncture that holds the thread firmly (1 N, against a thread that
// weighs 0.01 mN) still lets a hand that pulls draw the rod through, as
// far as with no friction, and stretches it no more than that does (0.16:
// the points move 0.4 mm a step, and putting the held point back across the
// thread stretches a link beside it). Before, its friction held the light
// nodes whatever pulled them: the thread stuck and stretched by 6.5 times a
// link; and the stretch cap, drawing each node straight towards the one
// before, cut the corner the rod turns at the second point (1.77).
static void test_a_pulled_rod_slides_through_a_firm_puncture(void** state) {
  (void)state;
  drag_result r0 = drag(TX_THREAD_ROD, 0, false, false, 2), r = drag(TX_THREAD_ROD, 1.0, false, false, 2);
  print_message("rod: largest strain %.4f, arcs at the end %.2f, %.2f mm without friction; "
                "%.4f, %.2f, %.2f mm with 1 N a puncture\n", r0.strain, r0.arc_end[0] * 1e3, r0.arc_end[1] * 1e3,
                r.strain, r.arc_end[0] * 1e3, r.arc_end[1] * 1e3);
  for (int j = 0; j < 2; j++) assert_float_equal(r.arc_end[j], r0.arc_end[j], 0.001);
  assert_true(r.strain <= r0.strain + 1e-3 && r0.strain < 0.2);
  assert_true(r.worst <= 0.00025);
}

// A thread pulled on through a puncture until its free tail goes through
// leaves it: 20 mm of thread, its head drawn along +x at 0.1 m/s through a
// point at x = 5 mm, then 15 mm further than the thread reaches. The point
// is passed at 0.05 s and left at 0.25 s, when the tail's end is at it;
// after that the thread runs through nothing (its arc -1, no load, no link
// held back past the cap) and lies beyond the point, behind the head.
static void test_a_thread_pulled_through_to_its_end_leaves_the_puncture(void** state) {
  (void)state;
  for (int model = 0; model < 2; model++) {
    tx_thread_def d = tx_thread_def_default();
    d.model = (tx_thread_model)model;
    d.nodes = 21;
    d.length = 0.02;
    d.direction[0] = -1;
    d.gravity = 0;
    d.damping = 5;
    tx_thread* t = tx_thread_create(&d);
    assert_non_null(t);
    const double P[3] = {0.005, 0, 0};
    int passed_at = -1, out_at = -1;
    double strain = 0;
    for (int k = 1; k <= 400; k++) {
      double h[3] = {0.1 * k * 1e-3, 0, 0};
      assert_int_equal(tx_thread_set_punctures(t, P, NULL, 1), TX_THREAD_OK);
      assert_int_equal(tx_thread_set_head(t, h), TX_THREAD_OK);
      assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
      if (passed_at < 0 && tx_thread_punctures_passed(t) == 1) passed_at = k;
      if (out_at < 0 && tx_thread_punctures_out(t) == 1) out_at = k;
      strain = fmax(strain, tx_thread_max_strain(t));
    }
    double load[3], k_load;
    int n = tx_thread_puncture_loads(t, 200, 10, load, &k_load);
    const double* tail = tx_thread_position(t, 20);
    print_message("%s: passed at step %d, pulled out at %d; the tail's end at x = %.2f mm; largest strain %.4f\n",
                  model ? "rod" : "ftl", passed_at, out_at, tail[0] * 1e3, strain);
    assert_true(passed_at >= 50 && passed_at <= 52);
    assert_true(out_at >= 249 && out_at <= 256);
    assert_true(tx_thread_puncture_arc(t, 0) == -1);
    assert_true(n == 1 && load[0] == 0 && load[1] == 0 && load[2] == 0 && k_load == 0);
    assert_true(tail[0] > 0.0055 && tail[0] < 0.021); // beyond the point, behind the head (at 40 mm)
    if (model == TX_THREAD_ROD) assert_true(strain <= 0.05 + 1e-6);
    tx_thread_destroy(t);
  }
}

static void test_bad_puncture_lists(void** state) {
  (void)state;
  tx_thread_def d = tx_thread_def_default();
  d.max_punctures = 2;
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  double p[9] = {0, 0, 0, 0.01, 0, 0, 0.02, 0, 0};
  assert_int_equal(tx_thread_set_punctures(t, p, NULL, 3), TX_THREAD_BAD);
  assert_non_null(strstr(tx_error(), "max_punctures"));
  p[4] = NAN;
  assert_int_equal(tx_thread_set_punctures(t, p, NULL, 2), TX_THREAD_BAD);
  assert_non_null(strstr(tx_error(), "puncture"));
  assert_int_equal(tx_thread_punctures_passed(t), 0);
  assert_true(tx_thread_puncture_arc(t, 0) == -1);
  double side[3] = {1, 2, -1};
  p[4] = 0;
  assert_int_equal(tx_thread_set_punctures(t, p, side, 2), TX_THREAD_BAD);
  assert_non_null(strstr(tx_error(), "side"));
  assert_int_equal(tx_thread_set_punctures(t, p, side, 3), TX_THREAD_BAD);
  assert_non_null(strstr(tx_error(), "max_punctures"));
  side[1] = -1;
  assert_int_equal(tx_thread_set_punctures(t, p, side, 2), TX_THREAD_OK);
  tx_thread_destroy(t);
  d = tx_thread_def_default();
  d.puncture_friction = -1;
  assert_int_equal(tx_thread_def_check(&d), -1);
  assert_non_null(strstr(tx_error(), "puncture_friction"));
  d = tx_thread_def_default();
  d.puncture_capture = 0;
  assert_int_equal(tx_thread_def_check(&d), -1);
  assert_non_null(strstr(tx_error(), "puncture_capture"));
}

// A bite: a 2 x 2 cm skin patch at y = 0, 1 mm thick; the head goes down
// through an entry at x = -8 mm, along the sheet's mid-plane, and up through
// an exit at x = +8 mm, then up 15 mm, drawing taut a limp 6 cm rod whose
// tail is pinned 3 cm above the entry (laid in a zigzag). With the
// punctures' sides given (+1 in, -1 out), the strand between them runs
// through the tissue: straight from point to point, inside the sheet's
// thickness, within the stretch cap. Without them (the control), the skin's
// contact holds that strand out of the sheet, half its thickness plus the
// thread's radius (0.75 mm) from the mid-plane, and the taut thread is
// stretched past its cap (0.075).
typedef struct bite_result {
  double off;    // m, the largest |y| of a node between the punctures (|x| < 3 mm)
  double strain; // the largest link strain at the end
} bite_result;

static bite_result bite(bool sides) {
  float px[21 * 21 * 3];
  int32_t tri[2 * 20 * 20 * 3];
  uint32_t ntri = tx_skin_grid(21, 21, 0.001, 0.001, (double[3]){0, 0, 0}, px, tri);
  tx_thread_def d = tx_thread_def_default();
  d.model = TX_THREAD_ROD;
  d.nodes = 61;
  d.length = 0.06; // l0 = 1 mm
  d.gravity = 0;
  d.damping = 5;
  d.pin_tail = true;
  d.bend_factor = 0; // limp: drawn taut, a bite runs straight from point to point
  d.max_triangles = (int)ntri;
  tx_thread* t = tx_thread_create(&d);
  assert_non_null(t);
  assert_int_equal(tx_thread_set_mesh(t, px, 21 * 21, tri, ntri, 0.001), TX_THREAD_OK);
  double x[61 * 3], P[6] = {-0.008, 0, 0, 0.008, 0, 0}, side[2] = {1, -1};
  for (int i = 0; i < 61; i++) { // up from (-8, 0.5) mm in links at 60 degrees, turning every 5
    int leg = i / 5, in = i % 5;
    double dx = 0.001 * sin(PI / 3) * (leg % 2 ? 5 - in : in);
    x[3 * i] = -0.008 - dx, x[3 * i + 1] = 0.0005 + 0.0005 * i, x[3 * i + 2] = 0;
  }
  assert_int_equal(tx_thread_set_positions(t, x), TX_THREAD_OK);
  assert_int_equal(tx_thread_set_punctures(t, P, sides ? side : NULL, 2), TX_THREAD_OK);
  // the head's path: down 0.5 mm, along 16 mm, up 15 mm (1 mm a step), then held
  double path[4][3] = {{-0.008, 0.0005, 0}, {-0.008, 0, 0}, {0.008, 0, 0}, {0.008, 0.015, 0}};
  for (int leg = 0; leg < 3; leg++) {
    double len = fabs(path[leg + 1][0] - path[leg][0]) + fabs(path[leg + 1][1] - path[leg][1]);
    int steps = (int)ceil(len / 0.001);
    for (int k = 1; k <= steps; k++) {
      double h[3];
      for (int a = 0; a < 3; a++) h[a] = path[leg][a] + (path[leg + 1][a] - path[leg][a]) * k / steps;
      assert_int_equal(tx_thread_set_head(t, h), TX_THREAD_OK);
      assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
    }
  }
  for (int k = 0; k < 200; k++) assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
  assert_int_equal(tx_thread_punctures_passed(t), 2);
  bite_result r = {0, tx_thread_max_strain(t)};
  for (int i = 0; i < 61; i++) {
    const double* p = tx_thread_position(t, i);
    if (fabs(p[0]) < 0.004) r.off = fmax(r.off, fabs(p[1]));
  }
  tx_thread_destroy(t);
  return r;
}

static void test_a_bite_runs_through_the_tissue(void** state) {
  (void)state;
  bite_result with = bite(true), without = bite(false);
  print_message("bite, sides given: strand %.3f mm off the mid-plane, strain %.4f; not given: %.3f mm, strain %.4f\n",
                with.off * 1e3, with.strain, without.off * 1e3, without.strain);
  assert_true(with.off < 0.0005);               // inside the sheet (0.37 mm: the entry's corner lies lower)
  assert_true(with.strain <= 0.05 + 1e-6);      // the cap
  assert_true(without.off > 0.0007);            // held out of it
  assert_true(without.strain > 0.06);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_slides_through_two_moving_punctures),
      cmocka_unit_test(test_taut_thread_loads_its_puncture_as_a_pulley),
      cmocka_unit_test(test_friction_raises_the_head_force),
      cmocka_unit_test(test_a_pulled_rod_slides_through_a_firm_puncture),
      cmocka_unit_test(test_a_thread_pulled_through_to_its_end_leaves_the_puncture),
      cmocka_unit_test(test_a_bite_runs_through_the_tissue),
      cmocka_unit_test(test_bad_puncture_lists),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
