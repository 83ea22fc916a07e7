// PNG line plots through PLplot's pngcairo driver.
#include "plot.h"

#include <tactus/config.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// a palette that reads on white: blue, orange, green, red, purple, brown, pink, grey, olive, cyan, ...
static const int palette[16][3] = {{255, 255, 255}, {31, 119, 180}, {255, 127, 14}, {44, 160, 44},  {214, 39, 40},
                                   {148, 103, 189}, {140, 86, 75},  {227, 119, 194}, {127, 127, 127}, {188, 189, 34},
                                   {23, 190, 207},  {0, 0, 128},    {128, 0, 0},    {0, 128, 128},  {90, 90, 90},
                                   {0, 0, 0}};

void tx_plot_color(int index, int rgb[3]) {
  if (index < 0 || index > 15) index = 15;
  for (int c = 0; c < 3; c++) rgb[c] = palette[index][c];
}

#if TX_WITH_PLPLOT
#include <plplot.h>

// the data range over every series, in the plotted (possibly log10) space
static void range(const tx_plot* p, bool x, bool log_axis, double* lo, double* hi) {
  *lo = INFINITY, *hi = -INFINITY;
  for (int s = 0; s < p->nseries; s++)
    for (int i = 0; i < p->series[s].n; i++) {
      double v = x ? p->series[s].x[i] : p->series[s].y[i];
      if (log_axis) v = v > 0 ? log10(v) : NAN;
      if (isfinite(v)) *lo = fmin(*lo, v), *hi = fmax(*hi, v);
    }
  if (!(*lo <= *hi)) *lo = 0, *hi = 1;
  double pad = (*hi - *lo) * 0.05 + (log_axis ? 0.1 : (*hi == *lo ? fmax(fabs(*hi) * 0.1, 1e-9) : 0));
  *lo -= pad, *hi += pad;
}

// one panel in the current subpage: frame, grid, labels, lines, legend at the right
static void panel(const tx_plot* p, double label_gap) {
  double x0, x1, y0, y1;
  range(p, true, p->log_x, &x0, &x1);
  range(p, false, p->log_y, &y0, &y1);
  pladv(0);
  plschr(0, 0.8);
  // the legend goes under the x label: all series in one row when their labels are short, else two columns
  int nlabels = p->nseries < TX_PLOT_SERIES_MAX ? p->nseries : TX_PLOT_SERIES_MAX, chars = 0;
  for (int s = 0; s < nlabels; s++) chars += (int)strlen(p->series[s].label) + 6;
  int ncol = chars <= 60 ? nlabels : 2, nrow = nlabels ? (nlabels + ncol - 1) / ncol : 0;
  double bottom = 0.12 + label_gap * 0.5 + 0.05 * nrow, top = label_gap > 0.12 ? 0.86 : 0.90;
  plvpor(0.17, 0.95, bottom, top);
  plwind(x0, x1, y0, y1);
  // a light grid under everything, then the frame and the numbers in black
  plcol0(14);
  plwidth(0.5);
  const char* xopt = p->log_x ? "ghl" : "g";
  const char* yopt = p->log_y ? "ghl" : "g";
  plbox(xopt, 0, 0, yopt, 0, 0);
  plcol0(15);
  plwidth(1);
  plbox(p->log_x ? "bcnstl" : "bcnst", 0, 0, p->log_y ? "bcnstlv" : "bcnstv", 0, 0);
  pllab(p->x_label, p->y_label, p->title);

  const char* texts[TX_PLOT_SERIES_MAX];
  PLINT opts[TX_PLOT_SERIES_MAX], colors[TX_PLOT_SERIES_MAX], styles[TX_PLOT_SERIES_MAX],
      symbol_numbers[TX_PLOT_SERIES_MAX];
  PLFLT widths[TX_PLOT_SERIES_MAX], scales[TX_PLOT_SERIES_MAX];
  const char* symbols[TX_PLOT_SERIES_MAX];
  int nleg = 0;
  for (int s = 0; s < p->nseries; s++) {
    const tx_plot_series* se = &p->series[s];
    double* x = malloc(sizeof(double) * (size_t)(se->n ? se->n : 1));
    double* y = malloc(sizeof(double) * (size_t)(se->n ? se->n : 1));
    if (!x || !y) {
      free(x), free(y);
      continue;
    }
    for (int i = 0; i < se->n; i++) {
      x[i] = p->log_x ? log10(se->x[i]) : se->x[i];
      y[i] = p->log_y ? log10(se->y[i]) : se->y[i];
    }
    plcol0(se->color);
    plwidth(2);
    if (se->points) plpoin(se->n, x, y, 4);
    else plline(se->n, x, y);
    free(x), free(y);
    if (nleg < TX_PLOT_SERIES_MAX) {
      texts[nleg] = se->label;
      opts[nleg] = se->points ? PL_LEGEND_SYMBOL : PL_LEGEND_LINE;
      colors[nleg] = se->color;
      styles[nleg] = 1;
      widths[nleg] = 2;
      scales[nleg] = 1;
      symbol_numbers[nleg] = 1;
      symbols[nleg] = "#(850)";
      nleg++;
    }
  }
  plwidth(1);
  PLFLT lw, lh;
  plcol0(15);
  if (!nleg) return;
  pllegend(&lw, &lh, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX, PL_POSITION_BOTTOM | PL_POSITION_OUTSIDE,
           0.0, label_gap / (top - bottom), 0.06, 0, 15, 1, nrow, ncol, nleg, opts, 0.6, 0.8, 1.4, 0, colors, texts, NULL, NULL,
           NULL, NULL,
           colors, styles, widths, colors, scales, symbol_numbers, symbols);
}

