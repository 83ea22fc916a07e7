// The membrane experiment behind tactus study skin-membrane: on the clamped,
// pre-tensioned disc under a spread load, the implicit skin at its real-time
// defaults (one 1/60 s substep a step) reaches the converged XPBD skin's
// static answer and the closed form, w0 = F (ln(a / r0) + 1/2) / (2 pi T).
// Under the sanitizers only the implicit run (the XPBD one is the study's).
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "studies/experiments/skin_membrane.h"

#include <tactus/model.h>

#include <math.h>

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define SANITIZED 1
#else
#define SANITIZED 0
#endif

static tx_membrane_result disc(int implicit) {
  tx_membrane_case k = tx_membrane_case_default(TX_MEMBRANE_DISC);
  k.implicit = implicit;
  tx_membrane_result r;
  if (!tx_membrane_run(&k, 0.0025, &r)) fail_msg("%s", tx_error());
  return r;
}

static void implicit_reaches_the_static_answer(void** state) {
  (void)state;
  tx_membrane_result wi = disc(1);
  print_message("  disc at 2.5 mm: implicit %.5f mm, closed form %.5f mm\n", wi.measured * 1e3, wi.exact * 1e3);
  assert_true(wi.error < 0.05);
  if (SANITIZED) return;
  tx_membrane_result wx = disc(0);
  print_message("  converged XPBD %.5f mm\n", wx.measured * 1e3);
  assert_true(fabs(wi.measured - wx.measured) < 0.01 * wx.measured);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(implicit_reaches_the_static_answer)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
