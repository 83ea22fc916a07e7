// Fitting the voxel model: the replay of a recording matches the needle
// stepped by hand, the fit of a curve the model itself made with other
// parameters gets much closer than its start, and bad input is refused.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/voxel/insertion_model.h"
#include "studies/experiments/needle_fit.h"
#include "tactus/model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// a short insertion (to 2.6 mm and back) sampled at 1 kHz
static void short_curve(tx_recording* r) {
  tx_insertion_model m = tx_insertion_model_default();
  tx_insertion_motion mo = tx_insertion_motion_default();
  mo.max_depth = 2.6e-3, mo.wait = 0.02;
  assert_true(tx_insertion_generate(&m, &mo, r));
}

static void replay_matches_and_rms(void** state) {
  (void)state;
  tx_recording r;
  short_curve(&r);
  tx_needle_fit_params p = tx_needle_fit_params_default();
  double* f = malloc(3 * r.count * sizeof *f);
  assert_non_null(f);
  double rms = tx_needle_fit_simulate(&p, &r, f);
  assert_true(rms > 0 && isfinite(rms));
  // the RMS is that of the force columns against the recording
  double sum = 0;
  for (size_t k = 0; k < r.count; k++)
    for (int a = 0; a < 3; a++) sum += pow(f[3 * k + a] - r.rows[k].f[a], 2);
  assert_true(fabs(sqrt(sum / (double)r.count) - rms) <= 1e-12 * rms);
  // the model resists on the way in: up (+y) near the deepest point
  size_t deep = 0;
  for (size_t k = 0; k < r.count; k++)
    if (r.rows[k].depth > r.rows[deep].depth) deep = k;
  assert_true(f[3 * (deep - 20) + 1] > 0);
  // the same replay twice: the same forces
  double* g = malloc(3 * r.count * sizeof *g);
  assert_non_null(g);
  assert_true(tx_needle_fit_simulate(&p, &r, g) == rms);
  assert_true(memcmp(f, g, 3 * r.count * sizeof *f) == 0);
  free(f), free(g);
  tx_recording_free(&r);
}

// the model's own output with known parameters, fitted from the defaults
static void fit_recovers_its_own_curve(void** state) {
  (void)state;
  tx_recording r;
  short_curve(&r);
  tx_needle_fit_params truth = tx_needle_fit_params_default();
  truth.spring *= 1.8, truth.friction *= 0.6, truth.rupture_force *= 1.5;
  double* f = malloc(3 * r.count * sizeof *f);
  assert_non_null(f);
  assert_true(tx_needle_fit_simulate(&truth, &r, f) >= 0);
  for (size_t k = 0; k < r.count; k++)
    for (int a = 0; a < 3; a++) r.rows[k].f[a] = f[3 * k + a];
  free(f);
  tx_needle_fit_params p = tx_needle_fit_params_default();
  double start = tx_needle_fit_simulate(&p, &r, NULL);
  tx_needle_fit_result res;
  assert_true(tx_needle_fit(&r, &p, 24, NULL, NULL, &res));
  print_message("  own curve: RMS %.4f N from %.4f N (peak %.3f N) in %d simulations\n", res.rms, start, res.peak,
                res.evaluations);
  assert_true(res.evaluations <= 24);
  assert_true(res.rms < 0.7 * start);
  assert_true(fabs(tx_needle_fit_simulate(&p, &r, NULL) - res.rms) <= 1e-12); // p holds the best
  tx_recording_free(&r);
}

static void bad_input_refused(void** state) {
  (void)state;
  tx_recording r;
  short_curve(&r);
  tx_needle_fit_params p = tx_needle_fit_params_default();
  tx_needle_fit_result res;
  assert_false(tx_needle_fit(&r, &p, 5, NULL, NULL, &res));
  assert_non_null(strstr(tx_error(), "evaluations"));
  p.radius = 1; // beyond half the spacing
  assert_false(tx_needle_fit(&r, &p, 50, NULL, NULL, &res));
  assert_non_null(strstr(tx_error(), "range"));
  tx_recording one = r;
  one.count = 1;
  p = tx_needle_fit_params_default();
  assert_false(tx_needle_fit(&one, &p, 50, NULL, NULL, &res));
  tx_recording_free(&r);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(replay_matches_and_rms), cmocka_unit_test(fit_recovers_its_own_curve),
                                     cmocka_unit_test(bad_input_refused)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
