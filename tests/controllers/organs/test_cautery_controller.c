// physics.cautery through the loader, in lockstep beside physics.organs and
// a scripted hook, on the coarse copy of the LAGB assets: the hook held on
// the liver with its pedal down burns it there (temperature and Omega on
// liver.x's rows, the power all deposited, boiling at 100 C, the stomach
// untouched) and the spot cools once the pedal is up; with the pedal up or
// the tip off the tissue nothing heats; physics.instruments' L-hook drives
// it through its root link (with ODE); bad parameters and a missing asset
// are refused with one line naming the key or the file; with physics.organs
// listening, what boils is removed from both, and the liver is published
// as its live tetrahedra's boundary, sound (removal).
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/organs/removal.h"
#include "scenarios/loader.h"
#include "tests/scenario_support.h"

#include <tactus/components.h>
#include <tactus/config.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define COARSE TX_TEST_DIR "/coarse"

static char hook[64]; // the scripted hook's waypoints (a temporary file)
static double spot[3]; // the coarse liver's drawn vertex it burns

// the coarse liver's highest drawn vertex near x = z = 60 mm
static void find_spot(void) {
  FILE* f = fopen(COARSE "/liver.obj", "r");
  assert_non_null(f);
  char line[256];
  spot[1] = -1;
  while (fgets(line, sizeof line, f)) {
    double p[3];
    if (line[0] == 'v' && line[1] == ' ' && sscanf(line + 2, "%lf %lf %lf", p, p + 1, p + 2) == 3 &&
        hypot(p[0] - 0.06, p[2] - 0.06) < 0.012 && p[1] > spot[1])
      memcpy(spot, p, sizeof spot);
  }
  fclose(f);
  assert_true(spot[1] > 0.03);
}

// the 2 mm tool sphere 1.5 mm into the liver at the spot from 0.4 s, the
// pedal (bit 0) down from 0.5 s to 1.5 s, lifted at 2 s
static int write_hook(void** state) {
  (void)state;
  find_spot();
  snprintf(hook, sizeof hook, "/tmp/tx_cautery_hook_XXXXXX.csv");
  int fd = mkstemps(hook, 4);
  if (fd < 0) return -1;
  close(fd);
  FILE* f = fopen(hook, "w");
  if (!f) return -1;
  double x = spot[0], y = spot[1] + 0.0005, z = spot[2];
  fprintf(f, "t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad,buttons\n0,%g,%g,%g,1,0,0,0,0,0\n0.4,%g,%g,%g,1,0,0,0,0,0\n"
             "0.5,%g,%g,%g,1,0,0,0,0,1\n1.5,%g,%g,%g,1,0,0,0,0,0\n2,%g,%g,%g,1,0,0,0,0,0\n",
          x, y + 0.02, z, x, y, z, x, y, z, x, y, z, x, y + 0.02, z);
  fclose(f);
  return 0;
}

static int remove_hook(void** state) {
  (void)state;
  unlink(hook);
  return 0;
}

// params: the cautery's (JSON members)
static tx_scenario* load(const char* params) {
  char text[4096];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":["
           "{\"name\":\"organs\",\"type\":\"physics.organs\",\"rate_hz\":30,\"params\":{\"assets\":\"" COARSE "\",\"tool_radius_m\":0.002}},"
           "{\"name\":\"cautery\",\"type\":\"physics.cautery\",\"rate_hz\":100,"
           "\"params\":{%s%s%s%s}},"
           "{\"name\":\"haptics\",\"type\":\"haptics\",\"rate_hz\":1000,\"params\":{\"device\":\"scripted:%s\"}}]}",
           strstr(params, "assets") ? "\"button\":0" : "\"assets\":\"" COARSE "\"",
           strstr(params, "tip_y_m") ? "" : ",\"tip_y_m\":-0.002", params[0] ? "," : "", params, hook);
  return tx_scenario_load_text("test", text, strlen(text), NULL);
}

typedef struct field {
  double hottest, coolest, at_spot, omega, stomach_hi, stomach_lo;
} field;

