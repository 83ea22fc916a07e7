// Internal: what the skin-paper study measures in one recorded run: the
// contact, the rupture, the linearity of force against displacement before
// it, how fast the force falls to zero, how steady a sliding force is, how
// smooth a force is, and the largest step between two haptic ticks.
//
// A run is a series of haptic ticks (1 kHz): time, the HIP position and the
// force along one axis (the pushing axis y, or the sliding axis), the rays in
// contact, the pierced flag and the skin's torn-link count.
#ifndef TX_SCENARIOS_STUDIES_SKIN_METRICS_H
#define TX_SCENARIOS_STUDIES_SKIN_METRICS_H

#include <stdbool.h>

typedef struct tx_skin_series {
  int n;                  // ticks
  const double* t;        // (n) s
  const double* pos;      // (n) m, HIP position along the pushing axis
  const double* force;    // (n) N, force along the pushing axis
  const double* tangent;  // (n) N, force along the sliding axis (NULL if none)
  const double* contacts; // (n) rays in contact
  const double* pierced;  // (n) 1 once the HIP is through
  const double* torn;     // (n) links torn so far
  const double* skin_t;   // (n) s, time of the skin publish the force was computed on
} tx_skin_series;

typedef struct tx_skin_metrics {
  int contact;            // first tick in contact, -1 if never
  int rupture;            // first tick after contact that is pierced, or out of contact with links torn; -1 if never
  double contact_pos;     // m, HIP position at first contact (NaN without)
  double peak;            // N, largest |force| from contact to rupture (or to the end)
  double r2;              // linear fit of force on position over contact .. rupture: R^2 (NaN if < 3 ticks)
  double slope;           // N/m, that fit's slope
  double zero_after_s;    // s, from the skin publish that showed the rupture to the first tick of zero force (NaN if none)
  double max_step;        // N, largest |force[i+1] - force[i]| from contact to rupture (excluded)
  double roughness;       // 1, RMS of the second difference of force over contact .. rupture (a slide: its
                          // steady part), over the peak
  double tangent_mean;    // N, mean tangential force over the steady part of a slide (NaN without tangent)
  double tangent_cv;      // 1, how much the 0.5 s means of that force vary: their std over their mean
} tx_skin_metrics;

// the metrics of a run; steady_from/steady_to (s) bound the sliding phase for tangent_*
tx_skin_metrics tx_skin_measure(const tx_skin_series* s, double steady_from, double steady_to);

// Convergence of one quantity along a refinement path (skin-accuracy): the
// levels refine by a constant ratio, coarsest first. From the three finest,
// d1 = q[n-2] - q[n-3] and d2 = q[n-1] - q[n-2]: when both have the same sign
// and |d2| < |d1| the path is in its asymptotic range, the observed order is
// p = ln(d1 / d2) / ln(ratio) and the Richardson reference is
// q[n-1] + d2 / (ratio^p - 1). Below p = 0.5 (steps shrinking by less than
// 1 / sqrt(2) at ratio 2) that correction is more than 2.4 times the last
// step and is not trusted. Otherwise, and when the steps do not shrink, the
// finest level stands in for the reference.
typedef enum tx_conv_status {
  TX_CONV_CONVERGING = 0, // same sign, shrinking steps: p > 0, Richardson reference
  TX_CONV_CONSTANT,       // d1 = d2 = 0 (within 1e-9 of the values): the quantity does not change along the path
  TX_CONV_OSCILLATING,    // the steps change sign (or only the last is 0)
  TX_CONV_DIVERGING,      // the steps do not shrink: p <= 0
  TX_CONV_MISSING,        // fewer than 3 levels, or a level without a value
  TX_CONV_SLOW,           // same sign, shrinking, but 0 < p < 0.5: no extrapolation
} tx_conv_status;

typedef struct tx_convergence {
  tx_conv_status status;
  double p;         // observed order (NaN unless CONVERGING, SLOW or DIVERGING)
  double reference; // Richardson reference, or the finest level when not CONVERGING (NaN when MISSING)
  bool monotone;    // the error against the reference falls at every level
} tx_convergence;

// err (n, may be NULL): |q[l] - reference| / |reference| per level
tx_convergence tx_converge(const double* q, int n, double ratio, double* err);
const char* tx_conv_status_name(tx_conv_status s);

#endif
