// Internal: force and position traces of a recorded device (OUT/deviceN.csv,
// written by the haptics recorder) as one PNG of three panels: (a) force
// against time, (b) tool position against time, (c) force against the
// tool's displacement from where it started, along the axis it moved most,
// as the suturing journal paper plots force against HIP displacement.
#ifndef TX_VIEWS_TRACE_PLOT_H
#define TX_VIEWS_TRACE_PLOT_H

#include <stddef.h>

typedef struct tx_trace {
  double* t;    // (n) s
  double* p[3]; // (n) tool position x, y, z, m
  double* f[3]; // (n) force sent, N
  int n;
} tx_trace;

// read t_s, px_m..pz_m, fx_n..fz_n from a device CSV; 0, or -1 with "FILE:LINE: message" in tx_error()
int tx_trace_load(const char* csv, tx_trace* t);
void tx_trace_free(tx_trace* t);
// the three-panel PNG of a device CSV; 0, or -1 with the message in tx_error()
int tx_trace_plot_png(const char* csv, const char* png);

#endif