static field read_field(tx_scenario* s) {
  tx_snapshot x = latest_snapshot(s, "liver.x"), t = latest_snapshot(s, "liver.temperature"),
              d = latest_snapshot(s, "liver.damage"), st = latest_snapshot(s, "stomach.temperature"),
              sx = latest_snapshot(s, "stomach.x");
  assert_int_equal(t.rows, x.rows); // one row per drawn vertex
  assert_int_equal(d.rows, x.rows);
  assert_int_equal(st.rows, sx.rows);
  const tx_temperature *tv = t.data, *sv = st.data;
  const tx_organ_damage* dv = d.data;
  field f = {-INFINITY, INFINITY, 0, 0, -INFINITY, INFINITY};
  int nearest = 0;
  const float* p = x.data;
  for (uint32_t i = 0; i < x.rows; i++) {
    assert_true(isfinite(tv[i].t) && isfinite(dv[i].omega) && dv[i].omega >= 0);
    f.hottest = fmax(f.hottest, tv[i].t), f.coolest = fmin(f.coolest, tv[i].t), f.omega = fmax(f.omega, dv[i].omega);
    if (hypot(hypot(p[3 * i] - spot[0], p[3 * i + 1] - spot[1]), p[3 * i + 2] - spot[2]) <
        hypot(hypot(p[3 * nearest] - spot[0], p[3 * nearest + 1] - spot[1]), p[3 * nearest + 2] - spot[2]))
      nearest = (int)i;
  }
  f.at_spot = tv[nearest].t;
  for (uint32_t i = 0; i < st.rows; i++) f.stomach_hi = fmax(f.stomach_hi, sv[i].t), f.stomach_lo = fmin(f.stomach_lo, sv[i].t);
  return f;
}

static void burns_the_spot_then_cools(void** state) {
  (void)state;
  tx_scenario* s = load("\"refine\":3");
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.5);
  field a = read_field(s);
  print_message("  pedal down 1 s: the spot %.1f K, the liver %.2f..%.1f K, Omega up to %.3g; the stomach %.3f..%.3f K\n",
                a.at_spot, a.coolest, a.hottest, a.omega, a.stomach_lo, a.stomach_hi);
  assert_true(a.at_spot > 360 && a.at_spot <= 373.15 + 1e-3); // burnt, never past boiling
  assert_true(a.hottest <= 373.15 + 1e-3);
  assert_true(fabs(a.coolest - 310.15) < 1e-3); // far away: the body's
  assert_true(a.omega > 1);
  assert_true(fabs(a.stomach_hi - 310.15) < 1e-4 && fabs(a.stomach_lo - 310.15) < 1e-4);
  tx_scenario_free(s);

  s = load("\"refine\":3");
  if (!s) fail_msg("%s", tx_error());
  run(s, 5.0);
  field b = read_field(s);
  print_message("  3.5 s after: the spot %.1f K\n", b.at_spot);
  assert_true(b.at_spot < a.at_spot - 5); // conduction and perfusion carry it off
  double active = result(s, "cautery.active_s"), energy = result(s, "cautery.energy_j");
  print_message("  active %.2f s, %.2f J deposited, %.2f J boiling; liver: peak %.1f K, %.3g m^3 with Omega > 1, %.3g m^3 "
                "boiled; step p99 %.3f ms\n",
                active, energy, result(s, "cautery.boiled_j"), result(s, "cautery.liver_peak_k"),
                result(s, "cautery.liver_damaged_m3"), result(s, "cautery.liver_boiled_m3"), result(s, "cautery.step_p99_ms"));
  assert_true(fabs(active - 1.0) < 0.021);   // the pedal's 1 s, to a step
  assert_true(fabs(energy - 30 * active) < 1e-9); // all 30 W deposited
  assert_true(result(s, "cautery.liver_damaged_m3") > 1e-9 && result(s, "cautery.liver_damaged_m3") < 1e-5);
  assert_true(result(s, "cautery.liver_boiled_m3") > 0 && result(s, "cautery.boiled_j") > 0);
  assert_true(result(s, "cautery.stomach_damaged_m3") == 0 && result(s, "cautery.stomach_peak_k") < 310.151);
  assert_int_equal(warnings(s, "cautery.bad_pose"), 0);
  assert_int_equal(warnings(s, "cautery.bad_surface"), 0);
  tx_scenario_free(s);
}

