// Device traces: CSV columns found by name, bad rows named by line, and the
// three-panel PNG written where PLplot is built.
#include "model/error.h"
#include "views/trace_plot.h"

#include <tactus/config.h>

#include <float.h>
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

static void write_file(const char* path, const char* text) {
  FILE* f = fopen(path, "w");
  assert_non_null(f);
  fputs(text, f);
  fclose(f);
}

static void loads_columns_by_name(void** state) {
  (void)state;
  char path[] = "/tmp/tx_trace_XXXXXX";
  close(mkstemp(path));
  // columns in another order than the recorder's, and one it does not know
  write_file(path, "fx_n,t_s,extra,px_m,py_m,pz_m,fy_n,fz_n\n"
                   "1,0.000,9,0.1,0.2,0.3,2,3\n"
                   "-1,0.001,9,0.1,0.19,0.3,2.5,3\n");
  tx_trace t;
  assert_int_equal(tx_trace_load(path, &t), 0);
  assert_int_equal(t.n, 2);
  assert_true(t.t[1] == 0.001 && t.f[0][0] == 1 && t.f[0][1] == -1 && t.p[1][1] == 0.19 && t.f[1][1] == 2.5);
  tx_trace_free(&t);
  char png[300];
  snprintf(png, sizeof png, "%s.png", path);
  int rc = tx_trace_plot_png(path, png);
  struct stat st;
  if (TX_WITH_PLPLOT) {
    assert_int_equal(rc, 0);
    assert_int_equal(stat(png, &st), 0);
    assert_true(st.st_size > 1000);
  } else {
    assert_int_equal(rc, -1);
    assert_non_null(strstr(tx_error(), "PLplot"));
  }
  remove(png);
  remove(path);
}

static void expect_bad(const char* text, const char* fragment) {
  char path[] = "/tmp/tx_trace_XXXXXX";
  close(mkstemp(path));
  write_file(path, text);
  tx_trace t;
  char want[300];
  assert_int_equal(tx_trace_load(path, &t), -1);
  snprintf(want, sizeof want, "%s%s", path, fragment);
  if (!strstr(tx_error(), want)) fail_msg("'%s' lacks '%s'", tx_error(), want);
  remove(path);
}

static void bad_files_name_the_line(void** state) {
  (void)state;
  expect_bad("", ":1: empty file");
  expect_bad("t_s,px_m,py_m,pz_m,fx_n,fy_n\n", ":1: no column 'fz_n'");
  expect_bad("t_s,px_m,py_m,pz_m,fx_n,fy_n,fz_n\n0,0,0,0,0,0,0\n0.1,0,zero,0,0,0,0\n", ":3: column py_m: not a number");
  expect_bad("t_s,px_m,py_m,pz_m,fx_n,fy_n,fz_n\n0,0,0\n", ":2: expected 7 columns");
  expect_bad("t_s,px_m,py_m,pz_m,fx_n,fy_n,fz_n\n", ":2: no samples");
  tx_trace t;
  assert_int_equal(tx_trace_load("/nonexistent/device0.csv", &t), -1);
  assert_non_null(strstr(tx_error(), "/nonexistent/device0.csv: "));
}

// every finite double that the recorder's %.17g writes reads back to the same
// bits: subnormals (strtod's ERANGE on them is no error), -0, the extremes
static void every_finite_double_reads_back(void** state) {
  (void)state;
  const double v[] = {4.1e-312, -4.1e-312, 0x1p-1074, DBL_MIN, -0.0, DBL_MAX, -DBL_MAX, 0.1, 1.0 / 3, nextafter(1, 2)};
  const int nv = (int)(sizeof v / sizeof v[0]);
  char path[] = "/tmp/tx_trace_XXXXXX";
  close(mkstemp(path));
  FILE* f = fopen(path, "w");
  assert_non_null(f);
  fprintf(f, "t_s,px_m,py_m,pz_m,fx_n,fy_n,fz_n\n");
  for (int i = 0; i < nv; i++) // each value in every column, rotated from row to row
    for (int c = 0; c < 7; c++) fprintf(f, "%.17g%s", v[(i + c) % nv], c < 6 ? "," : "\n");
  fclose(f);
  tx_trace t;
  if (tx_trace_load(path, &t)) fail_msg("%s", tx_error());
  assert_int_equal(t.n, nv);
  for (int i = 0; i < nv; i++) {
    double* got[7] = {&t.t[i], &t.p[0][i], &t.p[1][i], &t.p[2][i], &t.f[0][i], &t.f[1][i], &t.f[2][i]};
    for (int c = 0; c < 7; c++)
      if (memcmp(got[c], &v[(i + c) % nv], sizeof(double)) != 0) fail_msg("row %d column %d: %a, wrote %a", i, c, *got[c], v[(i + c) % nv]);
  }
  tx_trace_free(&t);
  remove(path);
  // what no finite double prints as
  expect_bad("t_s,px_m,py_m,pz_m,fx_n,fy_n,fz_n\n0,0,0,0,0,0,0\n0,0,1e999,0,0,0,0\n", ":3: column py_m: not a finite number");
  expect_bad("t_s,px_m,py_m,pz_m,fx_n,fy_n,fz_n\n0,0,0,0,nan,0,0\n", ":2: column fx_n: not a finite number");
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(loads_columns_by_name), cmocka_unit_test(bad_files_name_the_line),
                                     cmocka_unit_test(every_finite_double_reads_back)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
