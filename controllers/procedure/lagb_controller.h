// Internal: the "procedure.lagb" controller class: phases 2 and 3 of
// laparoscopic adjustable gastric banding (lagb_steps.h) followed from what
// the organs, the membranes, the cautery and the band publish, and the
// measures of its scorecard (docs/lagb.md, "The procedure").
//
// Reads (each named by a parameter; an empty name leaves it out): the
// organs' grasp events and rows (organs.events, organs.grasp), the liver's
// and the stomach's surfaces (which organ a grasp took), each membrane's
// MEMBRANE.state, band.state and band.centre, cautery.tissue, and hands
// (tx_pose: each hand's path).
// Writes PREFIX.step ("3/6 2c open a window at the angle of His", for the
// window), PREFIX.steps (6 rows of tx_procedure_step_state),
// PREFIX.step_names, PREFIX.step_paths (tx_step_path rows) and PREFIX.lagb
// (tx_lagb_measures); on PREFIX.events a TX_EVENT_STEP as each step's status
// changes. Results: steps_done, and each step's status as step_2a ...
// step_3c (a tx_step_status).
#ifndef TX_CONTROLLERS_PROCEDURE_LAGB_CONTROLLER_H
#define TX_CONTROLLERS_PROCEDURE_LAGB_CONTROLLER_H

#include <tactus/controller.h>

extern const tx_controller_class tx_procedure_lagb;

#endif
