// The needle in voxel tissue: gauges and tips, the force of eq. 9 against its
// three terms, resistance on the way in and friction reversed on the way
// out, puncture and cutting with damage, a bevel's side force, the energy
// bound, determinism, and bad input.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "model/error.h"
#include "controllers/voxel/needle.h"
#include "studies/experiments/needle_fit.h"
#include "tactus/model.h"

#include <math.h>
#include <string.h>

static const double ident[4] = {1, 0, 0, 0};

// the needle-fit block (5 mm, top at y = 0) and its needle
static void make(tx_voxel_tissue* t, tx_voxel_needle* n, const tx_needle_fit_params* p, tx_needle_tip tip) {
  tx_voxel_tissue_def td;
  tx_voxel_needle_def nd;
  tx_needle_fit_defs(p, &td, &nd);
  nd.tip = tip;
  assert_true(tx_voxel_tissue_init(t, &td));
  assert_true(tx_voxel_needle_init(n, &nd, t));
}

static void unmake(tx_voxel_tissue* t, tx_voxel_needle* n) {
  tx_voxel_needle_fini(n);
  tx_voxel_tissue_fini(t);
}

// the tip at depth z (m) below the top face, on the block's centre line
static bool place(tx_voxel_needle* n, tx_voxel_tissue* t, double z) {
  double tip[3] = {0, -z, 0};
  return tx_voxel_needle_step(n, t, tip, ident, 1e-3);
}

static void gauges_and_tips(void** state) {
  (void)state;
  assert_true(fabs(tx_needle_gauge_diameter(18) - 1.27e-3) < 1e-12);
  assert_true(fabs(tx_needle_gauge_diameter(22) - 0.718e-3) < 1e-12);
  assert_true(tx_needle_gauge_diameter(9) == 0 && tx_needle_gauge_diameter(35) == 0);
  for (int g = 11; g <= 34; g++) assert_true(tx_needle_gauge_diameter(g) < tx_needle_gauge_diameter(g - 1));
  tx_needle_tip tip;
  assert_true(tx_needle_tip_parse("bevel", &tip) && tip == TX_NEEDLE_BEVEL);
  assert_true(tx_needle_tip_parse("blunt", &tip) && tip == TX_NEEDLE_BLUNT);
  assert_false(tx_needle_tip_parse("sharp", &tip));
  assert_false(tx_needle_tip_parse(NULL, &tip));
  assert_string_equal(tx_needle_tip_name(TX_NEEDLE_CONICAL), "conical");
}

// every field refused with its name when out of range or not finite
static void bad_definitions_refused(void** state) {
  (void)state;
  const tx_voxel_needle_def good = tx_voxel_needle_def_default();
  assert_int_equal(tx_voxel_needle_def_check(&good), 0);
  tx_voxel_needle_def d;
#define REFUSED(field, value, name)                                   \
  d = good;                                                           \
  d.field = value;                                                    \
  assert_int_equal(tx_voxel_needle_def_check(&d), -1);               \
  assert_non_null(strstr(tx_error(), name));
  REFUSED(gauge, 9, "gauge");
  REFUSED(gauge, 35, "gauge");
  REFUSED(tip_angle_deg, 0, "tip_angle_deg");
  REFUSED(tip_angle_deg, NAN, "tip_angle_deg");
  REFUSED(length, -1, "length");
  REFUSED(friction, -0.1, "friction");
  REFUSED(friction, INFINITY, "friction");
  REFUSED(rupture_force, 0, "rupture_force");
  REFUSED(cutting_force, NAN, "cutting_force");
  REFUSED(load_time, 0, "load_time");
  REFUSED(axis[1], -2, "unit");
  REFUSED(side[0], NAN, "finite");
  REFUSED(tip, (tx_needle_tip)7, "tip");
  d = good;
  d.side[0] = 0, d.side[1] = 1; // along the axis
  assert_int_equal(tx_voxel_needle_def_check(&d), -1);
  assert_non_null(strstr(tx_error(), "normal"));
#undef REFUSED
  // init refuses too, and a non-finite pose or bad dt changes nothing
  tx_voxel_tissue t;
  tx_voxel_needle n;
  tx_needle_fit_params p = tx_needle_fit_params_default();
  make(&t, &n, &p, TX_NEEDLE_CONICAL);
  d = good;
  d.gauge = 40;
  tx_voxel_needle other;
  assert_false(tx_voxel_needle_init(&other, &d, &t));
  assert_non_null(strstr(tx_error(), "gauge"));
  assert_true(place(&n, &t, 1e-3));
  double before[3];
  memcpy(before, n.tip1, sizeof before);
  double nan_tip[3] = {0, NAN, 0}, zero_q[4] = {0, 0, 0, 0}, tip[3] = {0, 0, 0};
  assert_false(tx_voxel_needle_step(&n, &t, nan_tip, ident, 1e-3));
  assert_false(tx_voxel_needle_step(&n, &t, tip, zero_q, 1e-3));
  assert_false(tx_voxel_needle_step(&n, &t, tip, ident, 0));
  assert_false(tx_voxel_needle_step(&n, &t, tip, ident, NAN));
  assert_true(memcmp(before, n.tip1, sizeof before) == 0);
  unmake(&t, &n);
}

