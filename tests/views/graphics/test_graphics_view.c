// The graphics view end to end: a scenario with a "view", run in lockstep
// with --view png, writes every Nth frame and the last, in each stereo layout,
// and the tool it draws moves with the device.
#include "scenarios/loader.h"
#include "views/graphics/png_writer.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <cmocka.h>

static const char* const wall_scene =
    "{\"name\": \"wall-view\", \"controllers\": ["
    "{\"name\": \"wall\", \"type\": \"collision.wall\", \"rate_hz\": 60, \"params\": {\"stiffness\": 300}},"
    "{\"name\": \"haptics\", \"type\": \"haptics\", \"rate_hz\": 1000,"
    " \"params\": {\"device\": \"scripted:pierce-down\", \"force_model\": \"tool0.force_model\", \"record\": false}}]%s}";

static const char* const view_json =
    ", \"view\": {\"width\": 160, \"height\": 120, \"frame_every\": 8,"
    " \"camera\": {\"eye\": [0, 0, 0.08], \"target\": [0, 0, 0]}, \"background\": [0, 0, 0],"
    " \"draw\": [{\"tool\": \"device0\", \"radius_m\": 0.003, \"colour\": [1, 0, 0]}]}";

static double result(tx_system* s, const char* key) {
  for (int k = 0; k < tx_system_results(s); k++)
    if (strcmp(tx_system_result_key(s, k), key) == 0) return tx_system_result(s, k);
  return NAN;
}

static tx_scenario* load(const char* view, const char* stereo, bool with_view) {
  char text[2048];
  snprintf(text, sizeof text, wall_scene, with_view ? view_json : "");
  tx_load_options o = {.view = view, .stereo = stereo, .view_wait = true};
  return tx_scenario_load_text("wall-view", text, strlen(text), &o);
}

static void run(tx_scenario* sc, const char* dir, double seconds) {
  tx_run_options o = {.duration_s = seconds, .lockstep = true, .out_dir = dir};
  tx_run_result r;
  if (tx_system_run(sc->system, &o, &r)) fail_msg("%s", tx_error());
}

// the height (row from the top) of the red tool's lowest pixel in a frame
static int tool_bottom(const char* path, int* w, int* h) {
  uint8_t* img;
  if (tx_png_read(path, &img, w, h)) fail_msg("%s", tx_error());
  int bottom = -1;
  for (int y = 0; y < *h; y++)
    for (int x = 0; x < *w; x++) {
      const uint8_t* p = img + 4 * ((size_t)y * *w + x);
      if (p[0] > 60 && p[1] < 40) bottom = y;
    }
  free(img);
  return bottom;
}

static void png_frames_every_nth_and_last(void** state) {
  (void)state;
  char dir[] = "/tmp/tx_view_XXXXXX", path[4200];
  assert_non_null(mkdtemp(dir));
  tx_scenario* sc = load("png", "mono", true);
  if (!sc) fail_msg("%s", tx_error());
  run(sc, dir, 3.0); // 90 frames at 30 Hz: 0, 8, ..., 88, and the last, 89
  assert_true(result(sc->system, "view.frames") == 90);
  assert_true(result(sc->system, "view.frames_written") == 13);
  assert_true(result(sc->system, "view.frames_dropped") == 0); // lockstep waits for every frame
  assert_true(result(sc->system, "view.first_frame_ms") > 0);   // the warm-up, before the run: not one of the 90
  int w, h, first, mid, last;
  snprintf(path, sizeof path, "%s/frames/frame_000000.png", dir);
  first = tool_bottom(path, &w, &h);
  assert_int_equal(w, 160);
  assert_int_equal(h, 120);
  snprintf(path, sizeof path, "%s/frames/frame_000008.png", dir);
  mid = tool_bottom(path, &w, &h);
  snprintf(path, sizeof path, "%s/frames/frame_000089.png", dir);
  last = tool_bottom(path, &w, &h);
  snprintf(path, sizeof path, "%s/frames/frame_000009.png", dir);
  assert_int_not_equal(access(path, F_OK), 0); // not every frame
  snprintf(path, sizeof path, "%s/frames/contact_sheet.png", dir);
  assert_int_equal(access(path, R_OK), 0);
  // the tool starts 1 cm above the wall, waits half a second, then goes down: it moves down the image
  assert_true(first > 0 && first == mid);
  assert_true(last > first + 10);
  tx_scenario_free(sc);
  char cmd[4300];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  assert_int_equal(system(cmd), 0);
}

