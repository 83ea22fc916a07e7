// The scripted device: built-in motions, waypoint files, and bad files
// rejected with FILE:LINE.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "model/error.h"
#include "controllers/haptics/device.h"
#include "controllers/haptics/device_scripted.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "tests/temp_file.h"

static tx_device_state at(tx_device_handle* h, double t) {
  tx_device_state s;
  assert_true(h->backend->read(h->device, t, &s));
  return s;
}

static void pierce_down_moves_down_through_the_skin(void** state) {
  (void)state;
  tx_device_handle h;
  assert_int_equal(tx_device_open("scripted:pierce-down", 1e-3, &h), 0);
  assert_true(at(&h, 0).pos[1] == 0.010);
  tx_device_state mid = at(&h, 2.5);
  assert_true(fabs(mid.pos[1]) < 1e-12); // through the mid-plane half-way
  assert_true(fabs(mid.vel[1] + 0.005) < 1e-12);
  assert_true(at(&h, 99).pos[1] == -0.010); // holds at the end
  assert_true(at(&h, 99).vel[1] == 0);
  tx_device_info info;
  h.backend->info(h.device, &info);
  assert_true(info.max_force > 0);
  tx_device_close(&h);
}

// insert: 1 mm above the surface, down at 3 mm/s to 4 mm deep, back out at 3 mm/s
static void insert_goes_in_and_out_at_3_mm_per_s(void** state) {
  (void)state;
  tx_device_handle h;
  assert_int_equal(tx_device_open("scripted:insert", 1e-3, &h), 0);
  assert_true(at(&h, 0).pos[1] == 0.001 && at(&h, 0).vel[1] == 0);
  tx_device_state down = at(&h, 1.0), up = at(&h, 2.5);
  assert_true(fabs(down.vel[1] + 0.003) < 1e-12 && fabs(up.vel[1] - 0.003) < 1e-12);
  assert_true(fabs(down.pos[1] - (0.001 - 0.003 * 0.8)) < 1e-12);
  assert_true(fabs(at(&h, 0.2 + 5.0 / 3).pos[1] + 0.004) < 1e-12); // deepest point
  assert_true(down.pos[0] == 0 && down.pos[2] == 0 && down.quat[0] == 1);  // straight, along the axis
  assert_true(at(&h, 10).pos[1] == 0.001 && at(&h, 10).vel[1] == 0);      // out and still
  tx_device_close(&h);
}

static void every_named_motion_opens(void** state) {
  (void)state;
  const char* names[] = {"pierce-down", "pierce-up", "slide-x-over", "slide-x-under", "slide-z-over", "slide-z-under"};
  for (size_t i = 0; i < 6; i++) {
    char spec[64];
    snprintf(spec, sizeof spec, "scripted:%s", names[i]);
    tx_device_handle h;
    assert_int_equal(tx_device_open(spec, 1e-3, &h), 0);
    tx_device_state s = at(&h, 4.0);
    double sign = strstr(names[i], "under") || strstr(names[i], "up") ? -1 : 1;
    if (strstr(names[i], "slide")) assert_true(fabs(s.pos[1] - sign * 0.002) < 1e-12); // sliding in contact
    tx_device_close(&h);
  }
}

// one table of hand motions: pierce-down is the scenarios' (5 mm/s from y = 10 mm
// to -10 mm), the studies' own pierce motions have names of their own, and an
// unknown name is answered with every name of the table
static void one_table_of_hand_motions(void** state) {
  (void)state;
  const tx_hand_motion* m = tx_hand_motion_find("pierce-down");
  assert_non_null(m);
  assert_int_equal(m->count, 4);
  assert_true(m->t_pos[0][2] == 0.010 && m->t_pos[1][0] == 0.5 && m->t_pos[2][0] == 4.5 && m->t_pos[3][2] == -0.010);
  const tx_hand_motion* paper = tx_hand_motion_find("paper-pierce-down");
  assert_non_null(paper);
  assert_true(paper->t_pos[0][2] == 0.030 && paper->t_pos[2][0] == 9.2 && paper->t_pos[3][2] == -0.015);
  const tx_hand_motion* fast = tx_hand_motion_find("accuracy-pierce-down");
  assert_non_null(fast);
  assert_true(fast->t_pos[2][0] == 2.7 && fast->t_pos[3][0] == 3.0 && fast->t_pos[3][2] == -0.015);
  assert_non_null(tx_hand_motion_find("paper-pierce-up"));
  assert_non_null(tx_hand_motion_find("paper-pierce-up-hanging"));
  assert_null(tx_hand_motion_find("pierce-sideways"));

  tx_device_handle h;
  assert_int_equal(tx_device_open("scripted:paper-pierce-down", 1e-3, &h), 0);
  assert_true(fabs(at(&h, 9.2).pos[1] + 0.015) < 1e-12);
  tx_device_close(&h);
  assert_int_not_equal(tx_device_open("scripted:pierce-sideways", 1e-3, &h), 0);
  assert_non_null(strstr(tx_error(), "pierce-down, pierce-up, slide-x-over"));
  assert_non_null(strstr(tx_error(), "insert, paper-pierce-up, paper-pierce-up-hanging, paper-pierce-down, accuracy-pierce-down"));
}

