// Spherical voxel tissue: collisions by eq. 5 against conservation laws, the
// time of impact against its closed form, the Vieta cull against brute force,
// the neighbour lists against all pairs, the spring-damper against its closed
// form, damage and recovery, bad input, and a 20,000-voxel block stepped
// without allocation.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "model/error.h"
#include "controllers/voxel/tissue.h"
#include "tactus/model.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "tests/alloc_count.h"

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

// two voxels 1 mm apart along x, radius 0.2 mm, no springs
static tx_voxel_tissue_def pair_def(double e) {
  tx_voxel_tissue_def d = tx_voxel_tissue_def_default();
  d.count[0] = 2, d.count[1] = d.count[2] = 1;
  d.block_size[0] = 2e-3, d.block_size[1] = d.block_size[2] = 1e-3;
  d.radius = 0.2e-3;
  d.spring = 0, d.damper = 0;
  d.elasticity = e;
  return d;
}

static void momentum_energy(const tx_voxel_tissue* t, double mom[3], double* ke) {
  mom[0] = mom[1] = mom[2] = 0;
  *ke = 0;
  for (int i = 0; i < t->n; i++)
    for (int a = 0; a < 3; a++) {
      double v = t->vel[3 * i + a];
      mom[a] += t->mass[i] * v;
      *ke += 0.5 * t->mass[i] * v * v;
    }
}

// the default block: valid, on its lattice, at rest, and a step at rest
// changes nothing
static void defaults_rest(void** state) {
  (void)state;
  tx_voxel_tissue_def d = tx_voxel_tissue_def_default();
  assert_int_equal(tx_voxel_tissue_def_check(&d), 0);
  tx_voxel_tissue t;
  assert_true(tx_voxel_tissue_init(&t, &d));
  assert_int_equal(t.n, 1000);
  // touching neighbours at rest: 6 across the faces inside, 3 at a corner
  int inner = (5 * 10 + 5) * 10 + 5;
  assert_int_equal(t.nbr_count[inner], 6);
  assert_int_equal(t.nbr_count[0], 3);
  assert_int_equal(t.id[inner], inner);
  assert_true(t.radius[inner] == d.radius && t.mass[inner] == d.mass && t.elasticity[inner] == d.elasticity);
  for (int k = 0; k < 100; k++) assert_true(tx_voxel_tissue_step(&t, 1e-3));
  for (int i = 0; i < 3 * t.n; i++) assert_true(t.pos[i] == t.pos0[i] && t.vel[i] == 0);
  assert_int_equal(t.rebuilds, 1);
  assert_int_equal(t.contacts, 0);
  tx_voxel_tissue_fini(&t);
}

// head-on and oblique hits of unequal masses: momentum always, kinetic
// energy when e = 1; e = 0 leaves no normal relative velocity
static void collision_conserves(void** state) {
  (void)state;
  const double es[] = {1, 0, 0.5};
  const double vy[] = {0, 0.15}; // 0: head-on; otherwise oblique
  for (size_t ie = 0; ie < 3; ie++)
    for (size_t iy = 0; iy < 2; iy++) {
      tx_voxel_tissue_def d = pair_def(es[ie]);
      tx_voxel_tissue t;
      assert_true(tx_voxel_tissue_init(&t, &d));
      t.mass[1] = 3e-7;
      t.vel[0] = 0.5, t.vel[1] = vy[iy], t.vel[3] = -0.2;
      tx_voxel_tissue_wake(&t, 0), tx_voxel_tissue_wake(&t, 1);
      double m0[3], k0, m1[3], k1;
      momentum_energy(&t, m0, &k0);
      uint64_t contacts = 0;
      bool checked = false;
      for (int s = 0; s < 20; s++) {
        double before[6];
        memcpy(before, t.vel, sizeof before);
        assert_true(tx_voxel_tissue_step(&t, 1e-4));
        contacts += t.contacts;
        if (t.contacts && !checked) {
          // the first hit: the impulse on voxel 0 points along -N, and the
          // normal relative velocity turns from -c to e c (eq. 5)
          double n[3], len = 0;
          for (int a = 0; a < 3; a++) n[a] = before[a] - t.vel[a], len += n[a] * n[a];
          len = sqrt(len);
          double c = 0, after = 0;
          for (int a = 0; a < 3; a++) {
            n[a] /= len;
            c -= (before[3 + a] - before[a]) * n[a];
            after += (t.vel[3 + a] - t.vel[a]) * n[a];
          }
          assert_true(c > 0);
          assert_true(fabs(after - es[ie] * c) <= 1e-12 * c);
          checked = true;
        }
      }
      assert_true(checked && contacts >= 1);
      momentum_energy(&t, m1, &k1);
      for (int a = 0; a < 3; a++) assert_true(fabs(m1[a] - m0[a]) <= 1e-14 * (fabs(m0[a]) + 1e-7));
      if (es[ie] == 1) {
        assert_true(fabs(k1 - k0) <= 1e-12 * k0);
        assert_int_equal(contacts, 1);
      } else {
        assert_true(k1 < k0);
      }
      tx_voxel_tissue_fini(&t);
    }
}

