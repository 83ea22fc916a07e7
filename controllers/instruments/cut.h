// Scissors cutting a thread, and jaws pinching the skin: when the blades close, the thread segment that
// crosses them (within `reach` of the closed blades' line, from the pivot to
// the blades' length, nearest first) is cut there. Pure C, no ODE.
#ifndef TX_CONTROLLERS_INSTRUMENTS_CUT_H
#define TX_CONTROLLERS_INSTRUMENTS_CUT_H

#include <tactus/components.h>

// pivot: the blades' pivot; dir: unit, along the closed blades; length: the
// blades' length from the pivot (m); reach: how far from the blades' line a
// thread is between them (m, the thread's own radius is added). The segment
// (node i to i + 1) cut, or -1 for none; point: where on the thread.
int tx_scissors_cut(const double pivot[3], const double dir[3], double length, double reach,
                    const tx_thread_node* nodes, int n, double point[3]);

// Jaws closing on the skin: the particle (x: n rows of x, y, z) nearest the
// closed jaws' line, from the pivot (not at it) to `length` along dir,
// within `reach` of it: its row, or -1 for none; point: the particle.
int tx_jaws_pinch(const double pivot[3], const double dir[3], double length, double reach, const float* x, int n,
                  double point[3]);

// the jaws' closing, per instrument: armed when they open past `open`, a cut
// is due when an armed pair closes below `closed` (rad between the jaws)
typedef struct tx_blades {
  double open, closed;
  int armed;
} tx_blades;
// 1 when this step closes the blades, else 0
int tx_blades_close(tx_blades* b, double jaw);

#endif
