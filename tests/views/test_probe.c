// Tests of view.probe (views/probe.c): what it writes is what was published,
// at the times asked, whatever the element type; it stops whole samples when
// its memory is used up; a file it cannot write stops the run; bad
// parameters fail configure in one line.
#include "controllers/system.h"
#include "model/error.h"
#include "scenarios/loader.h"

#include <jansson.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

// a source of two components of different types: src.f (f32, 3 x 2), each
// value its publish number plus 0.25 per row and 0.5 per column; src.n (i32,
// up to 4 rows of 1), as many rows in use as the step index mod 3, each -seq
static tx_port src_f, src_n;
static tx_port bad_read; // a port the source did not declare
static const tx_component_def* bad_schema = (const tx_component_def*)1;
static int source_configure(tx_setup* s, void** self) {
  *self = NULL;
  src_f = tx_setup_write(s, &(tx_component_def){"src.f", TX_F32, 3, 2, "m"});
  src_n = tx_setup_write(s, &(tx_component_def){"src.n", TX_I32, 4, 1, "1"});
  bad_read = (tx_port){99};
  return 0;
}
static void source_step(tx_ctx* c, void* self) {
  (void)self;
  uint64_t seq = tx_step_index(c) + 1;
  float* f = tx_write(c, src_f);
  for (int r = 0; r < 3; r++)
    for (int k = 0; k < 2; k++) f[2 * r + k] = (float)seq + 0.25f * r + 0.5f * k;
  int32_t* n = tx_write(c, src_n);
  uint32_t rows = (uint32_t)(tx_step_index(c) % 3);
  for (uint32_t r = 0; r < rows; r++) n[r] = -(int32_t)seq;
  tx_write_rows(c, src_n, rows);
  if (seq == 1) bad_schema = tx_port_schema(c, bad_read);
}
static const tx_controller_class source_class = {
    .type = "test_probe.source", .summary = "writes src.f and src.n", .configure = source_configure, .step = source_step};

static int setup(void** state) {
  (void)state;
  tx_register_builtin();
  if (!tx_find_controller(source_class.type)) assert_int_equal(tx_register_controller(&source_class), 0);
  return 0;
}

// a system of the source and a probe with these params (JSON text); -1 with tx_error() when it fails
static tx_system* make(const char* params) {
  tx_system* s = tx_system_create();
  assert_non_null(s);
  assert_int_equal(tx_system_add(s, "src", "test_probe.source", 100, NULL), 0);
  json_error_t e;
  json_t* p = json_loads(params, 0, &e);
  assert_non_null(p);
  int rc = tx_system_add(s, "probe", "view.probe", 100, p);
  json_decref(p);
  if (rc || tx_system_finalize(s)) {
    tx_system_destroy(s);
    return NULL;
  }
  return s;
}

// run 0.2 s in lockstep into a fresh folder; returns the CSV's text (caller frees)
static char* run(tx_system* s, char* dir) {
  strcpy(dir, "/tmp/test_probe_XXXXXX");
  assert_non_null(mkdtemp(dir));
  tx_run_options o = {.duration_s = 0.2, .lockstep = true, .out_dir = dir};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  char path[128];
  snprintf(path, sizeof path, "%s/probe.csv", dir);
  FILE* f = fopen(path, "r");
  if (!f) return NULL;
  char* text = calloc(1, 1 << 16);
  assert_non_null(text);
  size_t n = fread(text, 1, (1 << 16) - 1, f);
  text[n] = 0;
  fclose(f);
  remove(path);
  return text;
}

