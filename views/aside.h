// Internal: an output file written aside (PATH.tmp) and renamed to PATH
// once whole, so that a run or a study that fails half way leaves no half
// file. In a view, either call that fails stops the run naming PATH
// ("cannot be written"): the run's data would otherwise be lost without a
// word. Outside a run (a study) the same calls without a context set
// tx_error() instead.
//
//     tx_aside a;
//     if (!tx_aside_open(ctx, &a, dir, "probe.csv")) return;
//     fprintf(a.f, ...);
//     tx_aside_commit(ctx, &a);
//
//     if (!tx_aside_begin(&a, dir, "study.csv")) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
//     ...
//     if (!tx_aside_end(&a)) ...           // or tx_aside_drop(&a) to give up
#ifndef TX_VIEWS_ASIDE_H
#define TX_VIEWS_ASIDE_H

#include <tactus/controller.h>

#include <stdbool.h>
#include <stdio.h>

typedef struct tx_aside {
  FILE* f;         // open on tmp while the file is written
  char path[4200]; // DIR/NAME
  char tmp[4300];  // DIR/NAME.tmp
} tx_aside;

bool tx_aside_open(tx_ctx* c, tx_aside* a, const char* dir, const char* name);
bool tx_aside_commit(tx_ctx* c, tx_aside* a);

// without a run: false with tx_error() "PATH: cannot be written" (and no file left)
bool tx_aside_begin(tx_aside* a, const char* dir, const char* name);
bool tx_aside_end(tx_aside* a);
// closes and removes the file begun (a study that gives up); none open: nothing
void tx_aside_drop(tx_aside* a);

#endif
