// PNG line plots through PLplot's pngcairo driver.
#include "plot.h"

#include "../model/error.h"

#include <tactus/config.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// a palette that reads on white, none paler than 3:1 contrast (a thin line or
// a small marker in a light yellow or cyan vanishes): blue, dark orange,
// green, red, purple, brown, magenta, grey, olive, teal, navy, maroon, ...
static const int palette[16][3] = {{255, 255, 255}, {31, 119, 180}, {213, 94, 0},   {0, 128, 0},    {214, 39, 40},
                                   {128, 80, 180},  {140, 86, 75},  {190, 60, 150}, {110, 110, 110}, {128, 128, 0},
                                   {0, 130, 150},   {0, 0, 128},    {128, 0, 0},    {0, 128, 128},  {90, 90, 90},
                                   {0, 0, 0}};

void tx_plot_color(int index, int rgb[3]) {
  if (index < 0 || index > 15) index = 15;
  for (int c = 0; c < 3; c++) rgb[c] = palette[index][c];
}

// open circle, square, triangle, then filled square, triangles: outlines show what
// lies under them (Hershey glyphs, which PLplot centres on the point)
static const char* const markers[] = {"#(840)", "#(841)", "#(842)", "#(851)", "#(852)", "#(854)", "#(853)", "#(855)"};
const char* tx_plot_marker(int k) { return markers[(k < 0 ? 0 : k) % 8]; }

int tx_plot_log_labels(double lo, double hi, double* values, int max) {
  static const int steps[3][10] = {{1}, {1, 2, 5}, {1, 2, 3, 4, 5, 6, 7, 8, 9}};
  static const int nsteps[3] = {1, 3, 9};
  int n = 0;
  if (!(lo <= hi) || !isfinite(lo) || !isfinite(hi) || max < 1) return 0;
  for (int set = 0; set < 3; set++) {
    n = 0;
    for (int k = (int)floor(lo); k <= (int)ceil(hi) && n < max; k++)
      for (int m = 0; m < nsteps[set] && n < max; m++) {
        double v = steps[set][m] * pow(10, k), l = log10(v);
        if (l >= lo - 1e-9 && l <= hi + 1e-9) values[n++] = v;
      }
    if (n >= 3) return n;
  }
  // under a decade with fewer than 3 digits in it: tenths, at most 8 of them
  double tenths[200];
  int nt = 0;
  for (int k = (int)floor(lo); k <= (int)ceil(hi) && nt < 200; k++)
    for (int m = 10; m < 100 && nt < 200; m++) {
      double v = m * pow(10, k - 1), l = log10(v);
      if (l >= lo - 1e-9 && l <= hi + 1e-9) tenths[nt++] = v;
    }
  if (nt <= n) return n;
  int stride = (nt + 7) / 8;
  n = 0;
  for (int i = 0; i < nt && n < max; i += stride) values[n++] = tenths[i];
  return n;
}

bool tx_plot_series_coincide(const tx_plot_series* a, const tx_plot_series* b) {
  if (a->n != b->n) return false;
  double scale = 0;
  for (int i = 0; i < a->n; i++) scale = fmax(scale, fmax(fmax(fabs(a->x[i]), fabs(a->y[i])), fmax(fabs(b->x[i]), fabs(b->y[i]))));
  double tol = 1e-9 * scale;
  for (int i = 0; i < a->n; i++)
    if (!(fabs(a->x[i] - b->x[i]) <= tol && fabs(a->y[i] - b->y[i]) <= tol)) return false;
  return true;
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
  // values equal but for rounding (3.3 and 3.2999999999) are one value: on a
  // span a millionth of their size PLplot's ticks no longer advance, and it
  // drew grid lines for ever
  if (!log_axis && *hi - *lo <= 1e-6 * fmax(fabs(*hi), fabs(*lo))) *lo = *hi = 0.5 * (*lo + *hi);
  double pad = (*hi - *lo) * 0.05 + (log_axis ? 0.1 : (*hi == *lo ? fmax(fabs(*hi) * 0.1, 1e-9) : 0));
  *lo -= pad, *hi += pad;
}

// a number on a log axis: plain where every label of the axis reads well so
// (0.02, 0.05, 0.1 or 200, 5000), else m x 10^k
static void log_label_text(double v, bool plain, char* out, size_t n) {
  if (plain) {
    snprintf(out, n, "%g", v);
    return;
  }
  int k = (int)floor(log10(v) + 1e-9), m = (int)lround(v / pow(10, k));
  if (m == 1) snprintf(out, n, "10#u%d#d", k);
  else snprintf(out, n, "%d#[0x00d7]10#u%d#d", m, k);
}

static void log_axis_labels(double lo, double hi, bool x_axis) {
  double v[TX_PLOT_LOG_LABELS_MAX];
  int n = tx_plot_log_labels(lo, hi, v, TX_PLOT_LOG_LABELS_MAX);
  bool plain = true;
  for (int i = 0; i < n; i++) plain &= v[i] >= 1e-3 && v[i] < 1e5;
  char text[64];
  for (int i = 0; i < n; i++) {
    double at = (log10(v[i]) - lo) / (hi - lo);
    log_label_text(v[i], plain, text, sizeof text);
    if (x_axis) plmtex("b", 1.6, at, 0.5, text);
    else plmtex("lv", 0.7, at, 1.0, text);
  }
}

