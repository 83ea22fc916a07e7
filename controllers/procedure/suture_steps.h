// Internal: the steps A-H of a simple interrupted suture (the suturing
// conference paper, section 4) as a state machine fed with what happened,
// without the model, so that each rule is tested alone. procedure.suture
// (suture_controller.c) feeds it from the event streams and components.
//
//   tx_suture_steps s;
//   tx_suture_steps_start(&s, &rules, 0.0);
//   tx_suture_steps_puncture(&s, 1.2, +1, +1);   // entered the skin left of the wound
//   tx_suture_steps_puncture(&s, 1.9, -1, -1);   // came out right of it: A done, B under way
//   ...
//   tx_suture_steps_done(&s);                    // steps done so far; one under way at the end stays not done
//
// The rules (docs/suturing.md states each as the entry condition of the next
// step):
//   A insert the needle through both wound edges: an exit puncture on the
//     other side of the wound from an entry made while A is under way
//   B pull the thread: the thread runs through every puncture of the stitch
//     and the tail beyond the entry is at most tail_m long
//   C wrap the thread around the needle holder: it winds around the holder's
//     jaws at least wrap_turns times
//   D the first throw: the thread's first knot is found
//   E fix the knot at the skin: a knot is fixed at the skin
//   F the second throw: a second knot is found
//   G cut the thread: the thread is cut
//   H end: after the cut, no instrument holds anything
// A, B and C are states, judged only while their step is under way; D to H
// follow events, and an event of a later step ends the steps before it as
// skipped (cutting after the first knot skips F).
#ifndef TX_CONTROLLERS_PROCEDURE_SUTURE_STEPS_H
#define TX_CONTROLLERS_PROCEDURE_SUTURE_STEPS_H

#include <tactus/components.h>

#include <stdbool.h>

enum { TX_SUTURE_A, TX_SUTURE_B, TX_SUTURE_C, TX_SUTURE_D, TX_SUTURE_E, TX_SUTURE_F, TX_SUTURE_G, TX_SUTURE_H, TX_SUTURE_STEPS };

typedef struct tx_suture_rules {
  double tail_m;     // m, B: the tail left beyond the entry once the thread is pulled through
  double wrap_turns; // C: turns of the thread around the holder's jaws
} tx_suture_rules;

tx_suture_rules tx_suture_rules_default(void);

typedef struct tx_suture_steps {
  tx_suture_rules rules;
  int current;                                   // the step under way; TX_SUTURE_STEPS: all ended
  tx_procedure_step_state step[TX_SUTURE_STEPS]; // each step's progress
  int entry_side;                                // A: the wound side of its entry (+1, -1), 0: none yet
  int first_knot;                                // the source of the first knot event, -1: none
} tx_suture_steps;

const char* tx_suture_step_id(int step);   // "A" ... "H"
const char* tx_suture_step_name(int step); // "insert the needle through both wound edges", ...

void tx_suture_steps_start(tx_suture_steps* s, const tx_suture_rules* r, double t);
// each returns true when a step changed
// side: +1 the needle entered the skin here, -1 it came out; wound_side: +1 or
// -1, the side of the wound line the puncture is on
bool tx_suture_steps_puncture(tx_suture_steps* s, double t, int side, int wound_side);
// through: the thread runs through every puncture the needle made up to A's exit
bool tx_suture_steps_tail(tx_suture_steps* s, double t, double tail_m, bool through);
bool tx_suture_steps_wrap(tx_suture_steps* s, double t, double turns);
bool tx_suture_steps_knot(tx_suture_steps* s, double t, int source, bool fixed);
bool tx_suture_steps_cut(tx_suture_steps* s, double t);
bool tx_suture_steps_hands_free(tx_suture_steps* s, double t);
int tx_suture_steps_done(const tx_suture_steps* s); // steps done

#endif
