// collision.organ through the loader, in lockstep: a fixture publishes two
// geodesic spheres as the liver and the stomach at 20 Hz (and, when asked,
// the organs' reaction), another lowers the tool onto the liver's top at
// 10 mm/s. The force model is the penalty on the sphere's closed-form depth,
// then the physics' reaction carried to the hand, then the penalty with the
// reaction's last stiffness; a surface that moves is refitted and gives the
// new depth; a non-finite surface is counted and never pushes; bad
// parameters and missing components are refused naming the key.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "scenarios/loader.h"
#include "tests/controllers/collision/organ_shapes.h"
#include "tests/scenario_support.h"

#include <tactus/components.h>

#include "tests/alloc_count.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define R 0.05    // m, the liver sphere, its top at y = 0
#define TIP 2.5e-3
#define SAG 1e-4  // m, more than the level-4 sphere's facets fall inside it (57 um)

typedef struct test_organs {
  double shift_at_s, shift_m, nan_at_s, touch_from_s, touch_until_s;
  shape liver, stomach;
  tx_port lx, ltri, sx, stri, contact;
} test_organs;

static int organs_configure(tx_setup* s, void** self) {
  test_organs* k = calloc(1, sizeof *k);
  if (!k) return -1;
  *self = k;
  k->shift_at_s = tx_param_num(s, "shift_at_s", 1e9, 0, 1e9);
  k->shift_m = tx_param_num(s, "shift_m", 0, -1, 1);
  k->nan_at_s = tx_param_num(s, "nan_at_s", 1e9, 0, 1e9);
  k->touch_from_s = tx_param_num(s, "touch_from_s", 1e9, 0, 1e9);
  k->touch_until_s = tx_param_num(s, "touch_until_s", 1e9, 0, 1e9);
  k->liver = ico_sphere(4, R, (double[3]){0, -R, 0});
  k->stomach = ico_sphere(2, 0.03, (double[3]){0.2, 0, 0});
  k->lx = tx_setup_write(s, &TX_COMPONENT_OF("liver.x", tx_vertex, k->liver.nx));
  k->ltri = tx_setup_write(s, &TX_COMPONENT_OF("liver.tri", tx_triangle, k->liver.ntri));
  k->sx = tx_setup_write(s, &TX_COMPONENT_OF("stomach.x", tx_vertex, k->stomach.nx));
  k->stri = tx_setup_write(s, &TX_COMPONENT_OF("stomach.tri", tx_triangle, k->stomach.ntri));
  k->contact = tx_setup_write(s, &TX_COMPONENT_OF("organs.contact", tx_skin_contact, 1));
  return 0;
}

static void organs_step(tx_ctx* c, void* self) {
  test_organs* k = self;
  double t = tx_sim_ns(c) * 1e-9;
  float* x = tx_write(c, k->lx);
  memcpy(x, k->liver.x, sizeof(float) * 3 * k->liver.nx);
  if (t >= k->shift_at_s)
    for (uint32_t i = 0; i < k->liver.nx; i++) x[3 * i + 1] += (float)k->shift_m;
  if (t >= k->nan_at_s) x[3 * 5] = NAN;
  memcpy(tx_write(c, k->ltri), k->liver.tri, sizeof(int32_t) * 3 * k->liver.ntri);
  memcpy(tx_write(c, k->sx), k->stomach.x, sizeof(float) * 3 * k->stomach.nx);
  memcpy(tx_write(c, k->stri), k->stomach.tri, sizeof(int32_t) * 3 * k->stomach.ntri);
  // the reaction as the physics would leave it: 0.3 N up, computed with the tool at y = -1 mm
  tx_skin_contact* r = tx_write(c, k->contact);
  bool on = t >= k->touch_from_s && t < k->touch_until_s;
  *r = (tx_skin_contact){.f = {0, on ? 0.3 : 0, 0}, .x = {0, -1e-3, 0}, .n = {0, on ? 1 : 0, 0}, .k = on ? 150 : 0,
                         .depth = on ? 3.5e-3 : 0, .touching = on};
}

static void organs_fini(void* self) {
  test_organs* k = self;
  shape_free(&k->liver);
  shape_free(&k->stomach);
  free(k);
}

static const tx_controller_class test_organs_class = {.type = "test.organs",
                                                      .summary = "two still spheres as organs",
                                                      .configure = organs_configure,
                                                      .step = organs_step,
                                                      .fini = organs_fini};

// the tool: 5 mm above the liver's top, down at 10 mm/s
typedef struct test_tool {
  tx_port pose;
} test_tool;

static int tool_configure(tx_setup* s, void** self) {
  test_tool* k = calloc(1, sizeof *k);
  if (!k) return -1;
  *self = k;
  k->pose = tx_setup_write(s, &TX_COMPONENT_OF("device0.pose", tx_pose, 1));
  return 0;
}