static int render(const char* path, const tx_plot* panels, int count, int columns, int pw, int ph, char* err, size_t n) {
  if (count < 1 || columns < 1) return snprintf(err, n, "%s: no panels", path), -1;
  FILE* probe = fopen(path, "wb"); // PLplot reports a bad path on stderr only
  if (!probe) return snprintf(err, n, "%s: cannot be written", path), -1;
  fclose(probe);
  int cols = count < columns ? count : columns, rows = (count + cols - 1) / cols;
  char geometry[32];
  snprintf(geometry, sizeof geometry, "%dx%d", pw * cols, ph * rows);
  plsdev("pngcairo");
  plsfnam(path);
  plsetopt("geometry", geometry);
  plscmap0n(16);
  for (int i = 0; i < 16; i++) plscol0(i, palette[i][0], palette[i][1], palette[i][2]);
  plscol0(14, 215, 215, 215); // the grid
  plssub(cols, rows);
  plinit();
  // the x label sits a fixed number of character heights under the axis: more of a small panel
  for (int i = 0; i < count; i++) panel(&panels[i], count > 1 ? 0.17 : 0.11);
  plend();
  return 0;
}

int tx_plot_png(const char* path, const tx_plot* p, char* err, size_t n) { return render(path, p, 1, 1, 800, 600, err, n); }

int tx_plot_png_panels(const char* path, const tx_plot* panels, int count, int columns, char* err, size_t n) {
  return render(path, panels, count, columns, 640, 480, err, n);
}
#else
int tx_plot_png(const char* path, const tx_plot* p, char* err, size_t n) {
  (void)p;
  return snprintf(err, n, "%s: not written: this build has no PLplot (TX_WITH_PLPLOT=OFF)", path), -1;
}
int tx_plot_png_panels(const char* path, const tx_plot* panels, int count, int columns, char* err, size_t n) {
  (void)panels, (void)count, (void)columns;
  return snprintf(err, n, "%s: not written: this build has no PLplot (TX_WITH_PLPLOT=OFF)", path), -1;
}
#endif
