// The stability cases of the needle in voxel tissue.
#include "needle_stability.h"

#include "../../controllers/voxel/guard.h"
#include "needle_fit.h"

#include "../../model/error.h"

#include <tactus/model.h>

#include <math.h>
#include <string.h>

typedef struct scase {
  const char* name;
  const char* what;
  double speed; // m/s of the needle, in and out
} scase;

static const scase cases[TX_NEEDLE_STABILITY_CASES] = {
    {"baseline", "the fitted block's defaults, 3 mm/s", 3e-3},
    {"stiff", "k_s x 1e3 (20 -> 2e4 N/m), k_d unchanged", 3e-3},
    {"elastic", "e = 1: voxel and needle contacts keep all their energy", 3e-3},
    {"light", "masses x 1e-8 (1e-4 -> 1e-12 kg)", 3e-3},
    {"fast", "the needle at 1 m/s, in 4 mm and out", 1.0},
    {"overlap", "radius 0.35 mm on a 0.5 mm lattice: every neighbour overlaps 0.2 mm at rest", 3e-3},
};

bool tx_needle_stability_run(int k, double duration_s, tx_needle_stability_result* out) {
  if (k < 0 || k >= TX_NEEDLE_STABILITY_CASES) return tx_set_error("needle stability: no case %d", k), false;
  const scase* c = &cases[k];
  tx_needle_fit_params p = tx_needle_fit_params_default();
  tx_voxel_tissue_def td;
  tx_voxel_needle_def nd;
  tx_needle_fit_defs(&p, &td, &nd);
  if (k == 1) td.spring *= 1e3;
  if (k == 2) td.elasticity = 1;
  if (k == 3) td.mass *= 1e-8;
  if (k == 5) td.radius = 0.35e-3;
  tx_voxel_tissue t;
  tx_voxel_needle n;
  tx_voxel_guard g;
  if (!tx_voxel_tissue_init(&t, &td)) return false;
  if (!tx_voxel_needle_init(&n, &nd, &t)) return tx_voxel_tissue_fini(&t), false;
  if (!tx_voxel_guard_init(&g, &t, 100)) return tx_voxel_needle_fini(&n), tx_voxel_tissue_fini(&t), false;
  memset(out, 0, sizeof *out);
  out->name = c->name, out->what = c->what;
  // from 1 mm above to 4 mm deep and back, then 0.1 s still
  const double travel = 5e-3 / c->speed, wait = 0.1, total = 2 * travel + 2 * wait;
  const double len = duration_s > 0 ? fmin(duration_s, total) : total;
  const int steps = (int)ceil(len / 1e-3);
  const double q[4] = {1, 0, 0, 0};
  double work_max = 0;
  int64_t t0 = tx_mono_ns();
  for (int s = 1; s <= steps; s++) {
    double tt = s * 1e-3, y;
    if (tt < wait) y = 1e-3;
    else if (tt < wait + travel) y = 1e-3 - c->speed * (tt - wait);
    else if (tt < wait + 2 * travel) y = -4e-3 + c->speed * (tt - wait - travel);
    else y = 1e-3;
    double tip[3] = {0, y, 0};
    tx_voxel_needle_step(&n, &t, tip, q, 1e-3);
    tx_voxel_guard_check(&g, &t, &n);
    if (t.substeps > out->max_substeps) out->max_substeps = t.substeps;
    const double* f = n.force;
    double mag = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    if (!isfinite(mag)) out->nan_out++;
    else out->peak_force = fmax(out->peak_force, mag);
    work_max = fmax(work_max, n.energy_in);
  }
  for (int i = 0; i < 3 * t.n; i++)
    if (!isfinite(t.pos[i]) || !isfinite(t.vel[i])) out->nan_state++;
  out->steps = steps;
  out->energy_max = g.energy_max;
  out->energy_bound = 2 * work_max + 0.5 * td.spring * 1e-18 * t.n + 1e-30;
  out->bounded = out->energy_max <= out->energy_bound;
  out->recoveries = g.recoveries;
  out->recovered_nan = g.non_finite;
  out->voxel_faults = t.faults;
  out->cuts = n.cuts;
  out->seconds = (double)(tx_mono_ns() - t0) * 1e-9;
  tx_voxel_guard_fini(&g);
  tx_voxel_needle_fini(&n);
  tx_voxel_tissue_fini(&t);
  return true;
}
