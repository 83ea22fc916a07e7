// Internal: PNG line plots with axes, units and a legend (PLplot, cairo).
// Built without PLplot (TX_WITH_PLPLOT=OFF), tx_plot_png says so and fails,
// and callers keep their CSV and JSON.
#ifndef TX_VIEWS_PLOT_H
#define TX_VIEWS_PLOT_H

#include <stdbool.h>
#include <stddef.h>

typedef struct tx_plot_series {
  const char* label;  // legend entry
  const double* x;
  const double* y;
  int n;
  bool points;        // markers instead of a line
  int color;          // PLplot colour-map-0 index, 1-15
} tx_plot_series;

typedef struct tx_plot {
  const char* title;
  const char* x_label; // with units, e.g. "servo period T (ms)"
  const char* y_label;
  bool log_x, log_y;
  const tx_plot_series* series;
  int nseries;
} tx_plot;

// write the plot to path (PNG, 800 x 600); 0, or -1 with a message
int tx_plot_png(const char* path, const tx_plot* p, char* err, size_t n);

#endif
