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

#include <tactus/components.h>
#include <tactus/events.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "instruments_fixture.h"

static char csv[64];

static tx_scenario* load(const char* extra) { return fixture_scenario(csv, "", extra, ""); }

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

// the holder as the thread sees it (instrument0.capsules), its URDF's
// collision shapes in order but the shanks: the pivot's lump (a cylinder 4
// mm in radius, 6 mm long, about the pivot), then each jaw. A jaw box (31 x
// 3.5 x 2.25 mm, its centre 19.5 mm ahead of the pivot and 1.125 mm off the
// jaws' line) is a capsule along the box, as thick as its thinnest side;
// opened to 0.2 rad each, the two jaws' capsules are 0.4 rad apart, their
// ends where the boxes' ends turn to
static void test_jaws_are_published_as_capsules(void** state) {
  (void)state;
  tx_scenario* s = load("\"instrument0\":\"needle_holder\"");
  if (!s) fail_msg("%s", tx_error());
  run(s, 1.55);
  tx_snapshot cs = latest_snapshot(s, "instrument0.capsules");
  const tx_capsule* c = cs.data;
  const double* ins = latest(s, "instrument0.pose");
  assert_int_equal(cs.rows, 3);
  double lump_a = 0, lump_b = 0;
  for (int j = 0; j < 3; j++) lump_a += (c[0].a[j] - ins[j]) * (c[0].a[j] - ins[j]), lump_b += (c[0].b[j] - ins[j]) * (c[0].b[j] - ins[j]);
  assert_true(fabs(c[0].radius - 0.004) < 1e-12 && fabs(sqrt(lump_a) - 0.003) < 1e-6 && fabs(sqrt(lump_b) - 0.003) < 1e-6);
  double u[2][3];
  for (int k = 0; k < 2; k++) {
    const tx_capsule* jaw = &c[1 + k];
    double len = 0, da = 0, db = 0;
    for (int j = 0; j < 3; j++) {
      u[k][j] = jaw->b[j] - jaw->a[j];
      len += u[k][j] * u[k][j];
      da += (jaw->a[j] - ins[j]) * (jaw->a[j] - ins[j]);
      db += (jaw->b[j] - ins[j]) * (jaw->b[j] - ins[j]);
    }
    len = sqrt(len);
    for (int j = 0; j < 3; j++) u[k][j] /= len;
    print_message("  jaw %d: radius %.4f mm, %.4f mm long, its ends %.4f and %.4f mm from the pivot\n", k,
                  1e3 * jaw->radius, 1e3 * len, 1e3 * sqrt(da), 1e3 * sqrt(db));
    assert_true(fabs(jaw->radius - 0.001125) < 1e-12);
    assert_true(fabs(len - (0.031 - 0.00225)) < 1e-9);
    // the box's axis from 5.125 to 33.875 mm ahead, 1.125 mm off the jaw's line
    assert_true(fabs(sqrt(da) - hypot(0.005125, 0.001125)) < 1e-6);
    assert_true(fabs(sqrt(db) - hypot(0.033875, 0.001125)) < 1e-6);
  }
  double cosine = u[0][0] * u[1][0] + u[0][1] * u[1][1] + u[0][2] * u[1][2];
  print_message("  the jaws %.4f rad apart, the capsules %.4f rad\n", ins[7], acos(cosine));
  assert_true(fabs(acos(cosine) - ins[7]) < 1e-6);
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
  // the puncture and foam keys: each refused naming itself
  static const char* const bad[][2] = {
      {"\"skin\":\"skin\"", "params.skin: a skin to pierce needs the needle"},
      {"\"needle\":true,\"needle_in_jaws\":1", "params.needle_in_jaws: there is no instrument1"},
      {"\"needle\":true,\"needle_in_jaws\":0,\"needle_foam\":true", "params.needle_foam"},
      {"\"needle\":true,\"needle_grasp_rad\":3", "params.needle_grasp_rad: past the needle's tip"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_null(load(bad[i][0]));
    if (!strstr(tx_error(), bad[i][1])) fail_msg("'%s' lacks '%s'", tx_error(), bad[i][1]);
    assert_null(strchr(tx_error(), '\n'));
  }
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
  // needle.segments: the arc as 16 chords from the swage to the tip, each
  // 2 R sin(pi / 32) long (half a circle), end to end, the wire's radius
  const float* seg = latest_snapshot(s, "needle.segments").data;
  const double* tip = latest(s, "needle.tip");
  double chord = 2 * R * sin(M_PI / 32);
  for (int k = 0; k < 16; k++) {
    const float* g = seg + 7 * k;
    double l = sqrt((g[3] - g[0]) * (g[3] - g[0]) + (g[4] - g[1]) * (g[4] - g[1]) + (g[5] - g[2]) * (g[5] - g[2]));
    assert_true(fabs(l - chord) < 1e-6 && fabs(g[6] - 0.0003) < 1e-9);
    if (k) assert_true(g[0] == seg[7 * k - 4] && g[1] == seg[7 * k - 3] && g[2] == seg[7 * k - 2]);
  }
  for (int c = 0; c < 3; c++) assert_true(fabs(seg[c] - sw[c]) < 1e-6 && fabs(seg[7 * 15 + 3 + c] - tip[c]) < 1e-6);
  assert_true(latest(s, "instrument0.held")[0] == 0);
  assert_true(result(s, "instruments.needle_grasps") == 0);
  tx_scenario_free(s);
  assert_null(load("\"needle\":true,\"needle_wire_diameter_m\":0.003,\"needle_length_m\":0.003"));
  assert_non_null(strstr(tx_error(), "needle_wire_diameter_m"));
}

// a test class that keeps every event of instruments.events
#define EVENTS_MAX 64
typedef struct listener {
  tx_port in;
  tx_event got[EVENTS_MAX];
  int n;
} listener;
static listener the_listener;
static int listen_configure(tx_setup* s, void** self) {
  *self = &the_listener;
  the_listener.in = tx_setup_listen(s, "instruments.events");
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
    .type = "test.listener", .summary = "keeps instruments.events", .configure = listen_configure, .step = listen_step};

// a test class that writes a thread of 9 nodes along z at x = 2 cm, y = 0,
// 5 mm apart from z = -2 cm
static tx_port thread_out;
static int thread_configure(tx_setup* s, void** self) {
  *self = &thread_out;
  thread_out = tx_setup_write(s, &TX_COMPONENT_OF("thread.nodes", tx_thread_node, 9));
  return 0;
}
static void thread_step(tx_ctx* c, void* self) {
  tx_thread_node* n = tx_write(c, *(tx_port*)self);
  for (int i = 0; i < 9; i++) n[i] = (tx_thread_node){.x = {0.02, 0, -0.02 + 0.005 * i}, .radius = 0.00025};
}
static const tx_controller_class thread_class = {
    .type = "test.thread", .summary = "a still thread", .configure = thread_configure, .step = thread_step};

// a test class that writes a still skin: 9 x 9 particles 2.5 mm apart in
// the y = 0 plane, x from 1 to 3 cm, z from -1 to 1 cm (row 9 i + j: x
// index i, z index j), two triangles, no contact and nothing torn
static tx_port skin_ports[4];
static int skin_configure(tx_setup* s, void** self) {
  *self = skin_ports;
  skin_ports[0] = tx_setup_write(s, &TX_COMPONENT_OF("skin.x", tx_vertex, 81));
  skin_ports[1] = tx_setup_write(s, &TX_COMPONENT_OF("skin.tri", tx_triangle, 2));
  skin_ports[2] = tx_setup_write(s, &TX_COMPONENT_OF("skin.contact", tx_skin_contact, 1));
  skin_ports[3] = tx_setup_write(s, &TX_COMPONENT_OF("skin.torn", tx_torn, 1));
  return 0;
}
static void skin_step(tx_ctx* c, void* self) {
  tx_port* p = self;
  tx_vertex* x = tx_write(c, p[0]);
  for (int i = 0; i < 9; i++)
    for (int j = 0; j < 9; j++) x[9 * i + j] = (tx_vertex){.x = {0.01f + 0.0025f * (float)i, 0, -0.01f + 0.0025f * (float)j}};
  tx_triangle* t = tx_write(c, p[1]);
  t[0] = (tx_triangle){.v = {0, 1, 9}}, t[1] = (tx_triangle){.v = {1, 10, 9}};
  memset(tx_write(c, p[2]), 0, sizeof(tx_skin_contact));
  memset(tx_write(c, p[3]), 0, sizeof(tx_torn));
}
static const tx_controller_class skin_class = {
    .type = "test.skin", .summary = "a still skin", .configure = skin_configure, .step = skin_step};

static void register_tests(void) {
  if (!tx_find_controller(listener_class.type)) assert_int_equal(tx_register_controller(&listener_class), 0);
  if (!tx_find_controller(thread_class.type)) assert_int_equal(tx_register_controller(&thread_class), 0);
  if (!tx_find_controller(skin_class.type)) assert_int_equal(tx_register_controller(&skin_class), 0);
}

static void write_csv(const char* path, const char* text) {
  FILE* f = fopen(path, "w");
  assert_non_null(f);
  fputs(text, f);
  fclose(f);
}

// a hand turned 180 degrees about y from the start: the holder starts turned
// as the hand is, where it is, and stays there (built square to the world,
// the coupling swung it round through the scene in the first 0.2 s, its pivot
// centimetres off the hand)
static void test_starts_turned_as_the_hand(void** state) {
  (void)state;
  instruments_fixture f;
  fixture_path(&f, "turned");
  fixture_load(&f, "t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad\n0,0,0.05,0,0,0,1,0,0\n1,0,0.05,0,0,0,1,0,0\n", "",
               "\"instrument0\":\"needle_holder\",\"gravity_m_s2\":0", "");
  double worst = 0, least_dot = 1;
  for (int k = 1; k <= 20; k++) {
    run(f.s, 0.01 * k);
    const double* ins = latest(f.s, "instrument0.pose");
    double d = sqrt(ins[0] * ins[0] + (ins[1] - 0.05) * (ins[1] - 0.05) + ins[2] * ins[2]);
    worst = fmax(worst, d);
    least_dot = fmin(least_dot, fabs(ins[5])); // |q . (0, 0, 1, 0)|
  }
  print_message("  first 0.2 s: the pivot at most %.4f mm from the hand, |q . q_hand| at least %.6f\n", 1e3 * worst,
                least_dot);
  assert_true(worst < 1e-4);
  assert_true(least_dot > 0.9999);
  fixture_free(&f);
}

// the Metzenbaum scissors open over the thread, 2 cm ahead of the pivot, and
// close: one cut, of segment 4 (z from 0 to 5 mm), where the blades crossed
// it; opened and closed again away from the thread: no cut
static void test_scissors_cut_the_thread(void** state) {
  (void)state;
  register_tests();
  instruments_fixture f;
  fixture_path(&f, "cut");
  // pivot at (0, 0, 1.2 mm), blades along x; open 0.5 s, close, then move 3 cm up, open, close
  fixture_load(&f,
               "t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad\n"
                  "0,0,0,0.0012,1,0,0,0,0\n0.3,0,0,0.0012,1,0,0,0,0.6\n0.6,0,0,0.0012,1,0,0,0,0.6\n"
                  "0.9,0,0,0.0012,1,0,0,0,0\n1.2,0,0.03,0.0012,1,0,0,0,0\n1.5,0,0.03,0.0012,1,0,0,0,0.6\n"
                  "1.8,0,0.03,0.0012,1,0,0,0,0\n",
               "{\"name\":\"thread\",\"type\":\"test.thread\",\"rate_hz\":100},",
               "\"instrument0\":\"metzenbaum_scissors\",\"thread\":\"thread\",\"gravity_m_s2\":0",
               ",{\"name\":\"listener\",\"type\":\"test.listener\",\"rate_hz\":1000}");
  tx_scenario* s = f.s;
  run(s, 2.0);
  print_message("  %d events; cuts %g\n", the_listener.n, result(s, "instruments.thread_cuts"));
  assert_int_equal(the_listener.n, 1);
  const tx_event* e = &the_listener.got[0];
  print_message("  cut segment %u at (%.4f, %.4f, %.4f) m\n", e->source, e->cut.point[0], e->cut.point[1], e->cut.point[2]);
  assert_int_equal(e->kind, TX_EVENT_CUT);
  assert_int_equal(e->source, 4);
  assert_true(fabs(e->cut.point[0] - 0.02) < 1e-9 && fabs(e->cut.point[2] - 0.0012) < 5e-4);
  assert_true(result(s, "instruments.thread_cuts") == 1);
  fixture_free(&f);
}

// the thumb forceps open over the thread and close on it: a grasp (source =
// the forceps, its point on the thread between the jaws); they open: a
// release; no cut
static void test_forceps_grasp_the_thread(void** state) {
  (void)state;
  register_tests();
  instruments_fixture f;
  fixture_path(&f, "tgrasp");
  fixture_load(&f,
               "t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad\n"
                  "0,0,0,0.0012,1,0,0,0,0\n0.3,0,0,0.0012,1,0,0,0,0.14\n0.6,0,0,0.0012,1,0,0,0,0.14\n"
                  "0.9,0,0,0.0012,1,0,0,0,0\n1.2,0,0,0.0012,1,0,0,0,0\n1.5,0,0,0.0012,1,0,0,0,0.14\n",
               "{\"name\":\"thread\",\"type\":\"test.thread\",\"rate_hz\":100},",
               "\"instrument0\":\"thumb_forceps\",\"thread\":\"thread\",\"gravity_m_s2\":0",
               ",{\"name\":\"listener\",\"type\":\"test.listener\",\"rate_hz\":1000}");
  tx_scenario* s = f.s;
  run(s, 1.8);
  print_message("  %d events: grasps %g, cuts %g\n", the_listener.n, result(s, "instruments.thread_grasps"),
                result(s, "instruments.thread_cuts"));
  assert_int_equal(the_listener.n, 2);
  const tx_event* g = &the_listener.got[0];
  print_message("  grasp by %u at (%.4f, %.4f, %.4f) m, jaws %.4f rad; then kind %u\n", g->source, g->grasp.point[0],
                g->grasp.point[1], g->grasp.point[2], g->grasp.jaw, the_listener.got[1].kind);
  assert_int_equal(g->kind, TX_EVENT_GRASP);
  assert_int_equal(g->source, 0);
  assert_true(fabs(g->grasp.point[0] - 0.02) < 1e-9 && fabs(g->grasp.point[2] - 0.0012) < 5e-4);
  assert_int_equal(the_listener.got[1].kind, TX_EVENT_RELEASE);
  assert_int_equal(the_listener.got[1].source, 0);
  assert_true(result(s, "instruments.thread_grasps") == 1 && result(s, "instruments.thread_cuts") == 0);
  fixture_free(&f);
}

// the thumb forceps, jaws along x from a pivot at (-10, 1, 1.2) cm (their
// 118 mm blades reach x = 3 cm), open 1 mm over the skin and close: a grasp
// (source = the hand), its point a particle of skin.x in the row z = 0
// (1.56 mm from the jaws' line, within their 2.9 mm half width; the row at
// z = 2.5 mm is 1.64 mm off), then they open: a release; lifted 3 cm, opened
// and closed: nothing between the jaws, no grasp. Counted by skin_grasps.
static void test_forceps_grasp_the_skin(void** state) {
  (void)state;
  register_tests();
  instruments_fixture f;
  fixture_path(&f, "sgrasp");
  fixture_load(&f,
               "t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad\n"
                  "0,-0.1,0.001,0.0012,1,0,0,0,0\n0.3,-0.1,0.001,0.0012,1,0,0,0,0.14\n0.6,-0.1,0.001,0.0012,1,0,0,0,0.14\n"
                  "0.9,-0.1,0.001,0.0012,1,0,0,0,0\n1.2,-0.1,0.001,0.0012,1,0,0,0,0\n1.5,-0.1,0.001,0.0012,1,0,0,0,0.14\n"
                  "1.8,-0.1,0.031,0.0012,1,0,0,0,0.14\n2.1,-0.1,0.031,0.0012,1,0,0,0,0\n",
               "{\"name\":\"skin\",\"type\":\"test.skin\",\"rate_hz\":60},",
               "\"instrument0\":\"thumb_forceps\",\"skin\":\"skin\",\"needle\":true,\"gravity_m_s2\":0",
               ",{\"name\":\"listener\",\"type\":\"test.listener\",\"rate_hz\":1000}");
  tx_scenario* s = f.s;
  run(s, 2.4);
  print_message("  %d events: skin grasps %g\n", the_listener.n, result(s, "instruments.skin_grasps"));
  assert_int_equal(the_listener.n, 2);
  const tx_event* g = &the_listener.got[0];
  print_message("  grasp by %u at (%.4f, %.4f, %.4f) m, jaws %.4f rad; then kind %u\n", g->source, g->grasp.point[0],
                g->grasp.point[1], g->grasp.point[2], g->grasp.jaw, the_listener.got[1].kind);
  assert_int_equal(g->kind, TX_EVENT_GRASP);
  assert_int_equal(g->source, 0);
  // a particle: on the grid, in the skin's plane, in the row z = 0
  double i = (g->grasp.point[0] - 0.01) / 0.0025;
  assert_true(fabs(i - round(i)) < 1e-4 && i > -0.5 && i < 8.5);
  assert_true(g->grasp.point[1] == 0 && fabs(g->grasp.point[2]) < 1e-9);
  assert_int_equal(the_listener.got[1].kind, TX_EVENT_RELEASE);
  assert_int_equal(the_listener.got[1].source, 0);
  assert_true(result(s, "instruments.skin_grasps") == 1);
  // the lowest the forceps came above the skin: their jaw boxes, 5.75 mm
  // across in y, about the pivot's line 1 mm above the sheet: -1.875 mm
  print_message("  lowest above the skin: %.4f mm\n", 1e3 * result(s, "instruments.skin_clearance_m"));
  assert_true(fabs(result(s, "instruments.skin_clearance_m") + 0.001875) < 1e-4);
  // one hand: its own lowest is the whole's
  assert_true(result(s, "instruments.hand0_skin_clearance_m") == result(s, "instruments.skin_clearance_m"));
  fixture_free(&f);
}

// The needle pierces the skin: the needle holder holds a 3/8-circle needle
// 30 mm long (R = 12.7 mm) from the start, its arc vertical and curving
// down; the hand lowers it from 7 cm until the circle's centre is 5.5 mm above the
// skin, then turns it about that centre, so that its tip goes down through
// the skin, along under it and up through it again. The skin's HIP is the
// needle's tip (pose needle.tip). Two punctures come out in order: an entry
// (+1) then an exit (-1), each with a live skin triangle and barycentric
// coordinates summing to 1; and the tip felt the skin before each.
static void write_puncture_path(const char* path, double* seconds) {
  FILE* f = fopen(path, "w");
  assert_non_null(f);
  fprintf(f, "t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad\n");
  double R = 0.03 / (0.75 * M_PI), d = 0.03, phi = 0.2;
  double th0 = 0.75 * M_PI - phi + 5 * M_PI / 180; // the tip 5 degrees above the centre's horizontal
  double turn = 205 * M_PI / 180, t = 0;
  // the root starts unturned: it turns to the hand's orientation 7 cm above the skin, out of its reach
  for (int i = 0; i <= 500; i++, t += 0.01) {
    double th = th0, cy = 0.07;
    if (t > 0.5) cy = 0.07 - (0.07 - 0.0055) * fmin(1, (t - 0.5) / 1.0);
    if (t > 1.5) th = th0 - turn * fmin(1, (t - 1.5) / 3.0);
    // the pivot: the centre plus the turned (R - d, 0, 0); the root: turned about z, flipped about x
    double x = cos(th) * (R - d), y = cy + sin(th) * (R - d);
    fprintf(f, "%.4f,%.9f,%.9f,0,0,%.9f,%.9f,0,0\n", t, x, y, cos(th / 2), sin(th / 2));
  }
  fclose(f);
  *seconds = t;
}

static void test_needle_punctures_the_skin(void** state) {
  (void)state;
  if (!tx_find_controller("physics.skin")) skip(); // built without Bullet
  register_tests();
  instruments_fixture f;
  fixture_path(&f, "pierce");
  double seconds;
  write_puncture_path(f.path, &seconds);
  fixture_load(&f, NULL,
               "",
               "\"instrument0\":\"needle_holder\",\"needle\":true,\"needle_in_jaws\":0,\"needle_length_m\":0.03,"
               "\"table_height_m\":-1,\"skin\":\"skin\"",
               // the skin as scenario instruments has it (its force read at the held particles)
               ",{\"name\":\"skin\",\"type\":\"physics.skin\",\"rate_hz\":60,"
               "\"params\":{\"pose\":\"needle.tip\",\"force_reading\":\"held\"}},"
                   "{\"name\":\"listener\",\"type\":\"test.listener\",\"rate_hz\":1000}");
  tx_scenario* s = f.s;
  run(s, seconds + 0.2);
  const tx_puncture* rows = latest_snapshot(s, "needle.punctures").data;
  int ntri = (int)latest_snapshot(s, "skin.tri").rows;
  const int32_t* tri = latest_snapshot(s, "skin.tri").data;
  const float* sx = latest_snapshot(s, "skin.x").data;
  const tx_pose* needle = latest_snapshot(s, "needle.pose").data;
  int np = 0;
  for (int i = 0; i < the_listener.n; i++) {
    const tx_event* e = &the_listener.got[i];
    if (e->kind != TX_EVENT_PUNCTURE) continue;
    const tx_puncture* r = &rows[np];
    print_message("  puncture %d: triangle %u (particles %g %g %g), side %+g, at (%.2f, %.2f, %.2f) mm, %.3f N, %.2f mm deep; bary (%.3f, %.3f, %.3f)\n",
                  np, e->source, r->v[0], r->v[1], r->v[2], r->side, 1e3 * e->puncture.point[0], 1e3 * e->puncture.point[1],
                  1e3 * e->puncture.point[2], e->puncture.force, 1e3 * e->puncture.depth, r->bary[0], r->bary[1], r->bary[2]);
    assert_true(e->source < 2 * 41 * 41); // a row of the 42 x 42 patch's skin.tri at that publish
    for (int k = 0; k < 3; k++) { // the triangle by its three particles: distinct rows of skin.x
      assert_true(r->v[k] >= 0 && r->v[k] < 42 * 42 && r->v[k] == floor(r->v[k]));
      assert_true(r->v[k] != r->v[(k + 1) % 3]);
    }
    assert_true(fabs(r->bary[0] + r->bary[1] + r->bary[2] - 1) < 1e-9);
    // the hole: the point on the needle's arc, where it crosses the skin, on a live triangle
    double p[3] = {0}, R = 0.03 / (0.75 * M_PI), d[3], n[3], dn = 0, dd = 0;
    for (int v = 0; v < 3; v++)
      for (int k = 0; k < 3; k++) p[k] += r->bary[v] * sx[3 * (int)r->v[v] + k];
    for (int k = 0; k < 3; k++) d[k] = p[k] - needle->pos[k];
    const double* q = needle->quat; // the needle frame's z: its circle's axis
    n[0] = 2 * (q[1] * q[3] + q[0] * q[2]), n[1] = 2 * (q[2] * q[3] - q[0] * q[1]), n[2] = 1 - 2 * (q[1] * q[1] + q[2] * q[2]);
    for (int k = 0; k < 3; k++) dn += d[k] * n[k];
    for (int k = 0; k < 3; k++) dd += (d[k] - dn * n[k]) * (d[k] - dn * n[k]);
    double off = sqrt((sqrt(dd) - R) * (sqrt(dd) - R) + dn * dn);
    bool live = false;
    for (int t = 0; t < ntri && !live; t++)
      for (int k = 0; k < 3; k++)
        live = live || (tri[3 * t] == r->v[k] && tri[3 * t + 1] == r->v[(k + 1) % 3] && tri[3 * t + 2] == r->v[(k + 2) % 3]);
    print_message("  its point (%.2f, %.2f, %.2f) mm, %.3f mm off the needle's circle, on a live triangle: %d\n", 1e3 * p[0],
                  1e3 * p[1], 1e3 * p[2], 1e3 * off, live);
    assert_true(off < 2.5e-3); // the needle moved on after it was last seen crossing there
    assert_true(live);
    assert_true(fabs(p[1]) < 0.006); // at the skin, not a flap carried under it
    assert_true(e->puncture.force > 0.01); // the tip felt the skin before it tore
    np++;
  }
  print_message("  %d punctures, skin torn %g links, %d triangles live\n", np, latest(s, "skin.contact")[12], ntri);
  assert_int_equal(np, 2);
  assert_true(rows[0].side == 1 && rows[1].side == -1);
  assert_true(rows[2].v[0] == -1);
  assert_true(result(s, "instruments.needle_punctures") == 2);
  fixture_free(&f);
}

// hand0 = "thumb_forceps metzenbaum_scissors": the button pressed at 0.3 s
// and held to 0.8 s switches once, to the scissors, taken at the device's
// pose (weightless and still, the coupling force stays under 0.05 N all run;
// the parked scissors, 1 m up, would pull with the 3.3 N clamp if taken from
// there); they open over the thread and cut it; a second press at 2.1 s puts
// them down and takes the forceps back
static void test_button_switches_instruments(void** state) {
  (void)state;
  register_tests();
  instruments_fixture f;
  fixture_path(&f, "switch");
  fixture_load(&f,
               "t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad,buttons\n"
                  "0,0,0,0.0012,1,0,0,0,0,0\n0.3,0,0,0.0012,1,0,0,0,0,1\n0.8,0,0,0.0012,1,0,0,0,0,0\n"
                  "1.0,0,0,0.0012,1,0,0,0,0,0\n1.3,0,0,0.0012,1,0,0,0,0.6,0\n1.6,0,0,0.0012,1,0,0,0,0.6,0\n"
                  "1.9,0,0,0.0012,1,0,0,0,0,0\n2.1,0,0,0.0012,1,0,0,0,0,1\n2.2,0,0,0.0012,1,0,0,0,0,0\n",
               "{\"name\":\"thread\",\"type\":\"test.thread\",\"rate_hz\":100},",
               "\"hand0\":\"thumb_forceps metzenbaum_scissors\",\"thread\":\"thread\",\"gravity_m_s2\":0",
               ",{\"name\":\"listener\",\"type\":\"test.listener\",\"rate_hz\":1000}");
  tx_scenario* s = f.s;
  run(s, 2.5);
  print_message("  %d events; switches %g, cuts %g, coupling force at most %.3g N\n", the_listener.n,
                result(s, "instruments.switches"), result(s, "instruments.thread_cuts"),
                result(s, "instruments.coupling_force_max_n"));
  assert_int_equal(the_listener.n, 3);
  assert_int_equal(the_listener.got[0].kind, TX_EVENT_USER + 1); // TX_EVENT_INSTRUMENT_SWITCH
  assert_int_equal(the_listener.got[0].source, 0);
  assert_true(the_listener.got[0].value[0] == 1 && the_listener.got[0].value[1] == 0);
  assert_int_equal(the_listener.got[1].kind, TX_EVENT_CUT); // the scissors in hand
  assert_int_equal(the_listener.got[1].source, 4);
  assert_int_equal(the_listener.got[2].kind, TX_EVENT_USER + 1);
  assert_true(the_listener.got[2].value[0] == 0 && the_listener.got[2].value[1] == 1);
  assert_true(result(s, "instruments.switches") == 2);
  assert_true(result(s, "instruments.coupling_force_max_n") < 0.05);
  const double* dev = latest(s, "device0.pose");
  const double* ins = latest(s, "instrument0.pose");
  assert_true(fabs(ins[0] - dev[0]) < 1e-4 && fabs(ins[1] - dev[1]) < 1e-4 && fabs(ins[2] - dev[2]) < 1e-4);
  fixture_free(&f);
  // a list too long, a name it cannot read: refused naming hand0
  static const char* const bad[][2] = {
      {"\"hand0\":\"thumb_forceps lap_grasper lap_scissors\"", "params.hand0: more than 2 instruments"},
      {"\"hand0\":\"thumb_forceps no_such\"", "params.hand0: "},
      {"\"instrument0\":\"\",\"hand1\":\"lap_grasper\"", "params.hand1: device1 has instruments but device0"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    assert_null(load(bad[i][0]));
    if (!strstr(tx_error(), bad[i][1])) fail_msg("'%s' lacks '%s'", tx_error(), bad[i][1]);
  }
  // a scripted buttons column that is not a bit field: refused with its row
  write_csv(csv, "0,0,0,0,1,0,0,0,0,0.5\n");
  assert_null(load("\"hand0\":\"thumb_forceps metzenbaum_scissors\""));
  print_message("  %s\n", tx_error());
  if (!strstr(tx_error(), ":1: buttons: an integer")) fail_msg("'%s'", tx_error());
  write_csv(csv, "t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad\n"
                 "0,0,0,0,1,0,0,0,0\n0.5,0,0,0,1,0,0,0,0\n1.0,0.02,0,0,1,0,0,0,0.4\n"); // as setup() wrote it
}

// hand0_holds, tuned during the run as the trainer's window does (from the
// run's progress callback): the hand puts the forceps down and takes the
// scissors at its next step (one switch event, instrument0.held 1); a tune
// to what it holds already changes nothing, one for hand1, which holds
// nothing, is refused with a warning, and back to 0 takes the forceps again.
// Given in the file, the hand starts with the scissors; a hand of one
// instrument cannot start with a second.
typedef struct tune_script {
  tx_scenario* s;
  int ins, done;
  double held_mid;
} tune_script;

static bool tune_on_time(double t, void* user) {
  tune_script* k = user;
  if (k->done == 0 && t >= 0.3) {
    assert_int_equal(tx_system_tune(k->s->system, k->ins, "hand0_holds", 1), 0);
    k->done++;
  } else if (k->done == 1 && t >= 0.6) {
    k->held_mid = latest(k->s, "instrument0.held")[0];
    assert_int_equal(tx_system_tune(k->s->system, k->ins, "hand0_holds", 1), 0);  // held already
    assert_int_equal(tx_system_tune(k->s->system, k->ins, "hand1_holds", 1), 0);  // no such hand: refused as it steps
    assert_int_equal(tx_system_tune(k->s->system, k->ins, "hand0_holds", 2), -1); // out of the table's range
    k->done++;
  } else if (k->done == 2 && t >= 0.9) {
    assert_int_equal(tx_system_tune(k->s->system, k->ins, "hand0_holds", 0), 0);
    k->done++;
  }
  return true;
}

static void test_tune_switches_instruments(void** state) {
  (void)state;
  register_tests();
  instruments_fixture f;
  fixture_path(&f, "tune");
  fixture_load(&f, "t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad\n0,0,0,0.0012,1,0,0,0,0\n",
               "{\"name\":\"thread\",\"type\":\"test.thread\",\"rate_hz\":100},",
               "\"hand0\":\"thumb_forceps metzenbaum_scissors\",\"thread\":\"thread\",\"gravity_m_s2\":0",
               ",{\"name\":\"listener\",\"type\":\"test.listener\",\"rate_hz\":1000}");
  tx_scenario* s = f.s;
  tune_script k = {s, -1, 0, -1};
  for (int i = 0; i < tx_system_count(s->system); i++)
    if (strcmp(tx_system_name(s->system, i), "instruments") == 0) k.ins = i;
  tx_run_options o = {.duration_s = 1.2, .lockstep = true, .progress = tune_on_time, .progress_user = &k};
  tx_run_result r;
  assert_int_equal(tx_system_run(s->system, &o, &r), 0);
  print_message("  %d events; switches %g, held at 0.6 s: %g\n", the_listener.n, result(s, "instruments.switches"), k.held_mid);
  assert_int_equal(k.done, 3);
  assert_true(k.held_mid == 1);
  assert_int_equal(the_listener.n, 2);
  assert_int_equal(the_listener.got[0].kind, TX_EVENT_USER + 1); // TX_EVENT_INSTRUMENT_SWITCH
  assert_true(the_listener.got[0].value[0] == 1 && the_listener.got[0].value[1] == 0);
  assert_true(the_listener.got[1].value[0] == 0 && the_listener.got[1].value[1] == 1);
  assert_true(latest(s, "instrument0.held")[0] == 0);
  assert_true(result(s, "instruments.switches") == 2);
  assert_int_equal(warnings(s, "instruments.switch_refused"), 1);
  const double* dev = latest(s, "device0.pose");
  const double* pose = latest(s, "instrument0.pose");
  assert_true(fabs(pose[0] - dev[0]) < 1e-4 && fabs(pose[1] - dev[1]) < 1e-4 && fabs(pose[2] - dev[2]) < 1e-4);
  fixture_free(&f);
  // given in the file: the second from the start
  fixture_path(&f, "tune-start");
  fixture_load(&f, "t_s,x_m,y_m,z_m,qw,qx,qy,qz,grip_rad\n0,0,0,0.0012,1,0,0,0,0\n", "",
               "\"hand0\":\"thumb_forceps metzenbaum_scissors\",\"hand0_holds\":1,\"gravity_m_s2\":0", "");
  run(f.s, 0.1);
  assert_true(latest(f.s, "instrument0.held")[0] == 1);
  assert_true(result(f.s, "instruments.switches") == 0);
  fixture_free(&f);
  assert_refused(load("\"instrument0\":\"needle_holder\",\"hand0_holds\":1"), "params.hand0_holds: device0 has 1 instrument: give 0");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_follows_the_hand_and_renders_the_weight),
      cmocka_unit_test(test_jaws_are_published_as_capsules),
      cmocka_unit_test(test_refuses_what_it_cannot_read),
      cmocka_unit_test(test_needle_is_published),
      cmocka_unit_test(test_starts_turned_as_the_hand),
      cmocka_unit_test(test_scissors_cut_the_thread),
      cmocka_unit_test(test_forceps_grasp_the_thread),
      cmocka_unit_test(test_forceps_grasp_the_skin),
      cmocka_unit_test(test_needle_punctures_the_skin),
      cmocka_unit_test(test_button_switches_instruments),
      cmocka_unit_test(test_tune_switches_instruments),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
