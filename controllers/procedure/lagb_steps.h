// Internal: phases 2 and 3 of laparoscopic adjustable gastric banding (the
// LAGB paper's dissection and band placement) as steps fed with what
// happened, without the model, so that each rule is tested alone.
// procedure.lagb (lagb_controller.c) feeds it from the components.
//
//   tx_lagb_steps s;
//   tx_lagb_steps_start(&s, 0.0);
//   tx_lagb_steps_done_at(&s, TX_LAGB_RETRACT, 2.5);   // the liver held up
//   ...
//
// The steps and what each needs before it (docs/lagb.md, "The procedure"):
//   2a retract the liver
//   2b divide the pars flaccida            after 2a
//   2c open a window at the angle of His   after 2a (2b and 2c in either order)
//   3a pass a grasper behind the stomach   after 2b and 2c
//   3b pull the band around                after 3a
//   3c lock the band                       after 3b
// A step begins once every step it comes after has ended. A step done
// before that ends the steps it comes after, directly or not, that have not
// ended, as skipped (locking the band round the stomach with no window made
// skips the dissection).
#ifndef TX_CONTROLLERS_PROCEDURE_LAGB_STEPS_H
#define TX_CONTROLLERS_PROCEDURE_LAGB_STEPS_H

#include <tactus/components.h>

#include <stdbool.h>

enum { TX_LAGB_RETRACT, TX_LAGB_PARS, TX_LAGB_HIS, TX_LAGB_BEHIND, TX_LAGB_AROUND, TX_LAGB_LOCK, TX_LAGB_STEPS };

typedef struct tx_lagb_steps {
  tx_procedure_step_state step[TX_LAGB_STEPS];
} tx_lagb_steps;

const char* tx_lagb_step_id(int step);   // "2a" ... "3c"
const char* tx_lagb_step_name(int step); // "retract the liver", ...

void tx_lagb_steps_start(tx_lagb_steps* s, double t);
// step done at t; false when it had ended already (nothing changes)
bool tx_lagb_steps_done_at(tx_lagb_steps* s, int step, double t);
bool tx_lagb_steps_ended(const tx_lagb_steps* s, int step); // done or skipped
// the first step under way, or TX_LAGB_STEPS when none is
int tx_lagb_steps_current(const tx_lagb_steps* s);
int tx_lagb_steps_done(const tx_lagb_steps* s);             // steps done

// The linking number of a closed loop (n points, m, the last joined to the
// first) with an open polyline (m points) whose ends lie well outside the
// loop: the signed crossings of the polyline through a fan of triangles from
// the loop's centroid, a surface the loop bounds. A band round the stomach's
// axis gives +1 or -1, one beside it 0. n < 3 or m < 2: 0
int tx_lagb_linking(const float* loop, int n, const double* axis, int m);
// where p is along the polyline (m points): the arc length to its nearest
// point, m, and its distance from it (*off, m)
double tx_lagb_along(const double* axis, int m, const double p[3], double* off);

#endif
