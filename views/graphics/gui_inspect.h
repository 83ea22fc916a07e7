// Internal: what the trainer's Inspect panel shows of the model, without
// ImGui (gui_inspect.c): each component's publish number and age, read
// lock-free with tx_model_stamp from the rendering thread, and the
// procedure's current step, from procedure.step (tx_procedure_step).
#ifndef TX_VIEWS_GRAPHICS_GUI_INSPECT_H
#define TX_VIEWS_GRAPHICS_GUI_INSPECT_H

#include <tactus/components.h>
#include <tactus/model.h>

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define TX_PROCEDURE_COMPONENT "procedure.step"

typedef struct tx_component_row {
  const char* name; // the model's
  uint64_t seq;     // publishes so far; 0: never published
  double age_ms;    // since the latest publish, wall clock; NAN if never
  double sim_s;     // simulation time of the latest publish; NAN if never
} tx_component_row;

// the first max components of m, in the model's order, as at now_mono_ns; the count written
int tx_inspect_components(const tx_model* m, int64_t now_mono_ns, tx_component_row* rows, int max);

// the step's text from a snapshot of procedure.step, made safe to print:
// cut at its NUL (or its 64th byte), anything but printable ASCII as '?';
// false (out "") when it was never published or has no row
bool tx_procedure_text(const tx_snapshot* s, char* out, size_t n);

#endif