// physics.organs listening to the cautery's burns: the 1 s burn removes
// the tetrahedra whose boiled fraction passed remove_fraction (the same
// count in both), the liver is then published as its live tetrahedra's
// boundary (each row a distinct node, every row used, closed, the
// temperature one row a row); the hook then sits in the hole, off the
// tissue, and heats no more; with remove_fraction 0 nothing is removed,
// the drawn surface stays and the whole 1 s burn is deposited
static void removes_what_boils(void** state) {
  (void)state;
  const char* fractions[] = {"0.01", "0"};
  for (int k = 0; k < 2; k++) {
    char text[4096];
    snprintf(text, sizeof text,
             "{\"name\":\"t\",\"controllers\":["
             "{\"name\":\"organs\",\"type\":\"physics.organs\",\"rate_hz\":30,\"params\":{\"assets\":\"" COARSE
             "\",\"tool_radius_m\":0.002,\"burn_events\":\"cautery.burn\"}},"
             "{\"name\":\"cautery\",\"type\":\"physics.cautery\",\"rate_hz\":100,"
             "\"params\":{\"assets\":\"" COARSE "\",\"tip_y_m\":-0.002,\"refine\":2,\"power_w\":100,\"remove_fraction\":%s}},"
             "{\"name\":\"haptics\",\"type\":\"haptics\",\"rate_hz\":1000,\"params\":{\"device\":\"scripted:%s\"}}]}",
             fractions[k], hook);
    tx_scenario* s = tx_scenario_load_text("test", text, strlen(text), NULL);
    if (!s) fail_msg("%s", tx_error());
    run(s, 2.0);
    double removed = result(s, "cautery.removed_tets");
    print_message("  remove_fraction %s: %.0f tetrahedra removed (%.3g m^3), %.1f J deposited in %.2f s\n", fractions[k], removed,
                  result(s, "cautery.removed_m3"), result(s, "cautery.energy_j"), result(s, "cautery.active_s"));
    assert_true(result(s, "organs.removed_tets") == removed);
    assert_int_equal(warnings(s, "organs.burn_refused"), 0);
    assert_int_equal(warnings(s, "cautery.bad_surface"), 0);
    // deposited while it touched: once the tissue under it is gone the tip is in the hole, off the tissue
    double active = result(s, "cautery.active_s");
    assert_true(fabs(result(s, "cautery.energy_j") - 100 * active) < 1e-9);
    assert_true(k == 1 ? fabs(active - 1.0) < 0.021 : active < 1.0 - 0.05);
    tx_snapshot x = latest_snapshot(s, "liver.x"), tri = latest_snapshot(s, "liver.tri"), nd = latest_snapshot(s, "liver.surface_node"),
                t = latest_snapshot(s, "liver.temperature");
    assert_int_equal(nd.rows, x.rows);
    const int32_t* node = &((const tx_surface_node*)nd.data)->node;
    if (k == 1) {
      assert_true(removed == 0);
      for (uint32_t r = 0; r < nd.rows; r++) assert_int_equal(node[r], -1);
      tx_scenario_free(s);
      continue;
    }
    assert_true(removed >= 1);
    assert_int_equal(t.rows, x.rows);
    int nodes = 0;
    for (uint32_t r = 0; r < nd.rows; r++) nodes = node[r] + 1 > nodes ? node[r] + 1 : nodes;
    uint64_t* keys = malloc(sizeof(uint64_t) * 3 * tri.rows);
    int32_t* seen = malloc(sizeof(int32_t) * (size_t)(nodes > (int)x.rows ? nodes : (int)x.rows));
    tx_surface_report rep;
    bool sound = tx_surface_check(&((const tx_triangle*)tri.data)->v[0], (int)tri.rows, (int)x.rows, node, nodes, keys, seen, &rep);
    print_message("  the cut liver: %d rows, %d triangles, %d edges (%d of more than two triangles)\n", rep.rows, rep.triangles,
                  rep.edges, rep.nonmanifold_edges);
    assert_true(sound);
    const tx_temperature* tv = t.data;
    const float* xv = x.data;
    for (uint32_t r = 0; r < x.rows; r++) {
      assert_true(node[r] >= 0);
      assert_true(isfinite(xv[3 * r] + xv[3 * r + 1] + xv[3 * r + 2]));
      assert_true(tv[r].t >= 310.15f - 1e-3f && tv[r].t <= 373.15f + 1e-3f);
    }
    free(keys), free(seen);
    tx_scenario_free(s);
  }
}

// the pedal on another bit, or the tip 3 cm above the tissue: no heat
static void nothing_heats_unless_active_and_touching(void** state) {
  (void)state;
  const char* params[] = {"\"button\":1,\"refine\":0", "\"tip_y_m\":0.03,\"refine\":0", "\"power_w\":0,\"refine\":0"};
  for (int i = 0; i < 3; i++) {
    tx_scenario* s = load(params[i]);
    if (!s) fail_msg("%s", tx_error());
    run(s, 1.5);
    field f = read_field(s);
    assert_true(fabs(f.hottest - 310.15) < 1e-4 && fabs(f.coolest - 310.15) < 1e-4);
    assert_true(result(s, "cautery.energy_j") == 0 && result(s, "cautery.active_s") == 0);
    tx_scenario_free(s);
  }
}