// the time of impact of eq. 3 against (d - sqrt(r^2 - h^2)) / u for a pair
// closing at u with offset h; and inside the block, the hit lands where the
// exchange of velocities at that time puts the voxels
static void time_of_impact_matches(void** state) {
  (void)state;
  const double d = 1e-3, r = 0.4e-3, u = 0.7;
  const double hs[] = {0, 0.1e-3, 0.3e-3};
  for (size_t k = 0; k < 3; k++) {
    double p[3] = {d, hs[k], 0}, v[3] = {-u, 0, 0}, th = -1;
    assert_true(tx_voxel_time_of_impact(p, v, r, 1e-2, &th));
    double expect = (d - sqrt(r * r - hs[k] * hs[k])) / u;
    assert_true(fabs(th - expect) <= 1e-14 * expect);
    // outside the frame, receding, or missing: no impact
    assert_false(tx_voxel_time_of_impact(p, v, r, 0.99 * expect, &th));
    double away[3] = {u, 0, 0};
    assert_false(tx_voxel_time_of_impact(p, away, r, 1, &th));
  }
  double p[3] = {d, 0.5e-3, 0}, v[3] = {-u, 0, 0}, th;
  assert_false(tx_voxel_time_of_impact(p, v, r, 1, &th));

  // equal masses, e = 1: voxel 0 at 1 m/s stops at contact and voxel 1 leaves
  tx_voxel_tissue_def def = pair_def(1);
  tx_voxel_tissue t;
  assert_true(tx_voxel_tissue_init(&t, &def));
  t.vel[0] = 1;
  tx_voxel_tissue_wake(&t, 0);
  double x0 = t.pos[0], x1 = t.pos[3];
  assert_true(tx_voxel_tissue_step(&t, 1e-3)); // hit at 0.6 ms, inside this frame
  assert_int_equal(t.contacts, 1);
  assert_true(t.substeps > 1);
  assert_true(fabs(t.pos[0] - (x0 + 0.6e-3)) <= 1e-12);
  assert_true(fabs(t.pos[3] - (x1 + 0.4e-3)) <= 1e-12);
  assert_true(fabs(t.vel[0]) <= 1e-12 && fabs(t.vel[3] - 1) <= 1e-12);
  tx_voxel_tissue_fini(&t);
}

static double uniform(uint64_t* s, double lo, double hi) {
  *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
  return lo + (hi - lo) * (double)(*s >> 11) * 0x1p-53;
}

// on random pairs: every pair that a dense sampling of the frame sees meet
// passes the Vieta test and gets an impact time before the first sample
// inside; every receding pair is culled
static void vieta_against_brute_force(void** state) {
  (void)state;
  uint64_t seed = 12345;
  const int pairs = 4000, samples = 2000;
  const double dt = 1;
  int hits = 0, culled = 0, receding = 0;
  for (int k = 0; k < pairs; k++) {
    double p[3], v[3], r = uniform(&seed, 0.2, 1.5);
    for (int a = 0; a < 3; a++) p[a] = uniform(&seed, -3, 3), v[a] = uniform(&seed, -3, 3);
    double p2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    double pv = p[0] * v[0] + p[1] * v[1] + p[2] * v[2];
    bool may = tx_voxel_vieta_may_collide(p, v, r);
    if (!may) culled++;
    if (pv > 0) {
      receding++;
      assert_false(may);
    }
    if (p2 <= r * r) continue; // brute force asks about apart pairs
    int first = -1;
    for (int s = 0; s <= samples && first < 0; s++) {
      double tau = dt * s / samples;
      double x = p[0] + v[0] * tau, y = p[1] + v[1] * tau, z = p[2] + v[2] * tau;
      if (sqrt(x * x + y * y + z * z) < r * (1 - 1e-9)) first = s;
    }
    double th = -1;
    bool hit = tx_voxel_time_of_impact(p, v, r, dt, &th);
    if (first >= 0) {
      hits++;
      assert_true(may);
      assert_true(hit);
      assert_true(th <= dt * first / samples && th >= dt * (first - 1) / samples);
    }
  }
  print_message("  %d random pairs: %d meet in the frame, %d culled by eq. 4 (%d receding)\n", pairs, hits, culled,
                receding);
  assert_true(hits > 100 && culled > pairs / 3);
  // NaN never passes
  double pn[3] = {NAN, 0, 0}, vn[3] = {-1, 0, 0}, th;
  assert_false(tx_voxel_vieta_may_collide(pn, vn, 0.1));
  assert_false(tx_voxel_time_of_impact(pn, vn, 0.1, 1, &th));
  double p[3] = {1, 0, 0};
  assert_false(tx_voxel_time_of_impact(p, vn, NAN, 1, &th));
  assert_false(tx_voxel_time_of_impact(p, vn, 0.1, NAN, &th));
}