static uint64_t warning(tx_system* s, const char* key) {
  for (int w = 0; w < tx_system_warnings(s); w++)
    if (strcmp(tx_system_warning_key(s, w), key) == 0) return tx_system_warning_count(s, w);
  return UINT64_MAX;
}

// a frame that cannot be written is counted and the run goes on; the contact
// sheet, written at the end, stops the run naming the file (here each file's
// temporary name is taken by a folder)
static void files_that_cannot_be_written(void** state) {
  (void)state;
  char dir[] = "/tmp/tx_view_XXXXXX", path[4200];
  assert_non_null(mkdtemp(dir));
  const char* taken[] = {"frames", "frames/frame_000000.png.tmp", "frames/contact_sheet.png.tmp"};
  for (size_t i = 0; i < sizeof taken / sizeof taken[0]; i++) {
    snprintf(path, sizeof path, "%s/%s", dir, taken[i]);
    assert_int_equal(mkdir(path, 0755), 0);
  }
  tx_scenario* sc = load("png", "mono", true);
  if (!sc) fail_msg("%s", tx_error());
  tx_run_options o = {.duration_s = 1.0, .lockstep = true, .out_dir = dir};
  tx_run_result r;
  if (tx_system_run(sc->system, &o, &r)) fail_msg("%s", tx_error());
  print_message("  %s at t = %.3f s\n", r.halt_reason, r.halt_t_s);
  assert_int_equal(warning(sc->system, "view.frame_not_written"), 1);
  assert_true(r.halted);
  snprintf(path, sizeof path, "view: %s/frames/contact_sheet.png: ", dir);
  if (strncmp(r.halt_reason, path, strlen(path)) != 0) fail_msg("'%s' does not start with '%s'", r.halt_reason, path);
  snprintf(path, sizeof path, "%s/frames/frame_000008.png", dir);
  assert_int_equal(access(path, R_OK), 0); // the frames after the one lost
  tx_scenario_free(sc);
  char cmd[4300];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  assert_int_equal(system(cmd), 0);
}

static void stereo_files_and_sizes(void** state) {
  (void)state;
  const struct { const char* mode; const char* file; int w, h; } cases[] = {
      {"sbs", "frame_000000.png", 320, 120},     {"tb", "frame_000000.png", 160, 240},
      {"anaglyph", "frame_000000.png", 160, 120}, {"lr", "frame_000000_left.png", 160, 120},
      {"lr", "frame_000029_right.png", 160, 120}};
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    char dir[] = "/tmp/tx_view_XXXXXX", path[4200];
    assert_non_null(mkdtemp(dir));
    tx_scenario* sc = load("png", cases[i].mode, true);
    if (!sc) fail_msg("%s", tx_error());
    run(sc, dir, 1.0);
    snprintf(path, sizeof path, "%s/frames/%s", dir, cases[i].file);
    uint8_t* img;
    int w, h;
    if (tx_png_read(path, &img, &w, &h)) fail_msg("%s: %s", cases[i].mode, tx_error());
    assert_int_equal(w, cases[i].w);
    assert_int_equal(h, cases[i].h);
    free(img);
    tx_scenario_free(sc);
    char cmd[4300];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    assert_int_equal(system(cmd), 0);
  }
}

// no "view" in the scenario: the draw list comes from the model's names (device0.pose here)
static void automatic_draw_list(void** state) {
  (void)state;
  tx_scenario* sc = load("png", "mono", false);
  if (!sc) fail_msg("%s", tx_error());
  int view = -1;
  for (int i = 0; i < tx_system_count(sc->system); i++)
    if (strcmp(tx_system_name(sc->system, i), "view") == 0) view = i;
  assert_true(view >= 0);
  assert_true(tx_system_rate(sc->system, view) == 30); // 30 Hz unless the view says
  bool reads_pose = false;
  for (int p = 0; p < tx_system_ports(sc->system, view); p++) {
    tx_port_info pi = tx_system_port(sc->system, view, p);
    assert_false(pi.write); // a view only reads
    reads_pose = reads_pose || strcmp(pi.component, "device0.pose") == 0;
  }
  assert_true(reads_pose);
  tx_scenario_free(sc);
  // and with --view none nothing is added, though the "view" is still checked
  tx_load_options none = {0};
  char text[2048];
  snprintf(text, sizeof text, wall_scene, ", \"view\": {\"widht\": 3}");
  assert_null(tx_scenario_load_text("wall-view", text, strlen(text), &none));
  assert_non_null(strstr(tx_error(), "view.widht: unknown key"));
  snprintf(text, sizeof text, wall_scene, view_json);
  sc = tx_scenario_load_text("wall-view", text, strlen(text), &none);
  assert_non_null(sc);
  assert_int_equal(tx_system_count(sc->system), 2);
  tx_scenario_free(sc);
}

