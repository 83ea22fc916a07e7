// collision.hip through the loader, in lockstep, against a still synthetic
// skin published at 60 Hz: the force model while touching, zero once through,
// one BVH build per triangle set and one refit per publish, and a non-finite
// skin counted and never passed on.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/physics/skin_grid.h"
#include "scenarios/loader.h"
#include "tests/scenario_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define N 41
#define SPACING 5e-4

// a flat 2 x 2 cm skin of thickness 4 mm; from tear_at_s on, a corner cell
// is gone; from nan_at_s on, one particle is NaN
typedef struct test_skin {
  double tear_at_s, nan_at_s;
  tx_port x, tri, thickness;
  float px[3 * N * N];
  int32_t ptri[6 * (N - 1) * (N - 1)];
  uint32_t ntri;
} test_skin;

static int skin_configure(tx_setup* s, void** self) {
  test_skin* k = calloc(1, sizeof *k);
  if (!k) return -1;
  *self = k;
  k->tear_at_s = tx_param_num(s, "tear_at_s", 1e9, 0, 1e9);
  k->nan_at_s = tx_param_num(s, "nan_at_s", 1e9, 0, 1e9);
  k->ntri = tx_skin_grid(N, N, SPACING, SPACING, (double[3]){0, 0, 0}, k->px, k->ptri);
  k->x = tx_setup_write(s, &(tx_component_def){"skin.x", TX_F32, N * N, 3, "m"});
  k->tri = tx_setup_write(s, &(tx_component_def){"skin.tri", TX_I32, k->ntri, 3, "1"});
  k->thickness = tx_setup_write(s, &(tx_component_def){"skin.thickness", TX_F64, 1, 1, "m"});
  return 0;
}

static void skin_step(tx_ctx* c, void* self) {
  test_skin* k = self;
  double t = tx_sim_ns(c) * 1e-9;
  float* x = tx_write(c, k->x);
  memcpy(x, k->px, sizeof k->px);
  if (t >= k->nan_at_s) x[3 * 7] = NAN;
  uint32_t rows = t >= k->tear_at_s ? k->ntri - 2 : k->ntri; // the first cell's two triangles torn out
  int32_t* tri = tx_write(c, k->tri);
  memcpy(tri, k->ptri + 3 * (k->ntri - rows), 3 * sizeof *tri * rows);
  tx_write_rows(c, k->tri, rows);
  *(double*)tx_write(c, k->thickness) = 4e-3;
}

static void skin_fini(void* self) { free(self); }

static const tx_controller_class test_skin_class = {
    .type = "test.skin", .summary = "a still flat skin", .configure = skin_configure, .step = skin_step, .fini = skin_fini};

static tx_scenario* load(const char* skin_params) {
  char text[1024];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":["
           "{\"name\":\"skin\",\"type\":\"test.skin\",\"rate_hz\":60,\"params\":{%s}},"
           "{\"name\":\"hip\",\"type\":\"collision.hip\",\"rate_hz\":4000,\"params\":{\"force_mode\":\"paper\"}},"
           "{\"name\":\"haptics\",\"type\":\"haptics\",\"rate_hz\":1000,\"params\":{\"device\":\"scripted:pierce-down\","
           "\"force_model\":\"tool0.force_model\",\"record\":false}}]}",
           skin_params);
  tx_scenario* s = tx_scenario_load_text("test", text, strlen(text), NULL);
  if (!s) fail_msg("%s", tx_error());
  return s;
}

// pierce-down starts at y = 10 mm and moves down at 5 mm/s from 0.5 s: it
// reaches r + h/2 = 2.5 mm at 2.0 s and the mid-plane at 2.5 s
static void test_touching_then_through(void** state) {
  (void)state;
  tx_scenario* s = load("");
  run(s, 2.3); // y = 1 mm: touching a skin that does not give
  const double* m = latest(s, "tool0.force_model");
  const double* st = latest(s, "hip0.state");
  // rays with |d_y| > 1 / 2.5 touch: the down ray, four at 45 and four at 54.7 degrees.
  // The down ray began at y_on = r + h/2 = 2.5 mm and anchors the contact; its contact point
  // is on the still skin, R = 0. A ray at |d_y| joins at y_j = 2.5 mm |d_y| with
  // P_in = (0, y_on, 0) + t d, so R = (c - A) + (t - t_j) d, whose y part stays y_j - y_on
  // on the still skin: F_y = alpha / 9 x 4 ((y_on - y_45) + (y_on - y_54.7)), within the
  // 5 um a pose moves per 1 ms tick (each onset up to a tick late)
  assert_int_equal((int)st[0], 9);
  double want = 20.0 / 9 * 4 * (2 * 2.5e-3 - 2.5e-3 / sqrt(2.0) - 2.5e-3 / sqrt(3.0));
  assert_true(fabs(m[1] - want) < 1e-4);
  assert_true(fabs(m[0]) < 1e-9 && fabs(m[2]) < 1e-9);
  assert_true(fabs(m[6 + 4] + 20.0) < 1e-9); // K_yy = -alpha
  assert_true(st[1] == 0);
  // x0: where the HIP would just touch this skin coming down, r + h/2 above it
  assert_true(fabs(m[3 + 1] - 2.5e-3) < 1e-9 && fabs(m[3]) < 1e-12);
  // and the skin publish in use is the last 60 Hz one
  assert_true(fabs(st[7] - 137 / 60.0) < 1e-6);
  tx_scenario_free(s);

  s = load("");
  run(s, 2.6); // y = -0.5 mm: through the skin
  m = latest(s, "tool0.force_model");
  st = latest(s, "hip0.state");
  for (int i = 0; i < 3; i++) assert_true(m[i] == 0);
  assert_true(st[1] == 1);
  assert_true(result(s, "hip.pierces") == 1);
  assert_true(result(s, "hip.peak_force_N") > 0.03);
  assert_true(result(s, "hip.bvh_rebuilds") == 1);
  assert_true(result(s, "hip.bvh_refits") >= 150); // one per 60 Hz publish after the first
  tx_scenario_free(s);
}

static void test_torn_triangles_rebuild(void** state) {
  (void)state;
  tx_scenario* s = load("\"tear_at_s\": 1.0");
  run(s, 2.3);
  assert_true(result(s, "hip.bvh_rebuilds") == 1); // the tear empties two triangles in place
  assert_true(result(s, "hip.bvh_tears") == 1);
  assert_true(latest(s, "tool0.force_model")[1] > 0.01); // the tear is far from the HIP: as without it
  tx_scenario_free(s);
}

static void test_nan_skin_counted_and_dropped(void** state) {
  (void)state;
  tx_scenario* s = load("\"nan_at_s\": 2.1");
  run(s, 2.3);
  assert_true(warnings(s, "hip.skin_not_finite") > 0);
  const double* m = latest(s, "tool0.force_model");
  for (int i = 0; i < 15; i++) assert_true(isfinite(m[i]));
  assert_true(m[1] == 0); // no skin to trust, no force
  tx_scenario_free(s);
}

int main(void) {
  tx_register_builtin();
  tx_register_controller(&test_skin_class);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_touching_then_through),
      cmocka_unit_test(test_torn_triangles_rebuild),
      cmocka_unit_test(test_nan_skin_counted_and_dropped),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