// after voxels move, every pair closer than the reach is on both lists,
// including voxels pushed out of the grid
static void neighbours_against_all_pairs(void** state) {
  (void)state;
  tx_voxel_tissue_def d = tx_voxel_tissue_def_default();
  d.count[0] = d.count[1] = d.count[2] = 7;
  tx_voxel_tissue t;
  assert_true(tx_voxel_tissue_init(&t, &d));
  uint64_t seed = 99;
  for (int i = 0; i < 3 * t.n; i++) t.pos[i] += uniform(&seed, -0.4e-3, 0.4e-3);
  for (int a = 0; a < 3; a++) t.pos[a] = 1, t.pos[3 + a] = 1 + 0.1e-3; // far outside, close together
  tx_voxel_tissue_refresh_neighbours(&t);
  int close = 0;
  for (int i = 0; i < t.n; i++)
    for (int j = 0; j < t.n; j++) {
      if (i == j) continue;
      double dd = 0;
      for (int a = 0; a < 3; a++) dd += pow(t.pos[3 * j + a] - t.pos[3 * i + a], 2);
      bool listed = false;
      for (int k = 0; k < t.nbr_count[i]; k++) listed |= t.nbr[i * d.max_neighbours + k] == j;
      if (dd < t.reach * t.reach) {
        close++;
        assert_true(listed);
      } else {
        assert_false(listed);
      }
    }
  assert_true(close > t.n);
  assert_int_equal(t.overflow, 0);
  tx_voxel_tissue_fini(&t);
}

// each voxel searching again on its own as it moves: after every step of a
// shaken block, every pair that could touch (closer than 2 radius plus a
// quarter of the skin) is on both lists, and the lists stay symmetric
static void moving_voxels_keep_their_neighbours(void** state) {
  (void)state;
  tx_voxel_tissue_def d = tx_voxel_tissue_def_default();
  d.count[0] = d.count[1] = d.count[2] = 6;
  d.radius = 0.2e-3;
  tx_voxel_tissue t;
  assert_true(tx_voxel_tissue_init(&t, &d));
  uint64_t seed = 7;
  for (int i = 0; i < t.n; i++) {
    for (int a = 0; a < 3; a++) t.vel[3 * i + a] = uniform(&seed, -0.3, 0.3);
    tx_voxel_tissue_wake(&t, i);
  }
  const int cap = d.max_neighbours;
  const double close = 2 * d.radius + 0.25 * d.skin;
  for (int s = 0; s < 40; s++) {
    assert_true(tx_voxel_tissue_step(&t, 1e-3));
    for (int i = 0; i < t.n; i++)
      for (int j = i + 1; j < t.n; j++) {
        double dd = 0;
        for (int a = 0; a < 3; a++) dd += pow(t.pos[3 * j + a] - t.pos[3 * i + a], 2);
        bool ij = false, ji = false;
        for (int k = 0; k < t.nbr_count[i]; k++) ij |= t.nbr[i * cap + k] == j;
        for (int k = 0; k < t.nbr_count[j]; k++) ji |= t.nbr[j * cap + k] == i;
        assert_true(ij == ji);
        if (dd < close * close) assert_true(ij);
      }
  }
  assert_true(t.refreshes > (uint64_t)t.n); // the voxels did search again, each on its own
  assert_int_equal(t.rebuilds, 1);          // and the whole block never had to
  assert_int_equal(t.overflow, 0);
  tx_voxel_tissue_fini(&t);
}

