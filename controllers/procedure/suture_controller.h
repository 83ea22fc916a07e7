// Internal: the "procedure.suture" controller class: steps A-H of a simple
// interrupted suture (suture_steps.h) followed from the event streams and
// components of the instruments and the thread, and the measures of its
// scorecard (docs/suturing.md).
//
// Reads (each named by a parameter; an empty name leaves it out):
// instrument_events (punctures, grasps, releases), punctures (tx_puncture
// rows: whether each puncture entered or came out), thread_events (knots,
// cuts), THREAD.nodes and THREAD.force_model (the tail, the tension), holder
// (tx_instrument_pose: the needle holder's jaws, for the wrap) and hands
// (tx_pose: each hand's path).
// Writes PREFIX.step (tx_procedure_step: "2/8 B pull the thread", for the
// window), PREFIX.steps (8 rows of tx_procedure_step_state), PREFIX.suture
// (tx_suture_measures) and, on PREFIX.events, a TX_EVENT_STEP as each step
// begins (source: its index, 0 for A) and ends (value[0]: its
// tx_step_status). Results: steps_done, and each step's status as
// step_A ... step_H (a tx_step_status).
#ifndef TX_CONTROLLERS_PROCEDURE_SUTURE_CONTROLLER_H
#define TX_CONTROLLERS_PROCEDURE_SUTURE_CONTROLLER_H

#include <tactus/controller.h>

extern const tx_controller_class tx_procedure_suture;

#endif