static void draw_errors_name_the_view(void** state) {
  (void)state;
  char text[2048];
  tx_load_options o = {.view = "png"};
  snprintf(text, sizeof text, wall_scene, ", \"view\": {\"draw\": [{\"mesh\": \"skin\"}]}");
  assert_null(tx_scenario_load_text("f.json", text, strlen(text), &o));
  assert_non_null(strstr(tx_error(), "f.json: view.draw: "));
  assert_non_null(strstr(tx_error(), "skin.x"));
  // a component of the wrong shape: device0.force is f64 1x3, not spheres
  snprintf(text, sizeof text, wall_scene, ", \"view\": {\"draw\": [{\"spheres\": \"device0.force\"}]}");
  assert_null(tx_scenario_load_text("f.json", text, strlen(text), &o));
  assert_non_null(strstr(tx_error(), "view.draw"));
  // markers: the key inside the entry, and a puncture list nobody writes
  snprintf(text, sizeof text, wall_scene, ", \"view\": {\"draw\": [{\"markers\": {\"punctures\": \"needle.pose\", \"skin\": \"skin\"}}]}");
  assert_null(tx_scenario_load_text("f.json", text, strlen(text), &o));
  assert_non_null(strstr(tx_error(), "f.json: view.draw[0].markers.punctures: expected a puncture list"));
  snprintf(text, sizeof text, wall_scene, ", \"view\": {\"draw\": [{\"markers\": {\"punctures\": \"needle.punctures\", \"skin\": \"skin\"}}]}");
  assert_null(tx_scenario_load_text("f.json", text, strlen(text), &o));
  assert_non_null(strstr(tx_error(), "needle.punctures"));
  tx_load_options bad = {.view = "png", .stereo = "3d"};
  snprintf(text, sizeof text, wall_scene, view_json);
  assert_null(tx_scenario_load_text("f.json", text, strlen(text), &bad));
  assert_non_null(strstr(tx_error(), "stereo_mode"));
}

// two items drawing one component (markers on a drawn skin read skin.x too) share one read
static void items_share_a_read(void** state) {
  (void)state;
  char text[2048];
  tx_load_options o = {.view = "png"};
  snprintf(text, sizeof text, wall_scene,
           ", \"view\": {\"draw\": [{\"tool\": \"device0\"}, {\"tool\": \"device0\", \"show_force\": true}]}");
  tx_scenario* sc = tx_scenario_load_text("f.json", text, strlen(text), &o);
  if (!sc) fail_msg("%s", tx_error());
  tx_scenario_free(sc);
}

// in real time the step never waits: each tick gives a frame or counts a dropped one
static void real_time_hand_over(void** state) {
  (void)state;
  char dir[] = "/tmp/tx_view_XXXXXX", text[2048], path[4200];
  assert_non_null(mkdtemp(dir));
  snprintf(text, sizeof text, wall_scene, view_json);
  tx_load_options o = {.view = "png", .stereo = "sbs"};
  tx_scenario* sc = tx_scenario_load_text("wall-view", text, strlen(text), &o);
  if (!sc) fail_msg("%s", tx_error());
  tx_run_options ro = {.duration_s = 1.0, .out_dir = dir};
  tx_run_result r;
  if (tx_system_run(sc->system, &ro, &r)) fail_msg("%s", tx_error());
  for (int i = 0; i < tx_system_count(sc->system); i++)
    if (strcmp(tx_system_name(sc->system, i), "view") == 0) {
      tx_controller_stats st = tx_system_stats(sc->system, i);
      double frames = result(sc->system, "view.frames"), dropped = result(sc->system, "view.frames_dropped");
      assert_true(frames >= 1);
      assert_true(frames + dropped == (double)st.steps);
    }
  snprintf(path, sizeof path, "%s/frames/contact_sheet.png", dir);
  assert_int_equal(access(path, R_OK), 0);
  tx_scenario_free(sc);
  char cmd[4300];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  assert_int_equal(system(cmd), 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(png_frames_every_nth_and_last),
      cmocka_unit_test(files_that_cannot_be_written),
      cmocka_unit_test(stereo_files_and_sizes),
      cmocka_unit_test(automatic_draw_list),
      cmocka_unit_test(draw_errors_name_the_view),
      cmocka_unit_test(items_share_a_read),
      cmocka_unit_test(real_time_hand_over),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
