// The needle's guard: a step that leaves a NaN, or more energy in the block
// than the needle put in, is undone to the checkpoint, counted, and its force
// zeroed; a healthy insertion is never undone.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/voxel/guard.h"
#include "studies/experiments/needle_fit.h"
#include "tactus/model.h"

#include <math.h>
#include <string.h>

typedef struct rig {
  tx_voxel_tissue t;
  tx_voxel_needle n;
  tx_voxel_guard g;
} rig;

static void rig_make(rig* r) {
  tx_needle_fit_params p = tx_needle_fit_params_default();
  tx_voxel_tissue_def td;
  tx_voxel_needle_def nd;
  tx_needle_fit_defs(&p, &td, &nd);
  assert_true(tx_voxel_tissue_init(&r->t, &td));
  assert_true(tx_voxel_needle_init(&r->n, &nd, &r->t));
  assert_true(tx_voxel_guard_init(&r->g, &r->t, 10));
}

static void rig_free(rig* r) {
  tx_voxel_guard_fini(&r->g);
  tx_voxel_needle_fini(&r->n);
  tx_voxel_tissue_fini(&r->t);
}

// one 1 ms step with the tip at depth z; true when the guard undid it
static bool step(rig* r, double z) {
  const double q[4] = {1, 0, 0, 0};
  double tip[3] = {0, -z, 0};
  assert_true(tx_voxel_needle_step(&r->n, &r->t, tip, q, 1e-3));
  return tx_voxel_guard_check(&r->g, &r->t, &r->n);
}

static void healthy_insertion_untouched(void** state) {
  (void)state;
  rig r;
  rig_make(&r);
  double z = -0.2e-3;
  for (int k = 0; k < 800; k++) assert_false(step(&r, z += 3e-6));
  assert_int_equal(r.g.recoveries, 0);
  assert_true(r.g.energy_max > 0 && r.g.energy_max <= 2 * r.n.energy_in);
  rig_free(&r);
}

// a voxel's velocity made NaN after a checkpoint: the next step is undone, the
// block is finite again, the force that goes out is zero
static void nan_undone(void** state) {
  (void)state;
  rig r;
  rig_make(&r);
  double z = -0.2e-3;
  for (int k = 0; k < 400; k++) step(&r, z += 3e-6);
  assert_true(r.n.contacts > 0);
  int i = r.t.awake_list[0];
  double saved_pos[3];
  memcpy(saved_pos, r.g.pos, sizeof saved_pos); // the checkpoint's first awake voxel
  r.t.vel[3 * i] = NAN;                          // after the step's own scan: reaches the energy
  r.n.force[1] = NAN;
  assert_true(tx_voxel_guard_check(&r.g, &r.t, &r.n));
  assert_int_equal(r.g.recoveries, 1);
  assert_int_equal(r.g.non_finite, 1);
  assert_true(r.n.force[0] == 0 && r.n.force[1] == 0 && r.n.force[2] == 0);
  for (int k = 0; k < 3 * r.t.n; k++) assert_true(isfinite(r.t.pos[k]) && isfinite(r.t.vel[k]));
  int j = r.g.awake[0];
  assert_true(memcmp(r.t.pos + 3 * j, saved_pos, sizeof saved_pos) == 0);
  // and the insertion goes on
  for (int k = 0; k < 50; k++) assert_false(step(&r, z += 3e-6));
  rig_free(&r);
}

// energy from nowhere (a voxel kicked without the needle doing it): undone
static void energy_blow_up_undone(void** state) {
  (void)state;
  rig r;
  rig_make(&r);
  double z = -0.2e-3;
  for (int k = 0; k < 300; k++) step(&r, z += 3e-6);
  double e_before = tx_voxel_tissue_energy(&r.t);
  r.t.vel[3 * 5 + 1] = 50; // 50 m/s on a voxel far from the needle
  tx_voxel_tissue_wake(&r.t, 5);
  assert_true(step(&r, z += 3e-6));
  assert_int_equal(r.g.recoveries, 1);
  assert_int_equal(r.g.non_finite, 0);
  assert_true(r.t.vel[3 * 5 + 1] == 0);
  assert_true(tx_voxel_tissue_energy(&r.t) <= 2 * e_before + 1e-12);
  rig_free(&r);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(healthy_insertion_untouched), cmocka_unit_test(nan_undone),
                                     cmocka_unit_test(energy_blow_up_undone)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
