// Internal: a view's output file written aside (PATH.tmp) and renamed to
// PATH once whole, so that a run that fails half way leaves no half file.
// Either call that fails stops the run naming PATH ("cannot be written"):
// the run's data would otherwise be lost without a word.
//
//     tx_aside a;
//     if (!tx_aside_open(ctx, &a, dir, "probe.csv")) return;
//     fprintf(a.f, ...);
//     tx_aside_commit(ctx, &a);
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

#endif