// one voxel displaced 0.1 mm: critically damped it creeps back without
// crossing rest, on x0 (1 + w t) exp(-w t); underdamped it crosses; a
// thousand times stiffer springs stay finite
static void spring_damper_returns(void** state) {
  (void)state;
  tx_voxel_tissue_def d = tx_voxel_tissue_def_default();
  d.count[0] = d.count[1] = d.count[2] = 1;
  d.damper = 2 * sqrt(d.spring * d.mass);
  tx_voxel_tissue t;
  assert_true(tx_voxel_tissue_init(&t, &d));
  const double x0 = 0.1e-3, w = sqrt(d.spring / d.mass), dt = 1e-3;
  t.pos[0] += x0;
  tx_voxel_tissue_wake(&t, 0);
  double prev = x0, worst = 0;
  for (int s = 1; s <= 100; s++) {
    assert_true(tx_voxel_tissue_step(&t, dt));
    double x = t.pos[0] - t.pos0[0], tt = s * dt;
    assert_true(x >= 0 && x <= prev);
    // awake it follows the exact curve; within a millionth of its radius it is put to rest
    if (x != 0) worst = fmax(worst, fabs(x - x0 * (1 + w * tt) * exp(-w * tt)));
    else assert_true(x0 * (1 + w * tt) * exp(-w * tt) < 1e-6 * d.radius);
    prev = x;
  }
  assert_true(worst <= 1e-12 * x0);
  assert_true(prev == 0 && t.vel[0] == 0); // asleep, exactly at rest
  assert_int_equal(t.n_awake, 0);
  tx_voxel_tissue_fini(&t);

  d.damper *= 0.2;
  assert_true(tx_voxel_tissue_init(&t, &d));
  t.pos[0] += x0;
  tx_voxel_tissue_wake(&t, 0);
  double lowest = x0;
  for (int s = 1; s <= 100; s++) {
    assert_true(tx_voxel_tissue_step(&t, dt));
    lowest = fmin(lowest, t.pos[0] - t.pos0[0]);
  }
  assert_true(lowest < -0.1 * x0);
  tx_voxel_tissue_fini(&t);

  d = tx_voxel_tissue_def_default();
  d.count[0] = d.count[1] = d.count[2] = 1;
  d.spring *= 1e3;
  assert_true(tx_voxel_tissue_init(&t, &d));
  t.pos[1] -= x0;
  tx_voxel_tissue_wake(&t, 0);
  for (int s = 1; s <= 1000; s++) assert_true(tx_voxel_tissue_step(&t, dt));
  assert_true(isfinite(t.pos[1]) && fabs(t.pos[1] - t.pos0[1]) <= x0);
  tx_voxel_tissue_fini(&t);
}

// full damage halves the radius (damage_shrink 0.5); half of it is gone
// after half of recovery_time and all of it after recovery_time
static void damage_recovers(void** state) {
  (void)state;
  tx_voxel_tissue_def d = tx_voxel_tissue_def_default();
  tx_voxel_tissue t;
  assert_true(tx_voxel_tissue_init(&t, &d));
  const double r0 = d.radius;
  assert_true(tx_voxel_tissue_damage(&t, 42, 0.7));
  assert_true(tx_voxel_tissue_damage(&t, 42, 0.7)); // clamps at full damage
  assert_true(t.damage[42] == 1 && fabs(t.radius[42] - 0.5 * r0) <= 1e-18);
  assert_int_equal(t.n_damaged, 1);
  for (int s = 0; s < 250; s++) assert_true(tx_voxel_tissue_step(&t, 1e-3));
  assert_true(fabs(t.damage[42] - 0.5) <= 1e-9 && fabs(t.radius[42] - 0.75 * r0) <= 1e-9 * r0);
  for (int s = 0; s < 251; s++) assert_true(tx_voxel_tissue_step(&t, 1e-3));
  assert_true(t.damage[42] == 0 && t.radius[42] == r0);
  assert_int_equal(t.n_damaged, 0);
  // bad damage: refused, nothing changes
  const double bad[] = {NAN, INFINITY, -1, 0, 2};
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    assert_false(tx_voxel_tissue_damage(&t, 3, bad[k]));
    assert_non_null(strstr(tx_error(), "amount"));
  }
  assert_false(tx_voxel_tissue_damage(&t, -1, 0.5));
  assert_false(tx_voxel_tissue_damage(&t, t.n, 0.5));
  assert_int_equal(t.n_damaged, 0);
  for (int i = 0; i < t.n; i++) assert_true(t.radius[i] == r0);
  tx_voxel_tissue_fini(&t);
}