// one panel in the current subpage: frame, grid, labels, lines, legend at the right
static void panel(const tx_plot* p, double label_gap) {
  double x0, x1, y0, y1;
  range(p, true, p->log_x, &x0, &x1);
  range(p, false, p->log_y, &y0, &y1);
  pladv(0);
  plschr(0, 0.8);
  // the legend goes under the x label: all series in one row when their labels are short, else two
  // columns, or one when two of the longest would not fit across the page
  int nlabels = p->nseries < TX_PLOT_SERIES_MAX ? p->nseries : TX_PLOT_SERIES_MAX, chars = 0, longest = 0;
  for (int s = 0; s < nlabels; s++) {
    int len = (int)strlen(p->series[s].label);
    chars += len + 6;
    if (len > longest) longest = len;
  }
  int ncol = chars <= 60 ? nlabels : longest > 34 ? 1 : 2, nrow = nlabels ? (nlabels + ncol - 1) / ncol : 0;
  double bottom = 0.12 + label_gap * 0.5 + (ncol == 1 ? 0.035 : 0.05) * nrow, top = label_gap > 0.12 ? 0.86 : 0.90;
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
  // PLplot labels a log axis at decades only, which leaves one label on a
  // short range: log axes get theirs from tx_plot_log_labels instead
  plbox(p->log_x ? "bcstl" : "bcnst", 0, 0, p->log_y ? "bcstl" : "bcnstv", 0, 0);
  if (p->log_x) log_axis_labels(x0, x1, true);
  if (p->log_y) log_axis_labels(y0, y1, false);
  pllab(p->x_label, p->y_label, p->title);

  const char* texts[TX_PLOT_SERIES_MAX];
  PLINT opts[TX_PLOT_SERIES_MAX], colors[TX_PLOT_SERIES_MAX], styles[TX_PLOT_SERIES_MAX],
      symbol_numbers[TX_PLOT_SERIES_MAX];
  PLFLT widths[TX_PLOT_SERIES_MAX], scales[TX_PLOT_SERIES_MAX];
  const char* symbols[TX_PLOT_SERIES_MAX];
  int nleg = 0, nlines = 0, npoints = 0;
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
    // the legend draws each entry as the plot does: same style, same glyph
    int style = se->points ? 1 : 1 + nlines++ % 8;
    const char* marker = se->points ? tx_plot_marker(npoints++) : tx_plot_marker(0);
    plcol0(se->color);
    plwidth(2);
    pllsty(style);
    if (se->points) plstring(se->n, x, y, marker);
    else plline(se->n, x, y);
    pllsty(1);
    free(x), free(y);
    if (nleg < TX_PLOT_SERIES_MAX) {
      texts[nleg] = se->label;
      opts[nleg] = se->points ? PL_LEGEND_SYMBOL : PL_LEGEND_LINE;
      colors[nleg] = se->color;
      styles[nleg] = style;
      widths[nleg] = 2;
      scales[nleg] = 0.8;
      symbol_numbers[nleg] = 2; // PLplot draws a lone legend symbol off its row
      symbols[nleg] = marker;
      nleg++;
    }
  }
  plwidth(1);
  PLFLT lw, lh;
  plcol0(15);
  if (!nleg) return;
  pllegend(&lw, &lh, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX, PL_POSITION_BOTTOM | PL_POSITION_OUTSIDE,
           0.0, label_gap / (top - bottom), 0.06, 0, 15, 1, nrow, ncol, nleg, opts, 0.7, 0.8, 1.4, 0, colors, texts, NULL, NULL,
           NULL, NULL,
           colors, styles, widths, colors, scales, symbol_numbers, symbols);
}

static int render(const char* path, const tx_plot* panels, int count, int columns, int pw, int ph) {
  if (count < 1 || columns < 1) return tx_set_error("%s: no panels", path), -1;
  FILE* probe = fopen(path, "wb"); // PLplot reports a bad path on stderr only
  if (!probe) return tx_set_error("%s: cannot be written", path), -1;
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

int tx_plot_png(const char* path, const tx_plot* p) { return render(path, p, 1, 1, 800, 600); }

int tx_plot_png_panels(const char* path, const tx_plot* panels, int count, int columns) {
  return render(path, panels, count, columns, 640, 480);
}
#else
int tx_plot_png(const char* path, const tx_plot* p) {
  (void)p;
  return tx_set_error("%s: not written: this build has no PLplot (TX_WITH_PLPLOT=OFF)", path), -1;
}
int tx_plot_png_panels(const char* path, const tx_plot* panels, int count, int columns) {
  (void)panels, (void)count, (void)columns;
  return tx_set_error("%s: not written: this build has no PLplot (TX_WITH_PLPLOT=OFF)", path), -1;
}
#endif
