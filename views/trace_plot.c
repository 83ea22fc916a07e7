// Device traces: CSV columns by name, three PLplot panels.
#include "trace_plot.h"

#include "../model/error.h"
#include "plot.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void tx_trace_free(tx_trace* t) {
  free(t->t);
  for (int i = 0; i < 3; i++) free(t->p[i]), free(t->f[i]);
  *t = (tx_trace){0};
}

int tx_trace_load(const char* csv, tx_trace* t) {
  *t = (tx_trace){0};
  FILE* f = fopen(csv, "r");
  if (!f) return tx_set_error("%s: %s", csv, strerror(errno)), -1;
  static const char* const names[7] = {"t_s", "px_m", "py_m", "pz_m", "fx_n", "fy_n", "fz_n"};
  int col[7] = {-1, -1, -1, -1, -1, -1, -1}, ncols = 0;
  char* line = NULL;
  size_t cap = 0;
  long lineno = 1;
  int rc = -1, size = 0;
  if (getline(&line, &cap, f) < 0) {
    tx_set_error("%s:1: empty file, expected a header", csv);
    goto done;
  }
  line[strcspn(line, "\r\n")] = 0;
  for (char *save = NULL, *tok = strtok_r(line, ",", &save); tok; tok = strtok_r(NULL, ",", &save), ncols++)
    for (int k = 0; k < 7; k++)
      if (strcmp(tok, names[k]) == 0) col[k] = ncols;
  for (int k = 0; k < 7; k++)
    if (col[k] < 0) {
      tx_set_error("%s:1: no column '%s'", csv, names[k]);
      goto done;
    }
  while (getline(&line, &cap, f) >= 0) {
    lineno++;
    if (t->n == size) {
      size = size ? 2 * size : 4096;
      double* grown[7];
      double** fields[7] = {&t->t, &t->p[0], &t->p[1], &t->p[2], &t->f[0], &t->f[1], &t->f[2]};
      for (int k = 0; k < 7; k++) {
        grown[k] = realloc(*fields[k], sizeof(double) * (size_t)size);
        if (grown[k]) *fields[k] = grown[k];
        else {
          tx_set_error("%s: out of memory", csv);
          goto done;
        }
      }
    }
    double v[7] = {0};
    int c = 0, got = 0;
    char* p = line;
    for (; c < ncols && p; c++) {
      char* end;
      for (int k = 0; k < 7; k++)
        if (col[k] == c) {
          // strtod reads back every double that %.17g wrote; its ERANGE on a
          // subnormal is no error, only an overflow (not finite) is
          v[k] = strtod(p, &end);
          if (end == p || (*end != ',' && *end != '\n' && *end != '\r' && *end)) {
            tx_set_error("%s:%ld: column %s: not a number", csv, lineno, names[k]);
            goto done;
          }
          if (!isfinite(v[k])) {
            tx_set_error("%s:%ld: column %s: not a finite number", csv, lineno, names[k]);
            goto done;
          }
          got++;
        }
      p = strchr(p, ',');
      if (p) p++;
    }
    if (got != 7) {
      tx_set_error("%s:%ld: expected %d columns", csv, lineno, ncols);
      goto done;
    }
    t->t[t->n] = v[0];
    for (int k = 0; k < 3; k++) t->p[k][t->n] = v[1 + k], t->f[k][t->n] = v[4 + k];
    t->n++;
  }
  if (!t->n) {
    tx_set_error("%s:2: no samples", csv);
    goto done;
  }
  rc = 0;
done:
  free(line);
  fclose(f);
  if (rc) tx_trace_free(t);
  return rc;
}

int tx_trace_plot_png(const char* csv, const char* png) {
  tx_trace t;
  if (tx_trace_load(csv, &t)) return -1;
  int rc = -1;
  double *mag = malloc(sizeof(double) * (size_t)t.n), *mm[3] = {0}, *disp = malloc(sizeof(double) * (size_t)t.n);
  for (int k = 0; k < 3; k++) mm[k] = malloc(sizeof(double) * (size_t)t.n);
  if (!mag || !disp || !mm[0] || !mm[1] || !mm[2]) {
    tx_set_error("%s: out of memory", png);
    goto done;
  }
  // the axis along which the tool travelled furthest from its start
  int axis = 0;
  double reach[3] = {0, 0, 0};
  for (int i = 0; i < t.n; i++) {
    mag[i] = sqrt(t.f[0][i] * t.f[0][i] + t.f[1][i] * t.f[1][i] + t.f[2][i] * t.f[2][i]);
    for (int k = 0; k < 3; k++) {
      mm[k][i] = tx_plot_length(t.p[k][i]);
      reach[k] = fmax(reach[k], fabs(t.p[k][i] - t.p[k][0]));
    }
  }
  for (int k = 1; k < 3; k++)
    if (reach[k] > reach[axis]) axis = k;
  for (int i = 0; i < t.n; i++) disp[i] = tx_plot_length(t.p[axis][i] - t.p[axis][0]);
  static const char* const xyz[3] = {"x", "y", "z"};
  tx_plot_series force[] = {{"F_x", t.t, t.f[0], t.n, false, 1}, {"F_y", t.t, t.f[1], t.n, false, 2},
                            {"F_z", t.t, t.f[2], t.n, false, 3}, {"|F|", t.t, mag, t.n, false, 15}};
  tx_plot_series pos[] = {{"x", t.t, mm[0], t.n, false, 1}, {"y", t.t, mm[1], t.n, false, 2},
                          {"z", t.t, mm[2], t.n, false, 3}};
  char flabel[32], dlabel[64], ftitle[64];
  snprintf(flabel, sizeof flabel, "F_%s", xyz[axis]);
  tx_plot_series fd[] = {{flabel, disp, t.f[axis], t.n, false, 4}};
  snprintf(dlabel, sizeof dlabel, "tool displacement along %s (" TX_PLOT_LENGTH_UNIT ")", xyz[axis]);
  snprintf(ftitle, sizeof ftitle, "(c) force against displacement");
  char ylabel[32];
  snprintf(ylabel, sizeof ylabel, "force F_%s (N)", xyz[axis]);
  tx_plot panels[3] = {{"(a) force sent to the device", "time t (s)", "force (N)", false, false, force, 4},
                       {"(b) tool position", "time t (s)", "position (" TX_PLOT_LENGTH_UNIT ")", false, false, pos, 3},
                       {ftitle, dlabel, ylabel, false, false, fd, 1}};
  rc = tx_plot_png_panels(png, panels, 3, 3);
done:
  free(mag);
  free(disp);
  for (int k = 0; k < 3; k++) free(mm[k]);
  tx_trace_free(&t);
  return rc;
}
