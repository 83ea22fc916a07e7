// Internal: the "view.scorecard" controller class: a procedure's scorecard,
// written when the run ends as OUT/scorecard.json and OUT/scorecard.png (the
// steps against time). It reads what a procedure controller publishes:
// PREFIX.steps (tx_procedure_step_state rows), PREFIX.step_names
// (tx_procedure_step rows: "A insert the needle ...") and, for the suture,
// PREFIX.suture (tx_suture_measures); so it runs in the simulation's process
// or, over the bridge, in an instructor's (docs/distributed.md).
// The JSON: {"scenario", "procedure", "steps": [{"id", "name", "done",
// "status", "t_start_s", "t_end_s"}, ...], then each measure as
// {"value", "unit", "rule"} (docs/suturing.md gives the rules and sources).
// Results: steps_done.
#ifndef TX_VIEWS_SCORECARD_H
#define TX_VIEWS_SCORECARD_H

#include <tactus/controller.h>

extern const tx_controller_class tx_view_scorecard;

#endif
