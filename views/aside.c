// A view's output file written aside and renamed once whole (aside.h).
#include "aside.h"

bool tx_aside_open(tx_ctx* c, tx_aside* a, const char* dir, const char* name) {
  snprintf(a->path, sizeof a->path, "%s/%s", dir, name);
  snprintf(a->tmp, sizeof a->tmp, "%s.tmp", a->path);
  a->f = fopen(a->tmp, "w");
  if (!a->f) tx_stop_run(c, "%s: cannot be written", a->path);
  return a->f != NULL;
}

bool tx_aside_commit(tx_ctx* c, tx_aside* a) {
  bool ok = fclose(a->f) == 0 && rename(a->tmp, a->path) == 0;
  a->f = NULL;
  if (!ok) {
    remove(a->tmp);
    tx_stop_run(c, "%s: cannot be written", a->path);
  }
  return ok;
}