// above the block nothing touches; the depth is measured from the top face
static void outside_touches_nothing(void** state) {
  (void)state;
  tx_voxel_tissue t;
  tx_voxel_needle n;
  tx_needle_fit_params p = tx_needle_fit_params_default();
  make(&t, &n, &p, TX_NEEDLE_CONICAL);
  for (int k = 0; k < 20; k++) assert_true(place(&n, &t, -1e-3 + k * 1e-5));
  assert_int_equal(n.contacts, 0);
  assert_true(n.force[0] == 0 && n.force[1] == 0 && n.force[2] == 0);
  assert_int_equal(t.n_awake, 0);
  assert_true(fabs(tx_voxel_needle_depth(&n, &t) - (-1e-3 + 19e-5)) < 1e-12);
  // a needle beside the block: its axis misses the block, the depth is minus
  // the distance to it (17.5 mm from x = 20 mm to the face at 2.5 mm)
  double tip[3] = {0.02, 0, 0};
  assert_true(tx_voxel_needle_step(&n, &t, tip, ident, 1e-3));
  assert_true(fabs(tx_voxel_needle_depth(&n, &t) + 0.0175) < 1e-12);
  unmake(&t, &n);
}

// in at 3 mm/s: the force resists (up, +y), grows before the puncture, is the
// sum of eq. 9's terms, the puncture cuts voxels (damaged, smaller) and the
// cutting term takes over; out again: friction pulls the other way
static void insert_puncture_retract(void** state) {
  (void)state;
  tx_voxel_tissue t;
  tx_voxel_needle n;
  tx_needle_fit_params p = tx_needle_fit_params_default();
  make(&t, &n, &p, TX_NEEDLE_CONICAL);
  double z = -0.5e-3, f_at_1mm = 0, stiff_max = 0, cut_sum = 0, fric_in = 0, fric_out = 0;
  bool punctured_seen = false;
  double energy_margin = INFINITY;
  while (z < 3.5e-3) {
    z += 3e-6;
    assert_true(place(&n, &t, z));
    for (int a = 0; a < 3; a++)
      assert_true(fabs(n.force[a] - (n.stiffness[a] + n.friction[a] + n.cutting[a])) <= 1e-12 * (1 + fabs(n.force[a])));
    if (fabs(z - 1e-3) < 1.5e-6) f_at_1mm = n.force[1];
    if (!n.punctured) stiff_max = fmax(stiff_max, n.stiffness[1]);
    else punctured_seen = true, cut_sum += n.cutting[1], fric_in += n.friction[1];
    energy_margin = fmin(energy_margin, 2 * n.energy_in - tx_voxel_tissue_energy(&t));
  }
  assert_true(f_at_1mm > 0.01);           // resists: pushes the needle back out
  assert_true(stiff_max > 2 * f_at_1mm);  // and grows with depth before the puncture
  assert_true(punctured_seen && n.cuts > 0);
  assert_true(cut_sum > 0 && fric_in > 0); // cutting and friction both resist the way in
  int damaged = 0;
  for (int i = 0; i < t.n; i++)
    if (n.cut[i]) {
      damaged++;
      assert_true(t.damage[i] > 0 && t.radius[i] < t.radius0[i]);
    }
  assert_true(damaged > 0);
  assert_true(energy_margin > -1e-12); // the block never held more than twice the needle's work
  // out again at 3 mm/s: friction now pulls the needle into the tissue (-y)
  int pulls = 0, steps = 0;
  while (z > 0.5e-3) {
    z -= 3e-6;
    assert_true(place(&n, &t, z));
    fric_out += n.friction[1];
    pulls += n.friction[1] < 0;
    steps++;
  }
  assert_true(fric_out < 0 && pulls > steps / 2);
  unmake(&t, &n);
}