static void waypoint_file_is_interpolated(void** state) {
  (void)state;
  char* path = write_file("t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad\n# a comment\n0,0,0,0,1,0,0,0,0\n"
                          "2,0.02,0,0,0,0,0,1,0.4\n\n3,0.02,0,0.01,-1,0,0,0,0\n");
  char spec[128];
  snprintf(spec, sizeof spec, "scripted:%s", path);
  tx_device_handle h;
  assert_int_equal(tx_device_open(spec, 1e-3, &h), 0);
  tx_device_state s = at(&h, 1.0);
  assert_true(fabs(s.pos[0] - 0.01) < 1e-12);
  assert_true(fabs(s.vel[0] - 0.01) < 1e-12);
  assert_true(fabs(s.grip - 0.2) < 1e-12);
  double q = 0;
  for (int k = 0; k < 4; k++) q += s.quat[k] * s.quat[k];
  assert_true(fabs(q - 1) < 1e-12);
  s = at(&h, 2.5); // from (0,0,0,1) to (-1,0,0,0): the short way stays a unit rotation
  assert_true(isfinite(s.quat[0]) && fabs(s.quat[0] * s.quat[0] + s.quat[3] * s.quat[3] - 1) < 1e-12);
  assert_true(fabs(s.pos[2] - 0.005) < 1e-12);
  tx_device_close(&h);
  unlink(path);
}

static void bad_files_name_the_line(void** state) {
  (void)state;
  const struct {
    const char* text;
    const char* want;
  } bad[] = {
      {"0,0,0,0\n1,0,0\n", ":2: expected 4, 5, 8 or 9 columns"},
      {"0,0,0,0\n0,1,0,0\n", ":2: time must increase"},
      {"0,0,0,0\n1e-300,1,0,0\n", ":2: time must increase by at least 1 us"}, // else an infinite velocity
      {"0,0,0,0\n1,nan,0,0\n", ":2: expected a finite number"},
      {"0,0,0,0\n1;0;0;0\n", ":2: expected ','"},
      {"0,0,0,0\n1,0,0,0,0,0,0,0\n", ":2: the quaternion is zero"},
      {"0,0,0,0\n1,50,0,0\n", ":2: a position beyond 10 m"},
      {"-1,0,0,0\n", ":1: time must not be negative"},
      {"# nothing\n", ": no waypoints"},
      {"t,x,y,z\nx,0,0,0\n", ":2: expected a finite number"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    char* path = write_file(bad[i].text);
    char spec[128];
    snprintf(spec, sizeof spec, "scripted:%s", path);
    tx_device_handle h;
    assert_int_equal(tx_device_open(spec, 1e-3, &h), -1);
    if (!strstr(tx_error(), bad[i].want) || !strstr(tx_error(), path)) fail_msg("case %zu: '%s' lacks '%s'", i, tx_error(), bad[i].want);
    unlink(path);
  }
  tx_device_handle h;
  assert_int_equal(tx_device_open("scripted:/no/such/file.csv", 1e-3, &h), -1);
  assert_non_null(strstr(tx_error(), "/no/such/file.csv"));
  assert_int_equal(tx_device_open("scripted:wiggle", 1e-3, &h), -1);
  assert_non_null(strstr(tx_error(), "pierce-down"));
  assert_int_equal(tx_device_open("phantom", 1e-3, &h), -1);
  assert_non_null(strstr(tx_error(), "unknown kind"));
}

// a relative waypoint file not in the working folder is found on the
// scenario search path, beside its scenario's JSON
static void relative_file_on_the_scenario_path(void** state) {
  (void)state;
  char dir[] = "/tmp/tx-scen-XXXXXX", sub[64], file[96], env[128];
  assert_non_null(mkdtemp(dir));
  snprintf(sub, sizeof sub, "%s/hands", dir);
  assert_int_equal(mkdir(sub, 0700), 0);
  snprintf(file, sizeof file, "%s/right.csv", sub);
  FILE* f = fopen(file, "w");
  assert_non_null(f);
  fputs("0,0.01,0.02,0.03\n", f);
  fclose(f);
  snprintf(env, sizeof env, "/no/such/dir:%s", dir);
  setenv("TACTUS_SCENARIO_PATH", env, 1);
  tx_device_handle h;
  assert_int_equal(tx_device_open("scripted:hands/right.csv", 1e-3, &h), 0);
  tx_device_state st;
  assert_true(h.backend->read(h.device, 0.5, &st));
  assert_true(fabs(st.pos[0] - 0.01) < 1e-12 && fabs(st.pos[2] - 0.03) < 1e-12);
  tx_device_close(&h);
  // not there either: the error names the file as given
  assert_int_equal(tx_device_open("scripted:hands/left.csv", 1e-3, &h), -1);
  assert_non_null(strstr(tx_error(), "hands/left.csv: No such file"));
  unsetenv("TACTUS_SCENARIO_PATH");
  unlink(file);
  rmdir(sub);
  rmdir(dir);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(pierce_down_moves_down_through_the_skin),
      cmocka_unit_test(insert_goes_in_and_out_at_3_mm_per_s),
      cmocka_unit_test(relative_file_on_the_scenario_path),
      cmocka_unit_test(every_named_motion_opens),
      cmocka_unit_test(one_table_of_hand_motions),
      cmocka_unit_test(waypoint_file_is_interpolated),
      cmocka_unit_test(bad_files_name_the_line),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
