// Internal: the cautery-heat check (tactus study cautery-heat). The thermal
// solver (controllers/organs/thermal.h) on a block of tetrahedra against
// closed forms for a Gaussian heat source of power P and radius s in an
// infinite medium (docs/validation.md, "Heat"):
//   transient, no perfusion, from rest (erfc):
//     theta(r, t) = P / (4 pi k r) [erfc(r / sqrt(2 s^2 + 4 alpha t)) - erfc(r / (s sqrt 2))]
//   steady, with Pennes perfusion (L = sqrt(k / (w_b rho_b c_b))):
//     theta(r) = P e^(s^2 / 2L^2) / (8 pi k r) [e^(-r/L) erfc((s^2/L - r) / (s sqrt 2))
//                                               - e^(r/L) erfc((s^2/L + r) / (s sqrt 2))]
// both s -> 0: the point source's P erfc(r / sqrt(4 alpha t)) / (4 pi k r) and
// P e^(-r/L) / (4 pi k r).
#ifndef TX_STUDIES_EXPERIMENTS_CAUTERY_HEAT_H
#define TX_STUDIES_EXPERIMENTS_CAUTERY_HEAT_H

#include "../../controllers/organs/thermal.h"

#include <stdbool.h>

// the closed forms above, K above T_a; r in m (r -> 0 taken as its limit)
double tx_heat_gauss_transient(double r, double t, double power, double s, double k, double alpha);
double tx_heat_gauss_perfused(double r, double power, double s, double k, double l);

// the cube [-half, half]^3 cut into n^3 cells of 6 tetrahedra each (Kuhn's),
// every node on the centre's lattice; malloc'd x (nodes x 3) and tet (x 4)
bool tx_heat_block(double half, int n, double** x, int* nodes, int** tet, int* ntet);

typedef struct tx_heat_case {
  bool perfused;    // false: the transient erfc check; true: the perfused steady state
  double half_m;    // the block's half width, its faces held at T_a
  int cells;        // per side
  double sigma_m;   // the source's radius
  double power_w;
  double t_end_s;
  double dt_s;      // 0: the solver's stable step
  double r_eval_m;  // the error is measured within this of the centre
  tx_tissue tissue; // the liver's, perfusion 0 unless perfused
} tx_heat_case;

tx_heat_case tx_heat_case_default(bool perfused);

typedef struct tx_heat_result {
  int nodes, tets, steps;
  double h_m;       // the cell size
  double dt_s;      // the step taken
  double error;     // relative L2 (nodal volumes) within r_eval against the closed form
  double max_error; // the largest nodal error there, over the largest exact value
  double peak_k;    // the largest temperature rise, K
  double cpu_s;     // building and stepping
  double* theta;    // malloc'd (nodes): the rise, for a reference; NULL unless keep
} tx_heat_result;

// false and tx_error() on bad arguments or memory
bool tx_heat_run(const tx_heat_case* c, bool keep, tx_heat_result* r);

// the relative L2 difference of two fields on the same case's mesh within r_eval
double tx_heat_difference(const tx_heat_case* c, const double* a, const double* b);

#endif