static void tool_step(tx_ctx* c, void* self) {
  test_tool* k = self;
  tx_pose* p = tx_write(c, k->pose);
  *p = (tx_pose){.pos = {0, 5e-3 - 0.01 * tx_sim_ns(c) * 1e-9, 0}, .quat = {1, 0, 0, 0}};
}

static void tool_fini(void* self) { free(self); }

static const tx_controller_class test_tool_class = {
    .type = "test.tool", .summary = "a tool lowered", .configure = tool_configure, .step = tool_step, .fini = tool_fini};

static tx_scenario* try_load(const char* organ_params, const char* col_params) {
  char text[2048];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":["
           "{\"name\":\"organs\",\"type\":\"test.organs\",\"rate_hz\":20,\"params\":{%s}},"
           "{\"name\":\"tool\",\"type\":\"test.tool\",\"rate_hz\":1000},"
           "{\"name\":\"col\",\"type\":\"collision.organ\",\"rate_hz\":4000,\"params\":{%s}}]}",
           organ_params, col_params);
  return tx_scenario_load_text("test", text, strlen(text), NULL);
}

static tx_scenario* load(const char* organ_params, const char* col_params) {
  tx_scenario* s = try_load(organ_params, col_params);
  if (!s) fail_msg("%s", tx_error());
  return s;
}

// the tool's last pose
static double tool_y(tx_scenario* s) { return latest(s, "device0.pose")[1]; }

static void test_penalty_on_the_sphere(void** state) {
  (void)state;
  tx_scenario* s = load("", "\"contact\": \"\"");
  run(s, 0.75); // the tool about 2.5 mm below the top
  const double* m = latest(s, "tool0.force_model");
  double y = tool_y(s), depth = TIP - y; // the sphere's closed form, less up to SAG
  assert_true(y < -2e-3);
  assert_true(m[1] <= 100 * depth + 1e-9 && m[1] >= 100 * (depth - SAG));
  assert_true(fabs(m[0]) < 0.05 * m[1] && fabs(m[2]) < 0.05 * m[1]); // out of the surface: up
  assert_true(fabs(m[3 + 1] - y) < 1e-12);                              // x0: the tip's centre
  assert_true(m[6 + 4] < -99 && m[6 + 4] > -100.0001);                  // K_yy = -k n_y^2
  assert_true(result(s, "col.contacts") == 1);
  assert_true(result(s, "col.penalty_steps") > 0 && result(s, "col.reaction_steps") == 0);
  assert_true(result(s, "col.bvh_rebuilds") == 2); // one per organ, then refits
  assert_true(result(s, "col.bvh_refits") >= 2 * 13);
  assert_true(result(s, "col.inside_unentered") == 0);
  tx_scenario_free(s);
}

// the liver moves up by 1 mm at its first publish after 0.5 s: the refit gives 1 mm more depth
static void test_refit_gives_the_new_contact(void** state) {
  (void)state;
  tx_scenario* s = load("\"shift_at_s\": 0.5, \"shift_m\": 0.001", "\"contact\": \"\"");
  run(s, 0.75);
  double depth = TIP - tool_y(s) + 1e-3;
  double f = latest(s, "tool0.force_model")[1];
  assert_true(f <= 100 * depth + 1e-6 && f >= 100 * (depth - SAG));
  tx_scenario_free(s);
  // and a surface away from the tool by more than r + hold ends the contact
  s = load("\"shift_at_s\": 0.7, \"shift_m\": -0.01", "\"contact\": \"\"");
  run(s, 0.75);
  const double* m = latest(s, "tool0.force_model");
  for (int i = 0; i < 15; i++)
    if (i < 3 || i >= 6) assert_true(m[i] == 0); // F0 and K; x0 is the tip

  tx_scenario_free(s);
}

// the physics touches from 0.6 to 0.7 s: its reaction is carried to the hand, F = f - k ((c - x) . n) n;
// after it the penalty uses the reaction's last stiffness
static void test_reaction_then_its_stiffness(void** state) {
  (void)state;
  tx_scenario* s = load("\"touch_from_s\": 0.6, \"touch_until_s\": 0.7", "");
  run(s, 0.65);
  const double* m = latest(s, "tool0.force_model");
  double y = tool_y(s);
  assert_true(fabs(m[1] - (0.3 - 150 * (y + 1e-3))) < 1e-9);
  assert_true(fabs(m[6 + 4] + 150) < 1e-9);
  assert_true(result(s, "col.reaction_steps") > 0);
  assert_true(result(s, "col.penalty_steps") > 0); // before 0.6 s (contact from 0.25 s)
  tx_scenario_free(s);
  s = load("\"touch_from_s\": 0.6, \"touch_until_s\": 0.7", "");
  run(s, 0.75);
  double depth = TIP - tool_y(s), f = latest(s, "tool0.force_model")[1];
  assert_true(f <= 150 * depth + 1e-9 && f >= 150 * (depth - SAG));
  tx_scenario_free(s);
}

