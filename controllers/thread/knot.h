// Internal: knots in the thread, two ways.
//
// The papers' rule (the suturing conference paper, section 3.3): cylinders
// that collide with a cylinder at least min_gap cylinders away along the
// thread are "colliding"; a knot is when there are at least min_colliding
// of them, in at least two contiguous blocks of at least min_block, the
// blocks separated by at least min_gap cylinders (10, 4 and 5 in the paper).
// It sees contact, not topology: a loose knot has no contact, two strands
// lying side by side have plenty.
//
// The classifier: the thread is closed by a segment passing over everything
// (the usual closure of an open knot: its ends joined far above), projected
// along 32 directions spread over a half sphere, and each projection's crossings are
// written as a Gauss code (each crossing met twice along the curve, once
// over, once under). Reidemeister moves I (a crossing met twice in a row: a
// curl) and II (two crossings met in a row over on one strand and in a row
// under on another: a bigon) are undone until none applies. The projection
// with fewest crossings left decides: none is the unknot; 3 with writhe +-3
// a trefoil (the overhand knot); 6 with writhe +-6 a granny knot (two
// trefoils of one hand) and 6 with writhe 0 a square knot (one of each).
// Anything else is knotted but not named (TX_KNOT_OTHER). Moves I and II do
// not reduce every diagram, so a knot may be reported with more crossings
// than it needs; they never remove a real knot.
//
//     tx_knot_work* w = tx_knot_work_create(200);   // room for 200 nodes; NULL on no memory
//     tx_knot_diagram d;
//     tx_knot_classify(w, x, n, &d);                 // x: (n x 3)
//     tx_knot_work_destroy(w);
//
// Create allocates; the functions never allocate.
#ifndef TX_CONTROLLERS_THREAD_KNOT_H
#define TX_CONTROLLERS_THREAD_KNOT_H

#include <stdbool.h>
#include <stdint.h>

typedef struct tx_knot_rule {
  int min_colliding; // 10
  int min_block;     // 4
  int min_gap;       // 5
} tx_knot_rule;

// the papers' numbers
tx_knot_rule tx_knot_rule_papers(void);

typedef struct tx_knot_papers {
  bool knot;
  int colliding; // colliding cylinders
  int blocks;    // contiguous blocks of at least min_block
  int first;     // the knot's cylinders: from the first block's start...
  int last;      // ...to the last block's end (-1, -1 without a knot)
} tx_knot_papers;

// out (n - 1 entries): 1 for each cylinder closer than 2 r (touching:
// 2 r (1 + 1e-2)) to a cylinder at least min_gap + 1 away along the thread;
// brute force over the pairs. Returns how many are marked.
int tx_knot_contacts(const double* x, int n, double radius, int min_gap, uint8_t* out);

// the papers' rule on the marks of tx_knot_contacts (or a thread's own)
bool tx_knot_papers_rule(const uint8_t* colliding, int nseg, const tx_knot_rule* rule, tx_knot_papers* out);

typedef enum tx_knot_class {
  TX_KNOT_UNKNOT = 0,
  TX_KNOT_TREFOIL = 1, // the overhand knot
  TX_KNOT_SQUARE = 2,
  TX_KNOT_GRANNY = 3,
  TX_KNOT_OTHER = 4, // knotted, not one of the above
} tx_knot_class;

const char* tx_knot_class_name(tx_knot_class c);

typedef struct tx_knot_diagram {
  tx_knot_class cls;
  int crossings; // left after the moves, in the projection chosen
  int writhe;    // the sum of those crossings' signs
  int raw;       // crossings of that projection before the moves
} tx_knot_diagram;

typedef struct tx_knot_work tx_knot_work;

// room for threads of up to max_nodes nodes (and their crossings); NULL on no memory
tx_knot_work* tx_knot_work_create(int max_nodes);
void tx_knot_work_destroy(tx_knot_work* w);

// 0, or -1 (tx_error()) when n is outside [2, max_nodes] or the
// projections have more crossings than there is room for
int tx_knot_classify(tx_knot_work* w, const double* x, int n, tx_knot_diagram* out);

#endif
