// PNG line plots through PLplot's pngcairo driver.
#include "plot.h"

#include <tactus/config.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

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
  double pad = (*hi - *lo) * 0.08 + (log_axis ? 0.1 : 1e-12);
  *lo -= pad, *hi += pad;
}

int tx_plot_png(const char* path, const tx_plot* p, char* err, size_t n) {
  FILE* probe = fopen(path, "wb"); // PLplot reports a bad path on stderr only
  if (!probe) return snprintf(err, n, "%s: cannot be written", path), -1;
  fclose(probe);
  plsdev("pngcairo");
  plsfnam(path);
  plsetopt("geometry", "800x600");
  plscolbg(255, 255, 255);
  plinit();
  plscol0(15, 0, 0, 0); // black for the frame and the labels
  double x0, x1, y0, y1;
  range(p, true, p->log_x, &x0, &x1);
  range(p, false, p->log_y, &y0, &y1);
  y0 -= (y1 - y0) * 0.4; // room for the legend below the data
  plcol0(15);
  plenv(x0, x1, y0, y1, 0, (p->log_x ? 10 : 0) + (p->log_y ? 20 : 0) + 2); // 2: a grid
  pllab(p->x_label, p->y_label, p->title);

  const char* texts[16];
  PLINT opts[16], colors[16], styles[16], symbol_colors[16], symbol_numbers[16];
  PLFLT widths[16], scales[16];
  const char* symbols[16];
  int nleg = p->nseries < 16 ? p->nseries : 16;
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
    if (s < 16) {
      texts[s] = se->label;
      opts[s] = se->points ? PL_LEGEND_SYMBOL : PL_LEGEND_LINE;
      colors[s] = symbol_colors[s] = se->color;
      styles[s] = 1;
      widths[s] = 2;
      scales[s] = 1;
      symbol_numbers[s] = 1;
      symbols[s] = "#(850)";
    }
  }
  PLFLT lw, lh;
  plcol0(15);
  pllegend(&lw, &lh, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX, PL_POSITION_BOTTOM | PL_POSITION_LEFT | PL_POSITION_INSIDE,
           0.02, 0.02, 0.1, 0, 15, 1, 0, 0, nleg, opts, 1.0, 1.0, 2.0, 0, colors, texts, NULL, NULL, NULL, NULL, colors,
           styles, widths, symbol_colors, scales, symbol_numbers, symbols);
  plend();
  return 0;
}
#else
int tx_plot_png(const char* path, const tx_plot* p, char* err, size_t n) {
  (void)p;
  return snprintf(err, n, "%s: not written: this build has no PLplot (TX_WITH_PLPLOT=OFF)", path), -1;
}
#endif