static void writes_what_was_published_at_the_times_asked(void** state) {
  (void)state;
  tx_system* s = make("{\"components\": [\"src.f\", \"src.n\"], \"every_s\": 0.05, \"from_s\": 0.05}");
  if (!s) fail_msg("%s", tx_error());
  char dir[64];
  char* text = run(s, dir);
  assert_non_null(text);
  print_message("%s", text);
  // the schema of each, then the header with the widest row's columns
  assert_non_null(strstr(text, "# src.f: f32, 2 values a row, m\n# src.n: i32, 1 values a row, 1\nt_s,component,seq,row,v0,v1\n"));
  // samples at 0.05, 0.10 and 0.15 s (none before from_s); each row's values as published (seq from the line)
  int lines = 0, f_rows = 0, n_rows = 0;
  double times[8];
  int ntimes = 0;
  for (char* l = strtok(text, "\n"); l; l = strtok(NULL, "\n")) {
    if (*l == '#' || *l == 't') continue;
    double t, v0, v1 = 0;
    char comp[16];
    unsigned seq, row;
    int got = sscanf(l, "%lf,%15[^,],%u,%u,%lf,%lf", &t, comp, &seq, &row, &v0, &v1);
    lines++;
    if (strcmp(comp, "src.f") == 0) {
      assert_int_equal(got, 6);
      assert_true(v0 == seq + 0.25 * row && v1 == seq + 0.25 * row + 0.5);
      if (row == 0 && ntimes < 8) times[ntimes++] = t;
      f_rows++;
    } else {
      assert_string_equal(comp, "src.n");
      assert_int_equal(got, 5);
      assert_true(v0 == -(double)seq);
      n_rows++;
    }
  }
  assert_int_equal(ntimes, 3);
  for (int i = 0; i < 3; i++) assert_true(times[i] > 0.05 * (i + 1) - 1e-9 && times[i] < 0.05 * (i + 1) + 1e-9);
  assert_int_equal(f_rows, 9);
  // src.n's rows in use: 2, 1 and 0 at steps 5, 10 and 15, or 1, 0 and 2 a step before: 3 either way
  assert_int_equal(n_rows, 3);
  assert_int_equal(lines, f_rows + n_rows);
  assert_null(bad_schema); // a port the source never declared has no schema
  free(text);
  rmdir(dir);
  tx_system_destroy(s);
}

// room for one sample of src.f (4 + 6 values) and a half: the second is not kept
static void stops_whole_samples_when_full(void** state) {
  (void)state;
  tx_system* s = make("{\"components\": [\"src.f\"], \"every_s\": 0, \"max_values\": 15}");
  if (!s) fail_msg("%s", tx_error());
  char dir[64];
  char* text = run(s, dir);
  assert_non_null(text);
  int rows = 0;
  for (char* p = text; (p = strstr(p, "\n0.000000,src.f,")); p++) rows++;
  assert_int_equal(rows, 3);
  assert_null(strstr(text, "0.010000,"));
  free(text);
  rmdir(dir);
  tx_system_destroy(s);
}

// a folder it cannot write into: the run ends saying so, naming the file, and no .tmp is left
static void a_file_that_cannot_be_written_stops_the_run(void** state) {
  (void)state;
  tx_system* s = make("{\"components\": [\"src.f\"]}");
  if (!s) fail_msg("%s", tx_error());
  tx_run_options o = {.duration_s = 0.05, .lockstep = true, .out_dir = "/nonexistent/test_probe"};
  tx_run_result r;
  assert_int_equal(tx_system_run(s, &o, &r), 0);
  print_message("  %s\n", r.halt_reason);
  assert_true(r.halted);
  assert_non_null(strstr(r.halt_reason, "/nonexistent/test_probe/probe.csv: cannot be written"));
  tx_system_destroy(s);
}

static void bad_parameters_fail_in_one_line(void** state) {
  (void)state;
  const char* cases[][2] = {
      {"{\"components\": []}", "expected at least one component"},
      {"{\"components\": [\"src.f\"], \"from_s\": 2, \"until_s\": 1}", "before from_s"},
      {"{\"components\": [\"src.f\"], \"file\": \"../x\"}", "base name"},
      {"{\"components\": [\"src.f\"], \"every_s\": -1}", "every_s"},
      {"{\"components\": [\"nobody.writes\"]}", "nobody.writes"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    tx_system* s = make(cases[i][0]);
    if (s) fail_msg("%s was taken", cases[i][0]);
    char line[512]; // the key the error belongs to (the loader names it so), then the message
    snprintf(line, sizeof line, "%s: %s", tx_error_key(), tx_error());
    print_message("%s -> %s\n", cases[i][0], line);
    assert_null(strchr(line, '\n'));
    if (!strstr(line, cases[i][1])) fail_msg("'%s' does not mention '%s'", line, cases[i][1]);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(writes_what_was_published_at_the_times_asked),
      cmocka_unit_test(stops_whole_samples_when_full),
      cmocka_unit_test(a_file_that_cannot_be_written_stops_the_run),
      cmocka_unit_test(bad_parameters_fail_in_one_line),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
