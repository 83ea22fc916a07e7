// Plots: one length unit, a palette that reads on white, log axes with
// enough labels, markers that tell series apart, and coinciding curves found.
#include "views/plot.h"

#include <tactus/config.h>

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

static void lengths_in_one_unit(void** state) {
  (void)state;
  // the unit a surgeon reads; trace_plot, force_curve and the studies all take it from here
  assert_string_equal(TX_PLOT_LENGTH_UNIT, "mm");
  assert_true(fabs(tx_plot_length(0.0123) - 12.3) < 1e-12);
  assert_true(fabs(tx_plot_length(-0.5) + 500) < 1e-12);
}

// WCAG relative luminance and contrast against white
static double luminance(const int rgb[3]) {
  double l[3];
  for (int c = 0; c < 3; c++) {
    double v = rgb[c] / 255.0;
    l[c] = v <= 0.03928 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
  }
  return 0.2126 * l[0] + 0.7152 * l[1] + 0.0722 * l[2];
}

static void palette_reads_on_white(void** state) {
  (void)state;
  for (int i = 1; i <= 15; i++) {
    int rgb[3];
    tx_plot_color(i, rgb);
    double contrast = 1.05 / (luminance(rgb) + 0.05);
    if (contrast < 3) fail_msg("colour %d (%d, %d, %d) has %.2f:1 contrast on white, under 3:1", i, rgb[0], rgb[1], rgb[2], contrast);
  }
}

static void expect_labels(double lo_value, double hi_value, int at_least, const double* must, int nmust) {
  double v[TX_PLOT_LOG_LABELS_MAX], lo = log10(lo_value), hi = log10(hi_value);
  int n = tx_plot_log_labels(lo, hi, v, TX_PLOT_LOG_LABELS_MAX);
  if (n < at_least) fail_msg("[%g, %g]: %d labels, expected at least %d", lo_value, hi_value, n, at_least);
  for (int i = 0; i < n; i++) {
    assert_true(v[i] >= lo_value * (1 - 1e-9) && v[i] <= hi_value * (1 + 1e-9));
    if (i) assert_true(v[i] > v[i - 1]);
  }
  for (int k = 0; k < nmust; k++) {
    bool found = false;
    for (int i = 0; i < n; i++) found |= fabs(v[i] - must[k]) <= 1e-9 * must[k];
    if (!found) fail_msg("[%g, %g]: no label at %g", lo_value, hi_value, must[k]);
  }
}

static void log_axes_have_enough_labels(void** state) {
  (void)state;
  // the needle fit's RMS axis, under one decade: PLplot alone labelled 0.1 only
  expect_labels(0.017, 0.13, 3, (const double[]){0.02, 0.05, 0.1}, 3);
  // several decades: the decades, and nothing between them
  double v[TX_PLOT_LOG_LABELS_MAX];
  assert_int_equal(tx_plot_log_labels(log10(40), log10(20000), v, TX_PLOT_LOG_LABELS_MAX), 3);
  assert_true(v[0] == 100 && v[1] == 1000 && v[2] == 10000);
  // short ranges: digits, then tenths
  expect_labels(0.3, 0.95, 3, (const double[]){0.4, 0.5}, 2);
  expect_labels(1.26, 2.0, 3, NULL, 0);
  // the cap holds
  assert_int_equal(tx_plot_log_labels(-12, 12, v, 5), 5);
  assert_int_equal(tx_plot_log_labels(NAN, 1, v, 5), 0);
}

static void markers_differ(void** state) {
  (void)state;
  for (int a = 0; a < 8; a++)
    for (int b = a + 1; b < 8; b++) assert_string_not_equal(tx_plot_marker(a), tx_plot_marker(b));
}

static void coinciding_series_are_found(void** state) {
  (void)state;
  double x[4] = {0, 1, 2, 3}, y[4] = {0, -0.02, -0.06, 0}, y2[4] = {0, -0.02, -0.06, 0}, y3[4] = {0, -0.02, -0.05, 0};
  tx_plot_series a = {"x over", x, y, 4, false, 1}, b = {"x under", x, y2, 4, false, 2}, c = {"z", x, y3, 4, false, 3},
                 d = {"short", x, y, 3, false, 4};
  assert_true(tx_plot_series_coincide(&a, &b));
  assert_false(tx_plot_series_coincide(&a, &c));
  assert_false(tx_plot_series_coincide(&a, &d));
}

static void draws_log_axes_and_markers(void** state) {
  (void)state;
  double t[5] = {0.25, 1, 4, 8, 16}, rms[5] = {0.11, 0.06, 0.03, 0.02, 0.018};
  tx_plot_series s[] = {{"line", t, rms, 5, false, 1}, {"points", t, rms, 5, true, 9}};
  tx_plot p = {"log axes", "run time (s)", "RMS error (N)", true, true, s, 2};
  char path[] = "/tmp/tx_plot_XXXXXX";
  close(mkstemp(path));
  int rc = tx_plot_png(path, &p);
  struct stat st;
  if (TX_WITH_PLPLOT) {
    assert_int_equal(rc, 0);
    assert_int_equal(stat(path, &st), 0);
    assert_true(st.st_size > 1000);
  } else {
    assert_int_equal(rc, -1);
  }
  remove(path);
}

// values equal but for rounding (3.3 and the next double, a clamped force
// and its clamp): the axis spans them as one value (it used to
// make PLplot draw grid lines for ever: the test's timeout catches a hang)
static void draws_values_equal_but_for_rounding(void** state) {
  (void)state;
  double x[2] = {1, 2}, y[2] = {nextafter(3.3, 4), 3.3}, y2[2] = {3.3, 3.3};
  tx_plot_series s[] = {{"largest force", x, y, 2, true, 1}, {"clamp", x, y2, 2, false, 15}};
  tx_plot p = {"nearly equal", "case", "force (N)", false, false, s, 2};
  char path[] = "/tmp/tx_plot_XXXXXX";
  close(mkstemp(path));
  int rc = tx_plot_png(path, &p);
  assert_int_equal(rc, TX_WITH_PLPLOT ? 0 : -1);
  remove(path);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(lengths_in_one_unit), cmocka_unit_test(palette_reads_on_white),
                                     cmocka_unit_test(log_axes_have_enough_labels), cmocka_unit_test(markers_differ),
                                     cmocka_unit_test(coinciding_series_are_found),
                                     cmocka_unit_test(draws_log_axes_and_markers),
                                     cmocka_unit_test(draws_values_equal_but_for_rounding)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
