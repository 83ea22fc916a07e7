// The needle's numerical guard: checkpoint, energy bound, roll back.
#include "guard.h"

#include "../../model/error.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static void save(tx_voxel_guard* g, const tx_voxel_tissue* t, double energy_in) {
  g->n_awake = t->n_awake;
  for (int w = 0; w < t->n_awake; w++) {
    int i = t->awake_list[w];
    g->awake[w] = i;
    memcpy(g->pos + 3 * w, t->pos + 3 * i, 3 * sizeof *g->pos);
    memcpy(g->vel + 3 * w, t->vel + 3 * i, 3 * sizeof *g->vel);
  }
  g->n_damaged = t->n_damaged;
  for (int k = 0; k < t->n_damaged; k++) g->damaged[k] = t->damaged[k], g->damage[k] = t->damage[t->damaged[k]];
  g->energy_in = energy_in;
}

bool tx_voxel_guard_init(tx_voxel_guard* g, const tx_voxel_tissue* t, int every) {
  memset(g, 0, sizeof *g);
  size_t un = (size_t)t->n;
  g->n = t->n;
  g->every = every < 1 ? 1 : every;
  g->awake = malloc(un * sizeof *g->awake);
  g->pos = malloc(3 * un * sizeof *g->pos);
  g->vel = malloc(3 * un * sizeof *g->vel);
  g->damaged = malloc(un * sizeof *g->damaged);
  g->damage = malloc(un * sizeof *g->damage);
  if (!g->awake || !g->pos || !g->vel || !g->damaged || !g->damage) {
    tx_voxel_guard_fini(g);
    return tx_set_error("voxel guard: out of memory for %d voxels", t->n), false;
  }
  save(g, t, 0);
  return true;
}

void tx_voxel_guard_fini(tx_voxel_guard* g) {
  free(g->awake), free(g->pos), free(g->vel), free(g->damaged), free(g->damage);
  memset(g, 0, sizeof *g);
}

bool tx_voxel_guard_check(tx_voxel_guard* g, tx_voxel_tissue* t, tx_voxel_needle* nd) {
  g->steps++;
  double e = tx_voxel_tissue_energy(t);
  bool finite = isfinite(e) && isfinite(nd->force[0] + nd->force[1] + nd->force[2]) && isfinite(nd->energy_in);
  // passivity: no more than the needle's net work, with a margin and a floor
  // far below any motion that matters (a voxel a nanometre off rest)
  double floor = 0.5 * t->def.spring * 1e-18 * t->n + 1e-30;
  bool bounded = finite && e <= 2 * fmax(nd->energy_in, 0) + floor;
  if (finite && bounded) {
    if (e > g->energy_max) g->energy_max = e;
    if (g->steps % (uint64_t)g->every == 0) save(g, t, nd->energy_in);
    return false;
  }
  // undo: every voxel to rest and undamaged, then the checkpoint's moving
  // and damaged voxels as they were (rare, so the whole block may be touched)
  size_t un = (size_t)g->n;
  memcpy(t->pos, t->pos0, 3 * un * sizeof *t->pos);
  memset(t->vel, 0, 3 * un * sizeof *t->vel);
  for (int k = 0; k < t->n_damaged; k++) {
    int i = t->damaged[k];
    t->damage[i] = 0;
    t->radius[i] = t->radius0[i];
    t->is_damaged[i] = 0;
  }
  t->n_damaged = 0;
  for (int w = 0; w < g->n_awake; w++) {
    int i = g->awake[w];
    memcpy(t->pos + 3 * i, g->pos + 3 * w, 3 * sizeof *t->pos);
    memcpy(t->vel + 3 * i, g->vel + 3 * w, 3 * sizeof *t->vel);
    tx_voxel_tissue_wake(t, i);
  }
  for (int k = 0; k < g->n_damaged; k++) tx_voxel_tissue_damage(t, g->damaged[k], g->damage[k]);
  tx_voxel_tissue_refresh_neighbours(t);
  nd->energy_in = g->energy_in;
  memset(nd->force, 0, sizeof nd->force);
  memset(nd->stiffness, 0, sizeof nd->stiffness);
  memset(nd->friction, 0, sizeof nd->friction);
  memset(nd->cutting, 0, sizeof nd->cutting);
  nd->k_axial = 0;
  g->recoveries++;
  if (!finite) g->non_finite++;
  return true;
}
