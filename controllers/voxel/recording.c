// Haptic recordings: the CSV writer and its strict reader.
#include "recording.h"

#include "../../model/error.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char* const event_names[] = {"", "contact", "puncture", "retract", "exit"};

const char* tx_needle_event_name(tx_needle_event e) { return (unsigned)e <= TX_EVENT_EXIT ? event_names[e] : "?"; }

bool tx_recording_alloc(tx_recording* r, size_t cap) {
  memset(r, 0, sizeof *r);
  if (cap == 0 || cap > TX_RECORDING_MAX_ROWS) return tx_set_error("recording: %zu rows, must be in [1, %d]", cap, TX_RECORDING_MAX_ROWS), false;
  r->rows = malloc(cap * sizeof *r->rows);
  if (!r->rows) return tx_set_error("recording: out of memory for %zu rows", cap), false;
  r->cap = cap;
  return true;
}

void tx_recording_free(tx_recording* r) {
  free(r->rows);
  memset(r, 0, sizeof *r);
}

bool tx_recording_push(tx_recording* r, const tx_recording_row* row) {
  if (r->count == r->cap) return false;
  r->rows[r->count++] = *row;
  return true;
}

bool tx_recording_write(const tx_recording* r, const char* path) {
  char tmp[4200];
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  FILE* f = fopen(tmp, "w");
  if (!f) return tx_set_error("%s: %s", path, strerror(errno)), false;
  fprintf(f, "# tactus needle recording: t in s, depth in m, force on the needle in N (y out of the tissue)\n");
  fprintf(f, "%s\n", TX_RECORDING_HEADER);
  for (size_t i = 0; i < r->count; i++) {
    const tx_recording_row* w = &r->rows[i];
    fprintf(f, "%.6f,%.9f,%.9g,%.9g,%.9g,%s\n", w->t, w->depth, w->f[0], w->f[1], w->f[2], tx_needle_event_name(w->event));
  }
  bool ok = !ferror(f);
  ok = fclose(f) == 0 && ok;
  if (!ok || rename(tmp, path) != 0) {
    remove(tmp);
    return tx_set_error("%s: cannot write", path), false;
  }
  return true;
}

// one number up to the next comma; NULL and a message, or the position after the comma
static const char* number(const char* p, double* v, const char** why) {
  char* end;
  errno = 0;
  *v = strtod(p, &end);
  if (end == p || errno || !isfinite(*v)) return *why = "expected a finite number", NULL;
  if (*end != ',') return *why = "expected ',' after a number", NULL;
  return end + 1;
}

static const char* parse_row(const char* line, tx_recording_row* w) {
  const char* why = NULL;
  double v[5];
  const char* p = line;
  for (int k = 0; k < 5; k++)
    if (!(p = number(p, &v[k], &why))) return why;
  size_t len = strcspn(p, "\r\n");
  w->event = TX_EVENT_NONE;
  bool known = false;
  for (int e = 0; e <= TX_EVENT_EXIT && !known; e++)
    if (strlen(event_names[e]) == len && strncmp(p, event_names[e], len) == 0) w->event = (tx_needle_event)e, known = true;
  if (!known) return "event must be empty or one of contact, puncture, retract, exit";
  if (p[len] == '\r' && p[len + 1] != '\n' && p[len + 1] != 0) return "stray carriage return";
  w->t = v[0], w->depth = v[1];
  for (int k = 0; k < 3; k++) w->f[k] = v[2 + k];
  if (w->t < 0) return "t_s must not be negative";
  if (fabs(w->depth) > 1) return "depth_m beyond 1 m (the file must be in metres)";
  for (int k = 0; k < 3; k++)
    if (fabs(w->f[k]) > 1e4) return "a force beyond 10 kN (the file must be in newtons)";
  return NULL;
}

bool tx_recording_read(tx_recording* r, const char* path) {
  memset(r, 0, sizeof *r);
  FILE* f = fopen(path, "r");
  if (!f) return tx_set_error("%s: %s", path, strerror(errno)), false;
  size_t cap = 4096;
  r->rows = malloc(cap * sizeof *r->rows);
  char line[512];
  int lineno = 0;
  bool header = false;
  const char* problem = r->rows ? NULL : "out of memory";
  while (!problem && fgets(line, sizeof line, f)) {
    lineno++;
    if (!strchr(line, '\n') && !feof(f)) problem = "line longer than 510 characters";
    else if (!header) {
      if (line[0] == '#') continue;
      size_t len = strcspn(line, "\r\n");
      if (len != strlen(TX_RECORDING_HEADER) || strncmp(line, TX_RECORDING_HEADER, len) != 0)
        problem = "expected the header " TX_RECORDING_HEADER;
      header = true;
    } else if (r->count == TX_RECORDING_MAX_ROWS) problem = "more than 10000000 rows";
    else {
      if (r->count == cap) {
        tx_recording_row* grown = realloc(r->rows, 2 * cap * sizeof *grown);
        if (!grown) {
          problem = "out of memory";
          break;
        }
        r->rows = grown, cap *= 2;
      }
      tx_recording_row* w = &r->rows[r->count];
      problem = parse_row(line, w);
      if (!problem && r->count) {
        double gap = w->t - r->rows[r->count - 1].t;
        if (!(gap > 0)) problem = "t_s must increase from row to row";
        else if (gap > 1e-3 + 1e-9) problem = "more than 1 ms after the row before (recordings are 1 kHz or faster)";
      }
      r->count++;
    }
  }
  bool read_error = ferror(f);
  fclose(f);
  if (!problem && read_error) problem = "read error", lineno = 0;
  if (!problem && !header) problem = "no header line " TX_RECORDING_HEADER, lineno = 0;
  if (!problem && r->count < 2) problem = "fewer than 2 rows", lineno = 0;
  if (problem) {
    if (lineno) tx_set_error("%s:%d: %s", path, lineno, problem);
    else tx_set_error("%s: %s", path, problem);
    tx_recording_free(r);
    return false;
  }
  r->cap = cap;
  return true;
}
