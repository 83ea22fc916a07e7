// The Inspect panel's rows (gui_inspect.h): pure, so that they are tested
// without a window.
#include "gui_inspect.h"

#include <math.h>
#include <string.h>

int tx_inspect_components(const tx_model* m, int64_t now_mono_ns, tx_component_row* rows, int max) {
  int n = 0;
  for (uint32_t i = 0; i < tx_model_count(m) && n < max; i++) {
    tx_comp c = tx_model_comp(m, i);
    tx_stamp t = tx_model_stamp(m, c);
    tx_component_row* r = &rows[n++];
    r->name = tx_model_def(m, c)->name;
    r->seq = t.seq;
    r->age_ms = t.seq ? (double)(now_mono_ns - t.mono_ns) * 1e-6 : NAN;
    r->sim_s = t.seq ? (double)t.sim_ns * 1e-9 : NAN;
  }
  return n;
}

bool tx_procedure_text(const tx_snapshot* s, char* out, size_t n) {
  if (n) out[0] = 0;
  if (!s || !s->data || !s->seq || s->rows < 1 || s->cols != tx_procedure_step_COLS || n == 0) return false;
  const tx_procedure_step* p = s->data;
  size_t k = 0;
  for (; k + 1 < n && k < sizeof p->text && p->text[k]; k++) {
    unsigned char ch = (unsigned char)p->text[k];
    out[k] = ch >= 32 && ch < 127 ? (char)ch : '?';
  }
  out[k] = 0;
  return true;
}
