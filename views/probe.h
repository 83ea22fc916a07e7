// Internal: the "view.probe" controller class, a recorder of any components.
// It reads the components listed in `components`, whatever their type, every
// `every_s` from `from_s` to `until_s`, into memory taken at configure, and
// when the run ends writes OUT/FILE.csv: one line per row of each component
// at each sample (t_s, component, seq, row, v0, v1, ...), after a comment
// line per component with its schema (a component not yet published at a
// sample has no line for it). Used to read where things were at a
// given time: the needle at a handover, the thread's tail before a grasp,
// when a script is calibrated; and by researchers to keep what their own
// controllers publish. It writes nothing to the model.
#ifndef TX_VIEWS_PROBE_H
#define TX_VIEWS_PROBE_H

#include <tactus/controller.h>

extern const tx_controller_class tx_view_probe;

#endif