static void test_non_finite_surface_counted_and_dropped(void** state) {
  (void)state;
  tx_scenario* s = load("\"nan_at_s\": 0.7", "\"contact\": \"\"");
  run(s, 0.75);
  assert_true(warnings(s, "col.organ_not_finite") > 0);
  const double* m = latest(s, "tool0.force_model");
  for (int i = 0; i < 15; i++) assert_true(isfinite(m[i]));
  assert_true(m[1] == 0); // no surface to trust, no force
  tx_scenario_free(s);
}

// with the haptics controller rendering the model (scripted pierce-down: from y = 10 mm at 0.5 s
// down at 5 mm/s, touching the liver's top from 2.0 s): the force sent is k times the depth
static void test_rendered_by_haptics(void** state) {
  (void)state;
  const char* text = "{\"name\":\"t\",\"controllers\":["
                     "{\"name\":\"organs\",\"type\":\"test.organs\",\"rate_hz\":20},"
                     "{\"name\":\"col\",\"type\":\"collision.organ\",\"rate_hz\":4000,\"params\":{\"contact\":\"\"}},"
                     "{\"name\":\"haptics\",\"type\":\"haptics\",\"rate_hz\":1000,\"params\":{\"device\":\"scripted:pierce-down\","
                     "\"force_model\":\"tool0.force_model\",\"record\":false}}]}";
  tx_scenario* s = tx_scenario_load_text("test", text, strlen(text), NULL);
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.9);
  assert_true(latest(s, "device0.force")[1] == 0); // 0.5 mm above the contact
  tx_scenario_free(s);
  s = tx_scenario_load_text("test", text, strlen(text), NULL);
  if (!s) fail_msg("%s", tx_error());
  run(s, 2.3); // y = 1 mm, 1.5 mm deep
  double y = tool_y(s), f = latest(s, "device0.force")[1];
  assert_true(fabs(y - 1e-3) < 1e-5);
  assert_true(f <= 100 * (TIP - y) + 1e-3 && f >= 100 * (TIP - y - SAG) - 1e-3);
  tx_scenario_free(s);
}

#ifndef TX_NO_ALLOC_COUNT
// a run 4 times longer (3600 more steps, 18 more publishes, contact all along) allocates no more
static long allocations_in_run(double seconds) {
  tx_scenario* s = load("\"touch_from_s\": 0.3, \"touch_until_s\": 0.4", "");
  allocations = 0;
  counting = 1;
  run(s, seconds);
  counting = 0;
  assert_true(result(s, "col.contacts") >= 1);
  tx_scenario_free(s);
  return allocations;
}
#endif

static void test_steps_allocate_nothing(void** state) {
  (void)state;
#ifndef TX_NO_ALLOC_COUNT
  long short_run = allocations_in_run(0.3), long_run = allocations_in_run(1.2);
  assert_int_equal(long_run, short_run);
#else
  skip();
#endif
}

static void refused(const char* col_params, const char* names) {
  tx_scenario* s = try_load("", col_params);
  if (s) tx_scenario_free(s);
  assert_null(s);
  if (!strstr(tx_error(), names)) fail_msg("'%s' does not name %s", tx_error(), names);
  assert_null(strchr(tx_error(), '\n'));
}

static void test_bad_parameters_refused(void** state) {
  (void)state;
  refused("\"radius_m\": 1", "radius_m");
  refused("\"depth_max_m\": 0.002", "depth_max_m");
  refused("\"organs\": [\"liver\", \"liver\"]", "organs");
  refused("\"organs\": [\"spleen\"]", "spleen.x");
  refused("\"contact\": \"nobody.contact\"", "nobody.contact");
  refused("\"pose\": \"device9.pose\"", "device9.pose");
  refused("\"stiffness\": -1", "stiffness");
}

int main(void) {
  tx_register_builtin();
  tx_register_controller(&test_organs_class);
  tx_register_controller(&test_tool_class);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_penalty_on_the_sphere),
      cmocka_unit_test(test_refit_gives_the_new_contact),
      cmocka_unit_test(test_reaction_then_its_stiffness),
      cmocka_unit_test(test_non_finite_surface_counted_and_dropped),
      cmocka_unit_test(test_rendered_by_haptics),
      cmocka_unit_test(test_steps_allocate_nothing),
      cmocka_unit_test(test_bad_parameters_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
