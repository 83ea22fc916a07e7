// physics.organs through the loader, in lockstep beside a scripted probe, on
// a coarse copy of the LAGB assets (coarse/: the pipeline at 4 mm voxels,
// about 400 tetrahedra an organ): the organs settle under gravity held at
// their attachments; the probe pushing the liver moves its surface and meets
// a reaction along the push that grows with depth; a fault is counted and
// recovered, never published; bad parameters and a missing asset are refused
// with one line naming the key and the file.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "scenarios/loader.h"
#include "tests/scenario_support.h"

#include <tactus/components.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define COARSE TX_TEST_DIR "/coarse"

static char probe[64]; // the scripted probe's waypoints (a temporary file)

// the probe (radius 5 mm) held 2.5 cm above y = top until 0.3 s, then down
// to 5 mm into the surface at 1 s, held to 1.3 s, 10 mm at 2 s, held
static void write_probe_at(double top) {
  FILE* f = fopen(probe, "w");
  assert_non_null(f);
  fprintf(f, "t_s,x_m,y_m,z_m\n0,0.06,%g,0.06\n0.3,0.06,%g,0.06\n1,0.06,%g,0.06\n1.3,0.06,%g,0.06\n2,0.06,%g,0.06\n5,0.06,%g,0.06\n",
          top + 0.025, top + 0.025, top, top, top - 0.005, top - 0.005);
  fclose(f);
}

static int write_probe(void** state) {
  (void)state;
  snprintf(probe, sizeof probe, "/tmp/tx_organs_probe_XXXXXX.csv");
  int fd = mkstemps(probe, 4);
  if (fd < 0) return -1;
  close(fd);
  write_probe_at(0.06);
  return 0;
}

static int remove_probe(void** state) {
  (void)state;
  unlink(probe);
  return 0;
}

// params: the organs' (JSON members); the coarse assets unless they name others
static tx_scenario* load(const char* params) {
  char text[4096];
  bool own = strstr(params, "\"assets\"") != NULL;
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":["
           "{\"name\":\"organs\",\"type\":\"physics.organs\",\"rate_hz\":30,\"params\":{%s%s%s}},"
           "{\"name\":\"haptics\",\"type\":\"haptics\",\"rate_hz\":1000,\"params\":{\"device\":\"scripted:%s\"}}]}",
           own ? "" : "\"assets\":\"" COARSE "\"", own || !params[0] ? "" : ",", params, probe);
  return tx_scenario_load_text("test", text, strlen(text), NULL);
}

static bool all_finite(tx_snapshot x) {
  const float* p = x.data;
  for (uint32_t i = 0; i < 3 * x.rows; i++)
    if (!isfinite(p[i])) return false;
  return true;
}

// the largest distance a surface vertex moved between two publishes
static double moved(tx_snapshot a, tx_snapshot b) {
  double m = 0;
  const float *p = a.data, *q = b.data;
  for (uint32_t i = 0; i < 3 * a.rows; i += 3)
    m = fmax(m, sqrt(pow(p[i] - q[i], 2) + pow(p[i + 1] - q[i + 1], 2) + pow(p[i + 2] - q[i + 2], 2)));
  return m;
}

// the vertices of a surface at rest, as the asset has them
static float* read_obj_vertices(const char* path, int n) {
  FILE* f = fopen(path, "r");
  assert_non_null(f);
  float* x = malloc(sizeof(float) * 3 * (size_t)n);
  char line[256];
  int i = 0;
  while (fgets(line, sizeof line, f))
    if (line[0] == 'v' && line[1] == ' ') {
      assert_true(i < n);
      assert_int_equal(sscanf(line + 2, "%f %f %f", x + 3 * i, x + 3 * i + 1, x + 3 * i + 2), 3);
      i++;
    }
  fclose(f);
  assert_int_equal(i, n);
  return x;
}

// 1 s under gravity, the probe far above: in both modes the organs sag, held
// at their attachments, without a fault
static void settles_under_gravity(void** state) {
  (void)state;
  const char* modes[] = {"\"gravity\":true,\"mode\":\"fem\"", "\"gravity\":true,\"mode\":\"fem\",\"model\":\"corotated\"",
                         "\"gravity\":true,\"mode\":\"links\""};
  for (int m = 0; m < 3; m++) {
    tx_scenario* s = load(modes[m]);
    if (!s) fail_msg("%s", tx_error());
    float* rest = read_obj_vertices(COARSE "/liver.obj", 302);
    float* srest = read_obj_vertices(COARSE "/stomach.obj", 252);
    run(s, 1.0);
    tx_snapshot liver = latest_snapshot(s, "liver.x"), stomach = latest_snapshot(s, "stomach.x"),
                tri = latest_snapshot(s, "liver.tri"), spleen = latest_snapshot(s, "spleen.tri");
    assert_int_equal(liver.rows, 302); // the coarse drawn surfaces (coarse/lagb.json)
    assert_int_equal(tri.rows, 600);
    assert_int_equal(stomach.rows, 252);
    assert_int_equal(spleen.rows, 200);
    assert_true(all_finite(liver) && all_finite(stomach));
    double sag = moved((tx_snapshot){.data = rest, .rows = liver.rows}, liver),
           ssag = moved((tx_snapshot){.data = srest, .rows = stomach.rows}, stomach);
    print_message("  %s: liver sags %.2f mm, stomach %.2f mm\n", modes[m], sag * 1e3, ssag * 1e3);
    assert_true(sag > 1e-4 && sag < 0.5); // it moved (unsupported, a lobe hangs by centimetres)
    assert_true(ssag > 1e-4 && ssag < 0.5);
    // held: the liver's most cranial vertex has not moved
    const float* p = liver.data;
    int top = 0;
    for (uint32_t i = 0; i < liver.rows; i++)
      if (rest[3 * i + 2] > rest[3 * top + 2]) top = (int)i;
    assert_true(fabs(p[3 * top + 1] - rest[3 * top + 1]) < 2e-3);
    assert_int_equal(warnings(s, "organs.numerical_fault"), 0);
    assert_int_equal(result(s, "organs.faults"), 0);
    free(rest);
    free(srest);
    tx_scenario_free(s);
  }
}

