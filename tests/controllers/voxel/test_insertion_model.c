// The published needle-force model form: its pieces against their formulas,
// and a generated insertion curve with its events in order.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "model/error.h"
#include "controllers/voxel/insertion_model.h"
#include "tactus/model.h"

#include <math.h>
#include <string.h>

static void force_pieces(void** state) {
  (void)state;
  tx_insertion_model m = tx_insertion_model_default();
  assert_int_equal(tx_insertion_model_check(&m), 0);
  assert_true(tx_insertion_force(&m, -1e-3, 1, false) == 0);
  double z = 1.5e-3;
  assert_true(fabs(tx_insertion_force(&m, z, 1, false) - (m.a1 * z + m.a2 * z * z)) < 1e-15);
  assert_true(fabs(tx_insertion_force(&m, 3e-3, 1, true) - (m.cutting + m.friction * 3e-3)) < 1e-15);
  assert_true(fabs(tx_insertion_force(&m, 3e-3, -1, true) + m.friction * 3e-3) < 1e-15);
  assert_true(tx_insertion_force(&m, 3e-3, 0, true) == 0);
  m.puncture_depth = 0;
  assert_int_equal(tx_insertion_model_check(&m), -1);
  assert_non_null(strstr(tx_error(), "puncture_depth"));
  tx_insertion_motion mo = tx_insertion_motion_default();
  mo.rate = 500;
  assert_int_equal(tx_insertion_motion_check(&mo), -1);
  assert_non_null(strstr(tx_error(), "rate"));
}

static void generated_curve(void** state) {
  (void)state;
  tx_insertion_model m = tx_insertion_model_default();
  tx_insertion_motion mo = tx_insertion_motion_default();
  tx_recording r;
  assert_true(tx_insertion_generate(&m, &mo, &r));
  // 0.2 s still, 5 mm in and 5 mm out at 3 mm/s, 0.2 s still: 1000 rows a second
  assert_int_equal(r.count, (size_t)floor((0.4 + 10.0 / 3) * 1000 + 1e-9) + 1);
  int order[5] = {0}, seen = 0;
  double peak = 0, drop_before = 0, drop_after = 0;
  for (size_t k = 0; k < r.count; k++) {
    const tx_recording_row* w = &r.rows[k];
    if (k) assert_true(fabs(w->t - r.rows[k - 1].t - 1e-3) < 1e-12);
    assert_true(w->f[0] == 0 && w->f[2] == 0);
    peak = fmax(peak, w->f[1]);
    if (w->event != TX_EVENT_NONE) order[seen++] = w->event;
    if (w->event == TX_EVENT_PUNCTURE) {
      drop_before = r.rows[k - 1].f[1], drop_after = w->f[1];
      assert_true(w->depth >= m.puncture_depth && w->depth - m.puncture_depth <= mo.speed / mo.rate + 1e-12);
    }
  }
  const int expect[4] = {TX_EVENT_CONTACT, TX_EVENT_PUNCTURE, TX_EVENT_RETRACT, TX_EVENT_EXIT};
  assert_int_equal(seen, 4);
  for (int i = 0; i < 4; i++) assert_int_equal(order[i], expect[i]);
  // the peak is the stiffness at the puncture, then the force drops to cutting plus friction
  // (within one sample of 3 um)
  double zp = m.puncture_depth, z0 = zp - mo.speed / mo.rate;
  assert_true(peak <= m.a1 * zp + m.a2 * zp * zp && peak >= m.a1 * z0 + m.a2 * z0 * z0);
  assert_true(drop_before == peak && drop_after < 0.6 * peak);
  assert_true(fabs(drop_after - (m.cutting + m.friction * zp)) < m.friction * mo.speed / mo.rate + 1e-12);
  tx_recording_free(&r);
  m.cutting = -1;
  assert_false(tx_insertion_generate(&m, &mo, &r));
  assert_non_null(strstr(tx_error(), "cutting"));
  assert_null(r.rows);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(force_pieces), cmocka_unit_test(generated_curve)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
