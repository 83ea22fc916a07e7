// The steps of a simple interrupted suture as a state machine (suture_steps.h).
#include "suture_steps.h"

#include <math.h>
#include <stddef.h>

static const char* const ids[TX_SUTURE_STEPS] = {"A", "B", "C", "D", "E", "F", "G", "H"};
// the conference paper's steps, worded as the issue of the full suture words them
static const char* const names[TX_SUTURE_STEPS] = {
    "insert the needle through both wound edges",
    "pull the thread",
    "wrap the thread around the needle holder",
    "the first throw",
    "fix the knot at the skin",
    "the second throw",
    "cut the thread",
    "end",
};

tx_suture_rules tx_suture_rules_default(void) {
  // a 2-3 cm tail is left for an instrument tie; one turn makes a throw
  return (tx_suture_rules){.tail_m = 0.03, .wrap_turns = 1.0};
}

const char* tx_suture_step_id(int step) { return step >= 0 && step < TX_SUTURE_STEPS ? ids[step] : "?"; }
const char* tx_suture_step_name(int step) { return step >= 0 && step < TX_SUTURE_STEPS ? names[step] : "?"; }

void tx_suture_steps_start(tx_suture_steps* s, const tx_suture_rules* r, double t) {
  s->rules = r ? *r : tx_suture_rules_default();
  for (int i = 0; i < TX_SUTURE_STEPS; i++) s->step[i] = (tx_procedure_step_state){TX_STEP_NOT_REACHED, NAN, NAN};
  s->current = TX_SUTURE_A;
  s->step[TX_SUTURE_A] = (tx_procedure_step_state){TX_STEP_UNDER_WAY, t, NAN};
  s->entry_side = 0;
  s->first_knot = -1;
}

// step `done` is done at t: the ones under way or not reached before it are
// skipped, and the one after it begins
static bool finish(tx_suture_steps* s, double t, int done) {
  if (done < s->current || done >= TX_SUTURE_STEPS) return false;
  for (int i = s->current; i < done; i++) {
    if (isnan(s->step[i].t_start_s)) s->step[i].t_start_s = t;
    s->step[i].status = TX_STEP_SKIPPED, s->step[i].t_end_s = t;
  }
  if (isnan(s->step[done].t_start_s)) s->step[done].t_start_s = t;
  s->step[done].status = TX_STEP_DONE, s->step[done].t_end_s = t;
  s->current = done + 1;
  if (s->current < TX_SUTURE_STEPS) s->step[s->current] = (tx_procedure_step_state){TX_STEP_UNDER_WAY, t, NAN};
  return true;
}

bool tx_suture_steps_puncture(tx_suture_steps* s, double t, int side, int wound_side) {
  if (s->current != TX_SUTURE_A || (wound_side != 1 && wound_side != -1)) return false;
  if (side > 0) {
    if (s->entry_side == 0) s->entry_side = wound_side; // the first entry sets the near edge
    return false;
  }
  // an exit on the far edge completes the pass through both
  return side < 0 && s->entry_side != 0 && wound_side == -s->entry_side && finish(s, t, TX_SUTURE_A);
}

bool tx_suture_steps_tail(tx_suture_steps* s, double t, double tail_m, bool through) {
  return s->current == TX_SUTURE_B && through && tail_m <= s->rules.tail_m && finish(s, t, TX_SUTURE_B);
}

bool tx_suture_steps_wrap(tx_suture_steps* s, double t, double turns) {
  return s->current == TX_SUTURE_C && fabs(turns) >= s->rules.wrap_turns && finish(s, t, TX_SUTURE_C);
}

bool tx_suture_steps_knot(tx_suture_steps* s, double t, int source, bool fixed) {
  if (s->current < TX_SUTURE_B) return false; // no stitch yet: a knot in a loose thread is not a throw
  bool changed = false;
  if (s->first_knot < 0) {
    s->first_knot = source;
    changed |= finish(s, t, TX_SUTURE_D);
  } else if (source != s->first_knot) {
    changed |= finish(s, t, TX_SUTURE_F); // a second knot: the second throw (E skipped if never fixed)
  }
  if (fixed && s->current <= TX_SUTURE_E) changed |= finish(s, t, TX_SUTURE_E);
  return changed;
}

bool tx_suture_steps_cut(tx_suture_steps* s, double t) {
  return s->current >= TX_SUTURE_B && finish(s, t, TX_SUTURE_G);
}

bool tx_suture_steps_hands_free(tx_suture_steps* s, double t) {
  return s->current == TX_SUTURE_H && finish(s, t, TX_SUTURE_H);
}

int tx_suture_steps_done(const tx_suture_steps* s) {
  int n = 0;
  for (int i = 0; i < TX_SUTURE_STEPS; i++) n += s->step[i].status == TX_STEP_DONE;
  return n;
}