typedef struct pressed {
  double f[3], depth, k, moved_down;
} pressed;

// the liver's surface under the probe's path (x = z = 60 mm), m: its highest vertex there
static double top_under_probe(tx_snapshot x) {
  const float* p = x.data;
  double top = -1;
  for (uint32_t i = 0; i < x.rows; i++)
    if (hypot(p[3 * i] - 0.06, p[3 * i + 2] - 0.06) < 0.012) top = fmax(top, p[3 * i + 1]);
  return top;
}

// the probe over the liver at rest (gravity off: the surface stays where
// the asset has it), run to t
static pressed press(const char* params, double t) {
  float* rest = read_obj_vertices(COARSE "/liver.obj", 302);
  double top = top_under_probe((tx_snapshot){.data = rest, .rows = 302});
  assert_true(top > 0.03);
  write_probe_at(top); // the sphere's centre at the surface: its radius, 5 mm, into it
  tx_scenario* s = load(params);
  if (!s) fail_msg("%s", tx_error());
  run(s, t);
  tx_snapshot x = latest_snapshot(s, "liver.x");
  assert_true(all_finite(x));
  const tx_skin_contact* c = latest_snapshot(s, "organs.contact").data;
  pressed out = {.depth = c->depth, .k = c->k};
  memcpy(out.f, c->f, sizeof out.f);
  out.moved_down = top - top_under_probe(x);
  assert_int_equal(warnings(s, "organs.numerical_fault"), 0);
  free(rest);
  tx_scenario_free(s);
  return out;
}

// the probe pushes down (-y) into the liver: the surface under it goes down,
// the reaction on the probe points up (+y), and it grows with the depth
static void probe_pushes_the_liver(void** state) {
  (void)state;
  const char* modes[] = {"\"mode\":\"fem\"", "\"mode\":\"links\""};
  for (int m = 0; m < 2; m++) {
    pressed a = press(modes[m], 1.3), b = press(modes[m], 2.5);
    print_message("  %s: at %.1f mm, f = (%.3f, %.3f, %.3f) N, k = %.0f N/m, surface down %.1f mm; at %.1f mm, f = "
                  "(%.3f, %.3f, %.3f) N, k = %.0f N/m, down %.1f mm\n",
                  modes[m], a.depth * 1e3, a.f[0], a.f[1], a.f[2], a.k, a.moved_down * 1e3, b.depth * 1e3, b.f[0], b.f[1],
                  b.f[2], b.k, b.moved_down * 1e3);
    assert_true(a.depth > 0.002 && b.depth > a.depth);
    assert_true(a.f[1] > 0 && b.f[1] > 1.2 * a.f[1]);             // up, growing with depth
    assert_true(b.f[1] > 0.8 * sqrt(b.f[0] * b.f[0] + b.f[1] * b.f[1] + b.f[2] * b.f[2])); // mostly along the push
    assert_true(a.moved_down > 0.002 && b.moved_down > a.moved_down); // the surface gave way under it
    assert_true(a.k > 0 && b.k > 0);
  }
}

// a node faster than max_speed is a blow-up: counted, the organs back to
// their last good state, nothing non-finite published
static void fault_is_recovered(void** state) {
  (void)state;
  tx_scenario* s = load("\"max_speed\":0.01,\"gravity\":true");
  if (!s) fail_msg("%s", tx_error());
  run(s, 0.5);
  assert_true(warnings(s, "organs.numerical_fault") > 0);
  assert_true(result(s, "organs.faults") > 0);
  tx_snapshot x = latest_snapshot(s, "liver.x");
  assert_true(all_finite(x));
  tx_scenario_free(s);
}

static void expect_refused(const char* params, const char* needle) { assert_refused(load(params), needle); }

static void bad_parameters_and_assets(void** state) {
  (void)state;
  expect_refused("\"mode\":\"rigid\"", "mode");
  expect_refused("\"model\":\"hooke\"", "model");
  expect_refused("\"poisson\":0.5", "poisson");
  expect_refused("\"assets\":\"/nonexistent/lagb\"", "/nonexistent/lagb/liver.node");
  expect_refused("\"assets\":\"" TX_TEST_DIR "\"", "liver.node");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(settles_under_gravity),
      cmocka_unit_test(probe_pushes_the_liver),
      cmocka_unit_test(fault_is_recovered),
      cmocka_unit_test(bad_parameters_and_assets),
  };
  return cmocka_run_group_tests(tests, write_probe, remove_probe);
}