// NaN, Inf and negative values in every field: a message naming it, init
// refuses and leaves the tissue as it was; bad steps are refused too, and a
// NaN written into a voxel is put back at rest
static void bad_input_refused(void** state) {
  (void)state;
  const tx_voxel_tissue_def good = tx_voxel_tissue_def_default();
  struct {
    const char* name;
    size_t offset;
  } fields[] = {
      {"block_size[0]", offsetof(tx_voxel_tissue_def, block_size[0])},
      {"block_size[1]", offsetof(tx_voxel_tissue_def, block_size[1])},
      {"block_size[2]", offsetof(tx_voxel_tissue_def, block_size[2])},
      {"origin[0]", offsetof(tx_voxel_tissue_def, origin[0])},
      {"origin[1]", offsetof(tx_voxel_tissue_def, origin[1])},
      {"origin[2]", offsetof(tx_voxel_tissue_def, origin[2])},
      {"mass", offsetof(tx_voxel_tissue_def, mass)},
      {"elasticity", offsetof(tx_voxel_tissue_def, elasticity)},
      {"spring", offsetof(tx_voxel_tissue_def, spring)},
      {"damper", offsetof(tx_voxel_tissue_def, damper)},
      {"radius", offsetof(tx_voxel_tissue_def, radius)},
      {"damage_shrink", offsetof(tx_voxel_tissue_def, damage_shrink)},
      {"recovery_time", offsetof(tx_voxel_tissue_def, recovery_time)},
      {"skin", offsetof(tx_voxel_tissue_def, skin)},
  };
  const double bad[] = {NAN, INFINITY, -INFINITY, -1, -100, 1e12};
  tx_voxel_tissue t;
  memset(&t, 0xab, sizeof t);
  tx_voxel_tissue before;
  memcpy(&before, &t, sizeof t);
  for (size_t f = 0; f < sizeof fields / sizeof *fields; f++)
    for (size_t b = 0; b < sizeof bad / sizeof *bad; b++) {
      bool origin = strncmp(fields[f].name, "origin", 6) == 0;
      if (origin && bad[b] == -1) continue; // a valid corner
      tx_voxel_tissue_def d = good;
      memcpy((char*)&d + fields[f].offset, &bad[b], sizeof(double));
      const char* msg = tx_voxel_tissue_def_check(&d) ? tx_error() : NULL;
      assert_non_null(msg);
      assert_non_null(strstr(msg, fields[f].name));
      assert_false(tx_voxel_tissue_init(&t, &d));
      assert_non_null(strstr(tx_error(), fields[f].name));
      assert_memory_equal(&t, &before, sizeof t);
    }
  const int bad_counts[] = {0, -1, 1001};
  for (int a = 0; a < 3; a++)
    for (size_t b = 0; b < 3; b++) {
      tx_voxel_tissue_def d = good;
      d.count[a] = bad_counts[b];
      assert_int_equal(tx_voxel_tissue_def_check(&d), -1);
      assert_non_null(strstr(tx_error(), "count["));
    }
  tx_voxel_tissue_def d = good;
  d.max_neighbours = 0;
  assert_int_equal(tx_voxel_tissue_def_check(&d), -1);
  assert_non_null(strstr(tx_error(), "max_neighbours"));
  d = good;
  d.elasticity = 1.01;
  assert_int_equal(tx_voxel_tissue_def_check(&d), -1);
  assert_non_null(strstr(tx_error(), "elasticity"));
  // packed so tight that the lists would overflow: refused
  d = good;
  d.count[0] = 100;
  assert_int_equal(tx_voxel_tissue_def_check(&d), -1);
  assert_non_null(strstr(tx_error(), "twice the lattice spacing"));

  // steps of no length, negative, NaN or Inf: refused, nothing moves
  assert_true(tx_voxel_tissue_init(&t, &good));
  t.vel[5] = 0.01;
  tx_voxel_tissue_wake(&t, 1);
  const double bad_dt[] = {0, -1e-3, NAN, INFINITY, 2};
  for (size_t k = 0; k < sizeof bad_dt / sizeof *bad_dt; k++) {
    assert_false(tx_voxel_tissue_step(&t, bad_dt[k]));
    assert_non_null(strstr(tx_error(), "dt"));
    assert_int_equal(t.steps, 0);
    assert_true(t.pos[5] == t.pos0[5] && t.vel[5] == 0.01);
  }
  // a NaN written into the state: restored, counted, never spread
  t.pos[3 * 500] = NAN;
  t.vel[3 * 600 + 1] = INFINITY;
  t.mass[700] = -1;
  tx_voxel_tissue_wake(&t, 500), tx_voxel_tissue_wake(&t, 600), tx_voxel_tissue_wake(&t, 700);
  for (int s = 0; s < 10; s++) assert_true(tx_voxel_tissue_step(&t, 1e-3));
  assert_true(t.faults >= 3);
  for (int i = 0; i < 3 * t.n; i++) assert_true(isfinite(t.pos[i]) && isfinite(t.vel[i]));
  tx_voxel_tissue_fini(&t);
}

