// Internal: PNG line plots with axes, units, a grid and a legend (PLplot,
// cairo), one panel or several side by side like the force and displacement
// figures of the suturing journal paper (Figures 15-19: force in N against
// the HIP's displacement, one line per case, a panel per experiment).
// Built without PLplot (TX_WITH_PLPLOT=OFF), the functions say so and fail,
// and callers keep their CSV and JSON.
//
//     tx_plot_series s[] = {{"r = 0.05 cm", x, f, n, false, 1}, {"r = 0.1 cm", x2, f2, n2, false, 2}};
//     tx_plot p = {"(a) piercing", "HIP displacement y (mm)", "force F_y (N)", false, false, s, 2};
//     if (tx_plot_png("force.png", &p)) ... tx_error() says why
#ifndef TX_VIEWS_PLOT_H
#define TX_VIEWS_PLOT_H

#include <stdbool.h>
#include <stddef.h>

#define TX_PLOT_SERIES_MAX 12 // series with a legend entry in one panel
#define TX_PLOT_LOG_LABELS_MAX 32

// Every length on every plot is in one unit, what a surgeon reads: positions
// and displacements in mm. Callers convert with tx_plot_length and put
// TX_PLOT_LENGTH_UNIT in their axis labels, so no two plots disagree.
#define TX_PLOT_LENGTH_UNIT "mm"
#define TX_PLOT_LENGTH_PER_M 1000.0
static inline double tx_plot_length(double metres) { return metres * TX_PLOT_LENGTH_PER_M; }

typedef struct tx_plot_series {
  const char* label;  // legend entry
  const double* x;
  const double* y;
  int n;
  bool points;        // markers instead of a line
  int color;          // palette index 1-14 (tx_plot_color), 15 is black
} tx_plot_series;
// In a panel the k-th line series gets the k-th line style (solid, dashes,
// dots, ...) and the k-th marker series the k-th marker (circle, square,
// triangle, diamond, ...), the same in the plot and its legend, so series
// that run close together or share a colour stay apart.

typedef struct tx_plot {
  const char* title;
  const char* x_label; // with units, e.g. "servo period T (ms)"
  const char* y_label;
  bool log_x, log_y;
  const tx_plot_series* series;
  int nseries;
} tx_plot;

// one panel, 800 x 600 px; 0, or -1 with the message in tx_error()
int tx_plot_png(const char* path, const tx_plot* p);
// n panels in rows of `columns`, each 640 x 480 px, one legend per panel; 0, or -1 with the message in tx_error()
int tx_plot_png_panels(const char* path, const tx_plot* panels, int count, int columns);
// the palette as RGB 0-255 (index 1-15), for anything drawn to match; every
// colour has at least 3:1 contrast against the white background
void tx_plot_color(int index, int rgb[3]);
// the values a log axis over [10^lo, 10^hi] is labelled at: every decade, and
// where that gives fewer than 3 labels also 2 and 5 times each decade, then
// every digit, then (on a short range) tenths; at most max, ascending.
// Returns the count.
int tx_plot_log_labels(double lo, double hi, double* values, int max);
// the k-th marker, as PLplot text (a Unicode glyph), for points series
const char* tx_plot_marker(int k);
// whether two series draw the same curve (same points, within 1e-9 of the
// largest value), so that one would hide the other
bool tx_plot_series_coincide(const tx_plot_series* a, const tx_plot_series* b);

#endif
