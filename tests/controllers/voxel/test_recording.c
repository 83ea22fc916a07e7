// Haptic recordings: a written file reads back the same; the reader refuses
// every malformed line with FILE:LINE and leaves nothing behind.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/voxel/recording.h"
#include "tactus/model.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tests/temp_file.h"

static void round_trip(void** state) {
  (void)state;
  tx_recording r;
  assert_true(tx_recording_alloc(&r, 3));
  const tx_recording_row rows[3] = {{0, -1e-3, {0, 0, 0}, TX_EVENT_NONE},
                                    {0.001, 1e-6, {0.01, 0.25, -0.5}, TX_EVENT_CONTACT},
                                    {0.0015, 2e-6, {0, 1.5, 0}, TX_EVENT_PUNCTURE}};
  for (int k = 0; k < 3; k++) assert_true(tx_recording_push(&r, &rows[k]));
  assert_false(tx_recording_push(&r, &rows[0])); // full
  char* path = write_file("");
  assert_true(tx_recording_write(&r, path));
  tx_recording back;
  assert_true(tx_recording_read(&back, path));
  assert_int_equal(back.count, 3);
  for (int k = 0; k < 3; k++) {
    assert_true(back.rows[k].t == rows[k].t && back.rows[k].event == rows[k].event);
    assert_true(back.rows[k].depth == rows[k].depth);
    for (int a = 0; a < 3; a++) assert_true(back.rows[k].f[a] == rows[k].f[a]);
  }
  tx_recording_free(&back);
  tx_recording_free(&r);
  unlink(path);
}

// each bad file: the reader says FILE:LINE (or FILE:) and the fragment
static void bad_files_name_the_line(void** state) {
  (void)state;
  const char* head = "t_s,depth_m,fx_n,fy_n,fz_n,event\n";
  const struct { const char* body; const char* where; const char* what; } cases[] = {
      {"t,depth,fx,fy,fz,event\n0,0,0,0,0,\n0.001,0,0,0,0,\n", ":1:", "header"},
      {"# only comments\n", ":", "no header"},
      {"HEAD0,0,0,0,0,\n", ":", "fewer than 2 rows"},
      {"HEAD0,0,0,0,0,\n0.001,0,0,0,\n", ":3:", "expected"},
      {"HEAD0,0,0,0,0,\n0.001,0,nan,0,0,\n", ":3:", "finite"},
      {"HEAD0,0,0,0,0,\n0.001,0,0,0,0,poke\n", ":3:", "event"},
      {"HEAD0,0,0,0,0,\n0,0,0,0,0,\n", ":3:", "increase"},
      {"HEAD0,0,0,0,0,\n0.002,0,0,0,0,\n", ":3:", "1 ms"},
      {"HEAD0,0,0,0,0,\n0.001,5,0,0,0,\n", ":3:", "metres"},
      {"HEAD0,0,0,0,0,\n0.001,0,0,2e4,0,\n", ":3:", "newtons"},
      {"HEAD-1,0,0,0,0,\n0.001,0,0,0,0,\n", ":2:", "negative"},
      {"HEAD0,0,0,0,0,\n0.001 0 0 0 0\n", ":3:", "','"},
      {"# a comment\nHEAD0,0,0,0,0,\n# not here\n", ":4:", "finite"},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    char text[512] = "";
    const char* b = cases[k].body;
    const char* h = strstr(b, "HEAD");
    if (h) {
      strncat(text, b, (size_t)(h - b));
      strcat(text, head);
      strcat(text, h + 4);
    } else {
      strcat(text, b);
    }
    char* path = write_file(text);
    tx_recording r;
    assert_false(tx_recording_read(&r, path));
    const char* e = tx_error();
    assert_non_null(strstr(e, path));
    assert_non_null(strstr(e, cases[k].where));
    if (!strstr(e, cases[k].what)) fail_msg("case %zu: '%s' lacks '%s'", k, e, cases[k].what);
    assert_null(r.rows);
    assert_int_equal(r.count, 0);
    unlink(path);
  }
  // a line too long, a missing file
  char text[2048];
  snprintf(text, sizeof text, "%s0,0,0,0,0,%0900d\n", head, 0);
  char* path = write_file(text);
  tx_recording r;
  assert_false(tx_recording_read(&r, path));
  assert_non_null(strstr(tx_error(), ":2: line longer"));
  unlink(path);
  assert_false(tx_recording_read(&r, "/nonexistent/x.csv"));
  assert_non_null(strstr(tx_error(), "/nonexistent/x.csv"));
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(round_trip), cmocka_unit_test(bad_files_name_the_line)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