// a bevel pushes voxels toward its side, so the tissue pushes the needle the
// other way; a conical tip feels far less to the side
static void bevel_pushes_aside(void** state) {
  (void)state;
  tx_needle_fit_params p = tx_needle_fit_params_default();
  double side[2] = {0, 0}, axial[2] = {0, 0};
  const tx_needle_tip tips[2] = {TX_NEEDLE_BEVEL, TX_NEEDLE_CONICAL};
  for (int k = 0; k < 2; k++) {
    tx_voxel_tissue t;
    tx_voxel_needle n;
    make(&t, &n, &p, tips[k]);
    for (double z = -0.2e-3; z < 1.2e-3; z += 3e-6) {
      assert_true(place(&n, &t, z));
      side[k] += n.force[0], axial[k] += n.force[1];
    }
    unmake(&t, &n);
  }
  assert_true(side[0] < -0.2 * axial[0]);           // side (+x) pushed: the needle is pushed to -x
  assert_true(fabs(side[1]) < 0.1 * fabs(side[0])); // symmetric tip
}

// two runs of the same insertion give the same forces, bit for bit
static void deterministic(void** state) {
  (void)state;
  tx_needle_fit_params p = tx_needle_fit_params_default();
  double sum[2][3] = {{0}};
  for (int r = 0; r < 2; r++) {
    tx_voxel_tissue t;
    tx_voxel_needle n;
    make(&t, &n, &p, TX_NEEDLE_CONICAL);
    for (double z = -0.2e-3; z < 2.5e-3; z += 3e-6) {
      assert_true(place(&n, &t, z));
      for (int a = 0; a < 3; a++) sum[r][a] += n.force[a] * (1 + z);
    }
    unmake(&t, &n);
  }
  assert_true(memcmp(sum[0], sum[1], sizeof sum[0]) == 0);
}

// the needle turned: pointing along +x (quaternion of -90 degrees about z),
// entering the block's -x face, it is resisted along -x
static void turned_needle(void** state) {
  (void)state;
  tx_voxel_tissue t;
  tx_voxel_needle n;
  tx_needle_fit_params p = tx_needle_fit_params_default();
  make(&t, &n, &p, TX_NEEDLE_CONICAL);
  double s = sqrt(0.5), q[4] = {s, 0, 0, s}; // +90 about z takes -y to +x
  double fx = 0;
  for (double x = -3e-3; x < -1e-3; x += 3e-6) {
    double tip[3] = {x, -2.5e-3, 0};
    assert_true(tx_voxel_needle_step(&n, &t, tip, q, 1e-3));
    fx += n.force[0];
  }
  assert_true(fabs(n.dir[0] - 1) < 1e-12);
  assert_true(fx < 0);
  assert_true(fabs(tx_voxel_needle_depth(&n, &t) - (-1e-3 + 2.5e-3)) < 1e-5);
  unmake(&t, &n);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(gauges_and_tips),       cmocka_unit_test(bad_definitions_refused),
      cmocka_unit_test(outside_touches_nothing), cmocka_unit_test(insert_puncture_retract),
      cmocka_unit_test(bevel_pushes_aside),    cmocka_unit_test(deterministic),
      cmocka_unit_test(turned_needle),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