#if TX_WITH_ODE
// the hook as physics.instruments' L-hook (hook_cautery), held by the
// scripted hand 1 cm behind the spot: the cautery follows its root link
// (instrument0.links' first row) and the electrode's end 1 cm along its x
static void follows_the_hook_instrument(void** state) {
  (void)state;
  char path[64];
  snprintf(path, sizeof path, "/tmp/tx_cautery_hand_XXXXXX.csv");
  int fd = mkstemps(path, 4);
  assert_true(fd >= 0);
  close(fd);
  FILE* f = fopen(path, "w");
  assert_non_null(f);
  double x = spot[0] - 0.01, y = spot[1] - 0.001, z = spot[2];
  fprintf(f, "t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad,buttons\n0,%g,%g,%g,1,0,0,0,0,0\n0.4,%g,%g,%g,1,0,0,0,0,0\n"
             "0.5,%g,%g,%g,1,0,0,0,0,1\n1.5,%g,%g,%g,1,0,0,0,0,0\n",
          x, y + 0.02, z, x, y, z, x, y, z, x, y, z);
  fclose(f);
  char text[4096];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":["
           "{\"name\":\"haptics\",\"type\":\"haptics\",\"rate_hz\":1000,\"params\":{\"device\":\"scripted:%s\"}},"
           "{\"name\":\"instruments\",\"type\":\"physics.instruments\",\"rate_hz\":1000,"
           "\"params\":{\"instrument0\":\"hook_cautery\",\"table_height_m\":-1,\"gravity_m_s2\":0}},"
           "{\"name\":\"organs\",\"type\":\"physics.organs\",\"rate_hz\":30,\"params\":{\"assets\":\"" COARSE "\",\"tool_radius_m\":0}},"
           "{\"name\":\"cautery\",\"type\":\"physics.cautery\",\"rate_hz\":100,"
           "\"params\":{\"assets\":\"" COARSE "\",\"pose\":\"instrument0.links\",\"tip_x_m\":0.01,\"refine\":3}}]}",
           path);
  tx_scenario* s = tx_scenario_load_text("test", text, strlen(text), NULL);
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.5);
  field a = read_field(s);
  double active = result(s, "cautery.active_s");
  print_message("  the L-hook: active %.2f s, the spot %.1f K\n", active, a.at_spot);
  assert_true(fabs(active - 1.0) < 0.021);
  assert_true(fabs(result(s, "cautery.energy_j") - 30 * active) < 1e-9);
  assert_true(a.at_spot > 340);
  tx_scenario_free(s);
  unlink(path);
}
#endif

static void expect_refused(const char* params, const char* needle) { assert_refused(load(params), needle); }

static void bad_parameters_and_assets(void** state) {
  (void)state;
  expect_refused("\"power_w\":-1", "power_w");
  expect_refused("\"radius_m\":0", "radius_m");
  expect_refused("\"refine\":4", "refine");
  expect_refused("\"button\":32", "button");
  expect_refused("\"vaporisation_k\":320,\"blood_k\":320", "vaporisation_k");
  expect_refused("\"liver_k\":0", "liver_k");
  expect_refused("\"pose\":\"\"", "pose");
  expect_refused("\"events\":\"\"", "events");
  expect_refused("\"remove_fraction\":1.5", "remove_fraction");
  expect_refused("\"assets\":\"/nonexistent/lagb\"", "/nonexistent/lagb/liver.node");
  tx_scenario* s = tx_scenario_load_text("test",
      "{\"name\":\"t\",\"controllers\":[{\"name\":\"cautery\",\"type\":\"physics.cautery\",\"rate_hz\":50}]}", 85, NULL);
  assert_null(s);
  print_message("  %s\n", tx_error());
  assert_non_null(strstr(tx_error(), "100 to 1000 Hz"));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(burns_the_spot_then_cools),
      cmocka_unit_test(nothing_heats_unless_active_and_touching),
      cmocka_unit_test(removes_what_boils),
#if TX_WITH_ODE
      cmocka_unit_test(follows_the_hook_instrument),
#endif
      cmocka_unit_test(bad_parameters_and_assets),
  };
  return cmocka_run_group_tests(tests, write_hook, remove_hook);
}
