// The Inspect panel's rows: each component's publish number, age and
// simulation time from tx_model_stamp, and the procedure's step from a
// fixture procedure.step component, cut and cleaned for printing.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "views/graphics/gui_inspect.h"

#include <math.h>
#include <string.h>

static void rows_hold_each_components_stamp(void** state) {
  (void)state;
  tx_model* m = tx_model_create();
  tx_comp a = tx_model_add(m, &(tx_component_def){"skin.x", TX_F32, 4, 3, "m"});
  tx_model_add(m, &(tx_component_def){"wall.force_model", TX_F64, 1, 3, "1"});
  assert_true(tx_model_commit(m));
  tx_model_publish(m, a, 250000000);
  tx_model_publish(m, a, 500000000);
  int64_t at = tx_model_stamp(m, a).mono_ns;
  tx_component_row rows[4];
  assert_int_equal(tx_inspect_components(m, at + 3000000, rows, 4), 2);
  assert_string_equal(rows[0].name, "skin.x");
  assert_int_equal(rows[0].seq, 2);
  assert_true(fabs(rows[0].age_ms - 3.0) < 1e-9);
  assert_true(fabs(rows[0].sim_s - 0.5) < 1e-12);
  assert_string_equal(rows[1].name, "wall.force_model");
  assert_int_equal(rows[1].seq, 0); // never published: no age
  assert_true(isnan(rows[1].age_ms) && isnan(rows[1].sim_s));
  assert_int_equal(tx_inspect_components(m, at, rows, 1), 1); // at most max
  tx_model_destroy(m);
}

static void procedure_step_is_read_by_name_and_cleaned(void** state) {
  (void)state;
  tx_model* m = tx_model_create();
  tx_comp c = tx_model_add(m, &TX_COMPONENT_OF(TX_PROCEDURE_COMPONENT, tx_procedure_step, 1));
  tx_reader r = tx_model_add_reader(m, c);
  assert_true(tx_model_commit(m));
  char out[80];
  tx_snapshot s = tx_model_acquire(m, r);
  assert_false(tx_procedure_text(&s, out, sizeof out)); // not published yet
  assert_string_equal(out, "");
  tx_procedure_step* p = tx_model_back(m, c);
  memset(p, 0, sizeof *p);
  strcpy(p->text, "3/7 pass the needle\tthrough");
  tx_model_set_rows(m, c, 1);
  tx_model_publish(m, c, 0);
  s = tx_model_acquire(m, r);
  assert_true(tx_procedure_text(&s, out, sizeof out));
  assert_string_equal(out, "3/7 pass the needle?through"); // a tab is not printed as is
  char small[8];
  assert_true(tx_procedure_text(&s, small, sizeof small));
  assert_string_equal(small, "3/7 pas");
  // 64 bytes with no NUL: cut at the row's end, never read past it
  p = tx_model_back(m, c);
  memset(p->text, 'x', sizeof p->text);
  tx_model_set_rows(m, c, 1);
  tx_model_publish(m, c, 0);
  s = tx_model_acquire(m, r);
  assert_true(tx_procedure_text(&s, out, sizeof out));
  assert_int_equal(strlen(out), 64);
  // a component of another width is not the procedure's
  tx_snapshot wrong = s;
  wrong.cols = 3;
  assert_false(tx_procedure_text(&wrong, out, sizeof out));
  tx_model_destroy(m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(rows_hold_each_components_stamp),
      cmocka_unit_test(procedure_step_is_read_by_name_and_cleaned),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
