// physics.instruments in a scenario: a scripted hand moves and squeezes, the
// instrument's root follows it through the coupling, the jaws follow the
// grip, and the haptics controller renders the coupling force (the
// instrument's weight, held still); a description it cannot read is refused
// at load with the key named.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "model/error.h"
#include "scenarios/loader.h"
#include "tests/scenario_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char csv[64];

static tx_scenario* load(const char* extra) {
  char text[2048];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":["
           "{\"name\":\"haptics\",\"type\":\"haptics\",\"rate_hz\":1000,\"params\":{\"device\":\"scripted:%s\","
           "\"force_model\":\"instrument0.force_model\"}},"
           "{\"name\":\"instruments\",\"type\":\"physics.instruments\",\"rate_hz\":1000,\"params\":{%s}}]}",
           csv, extra);
  return tx_scenario_load_text("test", text, strlen(text), NULL);
}

static int setup(void** state) {
  (void)state;
  snprintf(csv, sizeof csv, "/tmp/tx-instr-XXXXXX.csv");
  int fd = mkstemps(csv, 4);
  if (fd < 0) return -1;
  // still for 0.5 s, then 2 cm along x over 0.5 s while the grip opens to 0.4 rad, then still
  const char* rows = "t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad\n"
                     "0,0,0,0,1,0,0,0,0\n0.5,0,0,0,1,0,0,0,0\n1.0,0.02,0,0,1,0,0,0,0.4\n";
  ssize_t n = write(fd, rows, strlen(rows));
  close(fd);
  return n == (ssize_t)strlen(rows) ? 0 : -1;
}
static int teardown(void** state) {
  (void)state;
  unlink(csv);
  return 0;
}

static void test_follows_the_hand_and_renders_the_weight(void** state) {
  (void)state;
  tx_scenario* s = load("\"instrument0\":\"needle_holder\"");
  if (!s) fail_msg("%s", tx_error());
  run(s, 0.45);
  // held still: the hand carries the instrument's weight through the coupling
  double fy = latest(s, "device0.force")[1];
  print_message("  held still: the hand feels %.4f N (down); 30.7 g x g = 0.301 N\n", fy);
  assert_true(fabs(fy + 0.0307 * 9.81) < 0.01);
  run(s, 1.55);
  const double* dev = latest(s, "device0.pose");
  const double* ins = latest(s, "instrument0.pose");
  double dx = ins[0] - dev[0], dy = ins[1] - dev[1];
  print_message("  moved 2 cm: the root is %.3f mm along x and %.3f mm along y from the hand; jaws %.3f rad apart\n",
                1e3 * dx, 1e3 * dy, ins[7]);
  assert_true(fabs(dev[0] - 0.02) < 1e-9);
  assert_true(fabs(dx) < 1e-4);
  assert_true(fabs(dy + 0.0307 * 9.81 / 200) < 2e-4); // sags by m g / k
  assert_true(fabs(ins[7] - 0.4) < 0.01); // the grip, between the jaws
  const double* links = latest(s, "instrument0.links");
  for (int l = 0; l < 3; l++) assert_true(fabs(links[7 * l] - ins[0]) < 1e-6); // all three frames at the pivot
  assert_true(result(s, "instruments.coupling_force_max_n") <= 3.3);
  assert_int_equal(warnings(s, "instruments.device_not_finite"), 0);
  tx_scenario_free(s);
}

static void test_refuses_what_it_cannot_read(void** state) {
  (void)state;
  tx_scenario* s = load("\"instrument0\":\"no_such_instrument\"");
  assert_null(s);
  print_message("  %s\n", tx_error());
  assert_non_null(strstr(tx_error(), "instrument0"));
  assert_non_null(strstr(tx_error(), "no_such_instrument.urdf"));
  s = load("\"instrument0\":\"\",\"instrument1\":\"lap_grasper\"");
  assert_null(s);
  assert_non_null(strstr(tx_error(), "instrument1"));
}

// with a needle: it lies on the table where the scenario puts it, and its
// swage end is published one radius from its circle's centre
static void test_needle_is_published(void** state) {
  (void)state;
  tx_scenario* s = load("\"needle\":true,\"needle_circle\":0.5,\"needle_x_m\":0.05");
  if (!s) fail_msg("%s", tx_error());
  run(s, 0.3);
  const double* np = latest(s, "needle.pose");
  const double* sw = latest(s, "needle.swage");
  double R = 0.019 / M_PI; // half a circle 19 mm long
  double d = sqrt((sw[0] - np[0]) * (sw[0] - np[0]) + (sw[1] - np[1]) * (sw[1] - np[1]) + (sw[2] - np[2]) * (sw[2] - np[2]));
  print_message("  needle centre (%.4f, %.4f, %.4f) m, swage %.4f mm from it (R = %.4f mm)\n", np[0], np[1], np[2], 1e3 * d, 1e3 * R);
  assert_true(fabs(np[0] - 0.05) < 1e-4 && fabs(np[1] - (-0.05 + 0.0003)) < 1e-4);
  assert_true(fabs(d - R) < 1e-9);
  assert_true(result(s, "instruments.needle_grasps") == 0);
  tx_scenario_free(s);
  assert_null(load("\"needle\":true,\"needle_wire_diameter_m\":0.003,\"needle_length_m\":0.003"));
  assert_non_null(strstr(tx_error(), "needle_wire_diameter_m"));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_follows_the_hand_and_renders_the_weight),
      cmocka_unit_test(test_refuses_what_it_cannot_read),
      cmocka_unit_test(test_needle_is_published),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
