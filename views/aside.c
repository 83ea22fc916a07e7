// An output file written aside and renamed once whole (aside.h).
#include "aside.h"

#include "../model/error.h"

bool tx_aside_begin(tx_aside* a, const char* dir, const char* name) {
  snprintf(a->path, sizeof a->path, "%s/%s", dir, name);
  snprintf(a->tmp, sizeof a->tmp, "%s.tmp", a->path);
  a->f = fopen(a->tmp, "w");
  if (!a->f) tx_set_error("%s: cannot be written", a->path);
  return a->f != NULL;
}

bool tx_aside_end(tx_aside* a) {
  bool ok = a->f && !ferror(a->f); // a write that failed on the way
  if (a->f && fclose(a->f) != 0) ok = false;
  ok = ok && rename(a->tmp, a->path) == 0;
  a->f = NULL;
  if (!ok) {
    remove(a->tmp);
    tx_set_error("%s: cannot be written", a->path);
  }
  return ok;
}

void tx_aside_drop(tx_aside* a) {
  if (!a->f) return;
  fclose(a->f);
  a->f = NULL;
  remove(a->tmp);
}

bool tx_aside_open(tx_ctx* c, tx_aside* a, const char* dir, const char* name) {
  if (tx_aside_begin(a, dir, name)) return true;
  tx_stop_run(c, "%s", tx_error());
  return false;
}

bool tx_aside_commit(tx_ctx* c, tx_aside* a) {
  if (tx_aside_end(a)) return true;
  tx_stop_run(c, "%s", tx_error());
  return false;
}