// 20,000 voxels of a 5 x 6.25 x 10 mm block at 0.25 mm, its top pressed by a
// 5 x 5 patch moving at 0.05 m/s: no allocation, no NaN, contacts happen
static void block_20k_steps_without_allocation(void** state) {
  (void)state;
  tx_voxel_tissue_def d = tx_voxel_tissue_def_default();
  d.count[0] = 20, d.count[1] = 40, d.count[2] = 25;
  d.block_size[0] = 5e-3, d.block_size[1] = 10e-3, d.block_size[2] = 6.25e-3;
  d.radius = 0.125e-3;
  d.mass = 1000 * 0.25e-3 * 0.25e-3 * 0.25e-3;
  d.damper = 2 * sqrt(d.spring * d.mass);
  tx_voxel_tissue t;
  assert_true(tx_voxel_tissue_init(&t, &d));
  assert_int_equal(t.n, 20000);
  const int steps = 300;
  double total = 0, worst = 0;
  uint64_t contacts = 0, rebuilds0 = t.rebuilds;
  // the counter sees an allocation when there is one
  allocations = 0;
  counting = 1;
  void* volatile probe = malloc(16);
  counting = 0;
  free(probe);
#ifndef TX_NO_ALLOC_COUNT
  assert_int_equal(allocations, 1);
#endif
  allocations = 0;
  counting = 1;
  for (int s = 0; s < steps; s++) {
    // the press: the patch's velocity is held for the first 100 steps
    if (s < 100)
      for (int z = 10; z < 15; z++)
        for (int x = 8; x < 13; x++) {
          int i = (z * 40 + 39) * 20 + x;
          t.vel[3 * i + 1] = -0.05;
          tx_voxel_tissue_wake(&t, i);
        }
    if (s == 50) tx_voxel_tissue_damage(&t, (12 * 40 + 39) * 20 + 10, 1);
    double t0 = now_s();
    bool ok = tx_voxel_tissue_step(&t, 1e-3);
    double el = now_s() - t0;
    if (!ok) break;
    total += el;
    worst = fmax(worst, el);
    contacts += t.contacts;
  }
  counting = 0;
#ifdef TX_NO_ALLOC_COUNT
  print_message("  (allocation count unavailable under a sanitizer)\n");
#else
  assert_int_equal(allocations, 0);
#endif
  assert_int_equal(t.steps, steps);
  for (int i = 0; i < 3 * t.n; i++) assert_true(isfinite(t.pos[i]) && isfinite(t.vel[i]));
  assert_true(contacts > 100);
  assert_int_equal(t.faults, 0);
  assert_int_equal(t.overflow, 0);
  print_message("  20000 voxels, %d steps of 1 ms: mean %.1f us, worst %.1f us per step; %llu contacts, %llu list "
                "searches, %ld allocations\n",
                steps, 1e6 * total / steps, 1e6 * worst, (unsigned long long)contacts,
                (unsigned long long)(t.refreshes + t.rebuilds - rebuilds0), (long)allocations);
  tx_voxel_tissue_fini(&t);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(defaults_rest),
      cmocka_unit_test(collision_conserves),
      cmocka_unit_test(time_of_impact_matches),
      cmocka_unit_test(vieta_against_brute_force),
      cmocka_unit_test(neighbours_against_all_pairs),
      cmocka_unit_test(moving_voxels_keep_their_neighbours),
      cmocka_unit_test(spring_damper_returns),
      cmocka_unit_test(damage_recovers),
      cmocka_unit_test(bad_input_refused),
      cmocka_unit_test(block_20k_steps_without_allocation),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
