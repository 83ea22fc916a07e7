// The simplified method against hand computations on synthetic skins: the
// contact threshold r + h/2, force direction and size for one ray and for
// the 26- and 98-ray fans, a pushed and a dented skin, the eq. 8 update of
// the first contact point, zero force once pierced, and no allocation.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/collision/hip.h"
#include "controllers/physics/skin_grid.h"
#include "studies/experiments/skin_dent.h"

#include <tactus/components.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tests/alloc_count.h"

#define N 41          // particles per side
#define SPACING 5e-4  // m: a 2 x 2 cm patch
#define R 5e-4        // m, HIP radius (0.05 cm)
#define H 4e-3        // m, skin thickness (0.4 cm)
#define REACH (R + H / 2)
#define ALPHA 20.0    // N/m (0.2 N/cm)

typedef struct skin {
  float x[3 * N * N];
  int32_t tri[6 * (N - 1) * (N - 1)];
  uint32_t ntri;
  tx_tri_bvh bvh;
} skin;

static skin* flat(void) {
  skin* s = calloc(1, sizeof *s);
  assert_non_null(s);
  s->ntri = tx_skin_grid(N, N, SPACING, SPACING, (double[3]){0, 0, 0}, s->x, s->tri);
  assert_int_equal(tx_tri_bvh_init(&s->bvh, s->ntri), 0);
  assert_int_equal(tx_tri_bvh_build(&s->bvh, s->x, N * N, s->tri, s->ntri), 0);
  return s;
}

static void drop(skin* s) {
  tx_tri_bvh_free(&s->bvh);
  free(s);
}

static tx_hip make_hip(int rays) {
  tx_hip_def d = tx_hip_def_default();
  d.radius = R;
  d.rays = rays;
  assert_int_equal(tx_hip_def_check(&d), 0);
  tx_hip h;
  tx_hip_init(&h, &d);
  return h;
}

static tx_hip_out query(tx_hip* h, skin* s, double x, double y, double z) {
  tx_hip_out o;
  tx_hip_query(h, &s->bvh, s->x, H, (double[3]){x, y, z}, &o);
  return o;
}

// off the grid lines, so the straight-down ray meets a triangle's inside
#define CX 1.1e-4
#define CZ 1.3e-4

static void test_defaults_are_the_papers(void** state) {
  (void)state;
  tx_hip_def d = tx_hip_def_default();
  assert_true(fabs(d.alpha - 0.2 / 0.01) < 1e-12); // 0.2 N per cm
  assert_true(fabs(d.k - 0.3) < 1e-12);
  assert_true(fabs(d.slide_max - 0.003) < 1e-12);   // 0.3 units of 1 cm
  assert_int_equal(d.rays, 26);
  assert_int_equal(tx_hip_def_check(&d), 0);
  d.rays = 50;
  assert_int_equal(tx_hip_def_check(&d), -1);
  d = tx_hip_def_default();
  d.k = 1;
  assert_int_equal(tx_hip_def_check(&d), -1);
  d = tx_hip_def_default();
  d.radius = NAN;
  assert_int_equal(tx_hip_def_check(&d), -1);
}

static void test_contact_threshold_radius_plus_half_thickness(void** state) {
  (void)state;
  skin* s = flat();
  tx_hip h = make_hip(26);
  tx_hip_out o = query(&h, s, CX, REACH + 1e-7, CZ);
  assert_int_equal(o.contacts, 0);
  assert_true(o.f[0] == 0 && o.f[1] == 0 && o.f[2] == 0);
  o = query(&h, s, CX, REACH - 1e-7, CZ);
  assert_int_equal(o.contacts, 1); // only the straight-down ray is that close
  assert_true(o.f[0] == 0 && o.f[1] == 0 && o.f[2] == 0); // the contact point is where it met the skin
  // a contact, once made, holds up to reach + hold (0.5 mm), then lets go
  o = query(&h, s, CX, REACH + 4e-4, CZ);
  assert_int_equal(o.contacts, 1);
  o = query(&h, s, CX, REACH + 6e-4, CZ);
  assert_int_equal(o.contacts, 0);
  o = query(&h, s, CX, REACH + 4e-4, CZ); // and a new one starts only below reach again
  assert_int_equal(o.contacts, 0);
  drop(s);
}

static void test_one_ray_force_and_push(void** state) {
  (void)state;
  skin* s = flat();
  tx_hip h = make_hip(26);
  const double y = 2.4e-3; // the 45-degree rays meet the plane at 2.4 sqrt(2) mm > reach
  tx_hip_out o = query(&h, s, CX, y, CZ);
  assert_int_equal(o.contacts, 1);
  // P_in = P_n = (cx, 0, cz) at first contact: the force starts from zero (no alpha h/2 step)
  assert_true(o.f[0] == 0 && o.f[1] == 0 && o.f[2] == 0);
  // K = -alpha I: every R_n grows with the HIP while the skin is held at its surface
  for (int i = 0; i < 9; i++) assert_true(fabs(o.k[i] - (i % 4 == 0 ? -ALPHA : 0)) < 1e-9);
  assert_true(fabs(o.depth - (REACH - y)) < 1e-12);
  // the skin pushed down 1 mm with the HIP: the force grows by alpha x 1 mm
  const double push = 1e-3;
  for (int i = 0; i < N * N; i++) s->x[3 * i + 1] -= (float)push;
  tx_tri_bvh_refit(&s->bvh, s->x);
  o = query(&h, s, CX, y - push, CZ);
  assert_int_equal(o.contacts, 1);
  assert_true(fabs(o.f[1] - ALPHA * push) < 1e-6);
  drop(s);
}

// every ray starting contact at one query starts at zero force; the skin then
// pushed 1 mm down with the HIP moves every contact point by 1 mm: F = alpha x 1 mm
static void check_fan(int rays, int want_contacts) {
  skin* s = flat();
  tx_hip h = make_hip(rays);
  const double D = 0.6 * REACH, push = 1e-3;
  tx_hip_out o = query(&h, s, CX, D, CZ);
  assert_int_equal(o.contacts, want_contacts);
  assert_true(fabs(o.f[0]) < 1e-12 && fabs(o.f[1]) < 1e-12 && fabs(o.f[2]) < 1e-12);
  for (int i = 0; i < N * N; i++) s->x[3 * i + 1] -= (float)push;
  tx_tri_bvh_refit(&s->bvh, s->x);
  o = query(&h, s, CX, D - push, CZ);
  assert_int_equal(o.contacts, want_contacts);
  assert_true(fabs(o.f[1] - ALPHA * push) < 1e-6 * ALPHA * push + 1e-7);
  assert_true(fabs(o.f[0]) < 1e-7 && fabs(o.f[2]) < 1e-7); // symmetric fan on a flat skin
  drop(s);
}

static void test_26_and_98_rays_by_hand(void** state) {
  (void)state;
  // 26 rays: contact needs |d_y| > 0.6: the down ray and four at 45 degrees
  check_fan(26, 5);
  // 98 rays: the j = -2 face with i^2 + k^2 <= 5 (|d_y| = 2 / sqrt(4 + i^2 + k^2) > 0.6): 21 rays
  check_fan(98, 21);
}

// rays joining a contact: by the contact's anchor (default) or each at its own onset
static void test_joining_rays_anchor_or_own(void** state) {
  (void)state;
  skin* s = flat();
  const double y0 = 2.4e-3, D = 0.6 * REACH;
  for (int own = 0; own < 2; own++) {
    tx_hip h = make_hip(26);
    h.def.join_anchor = !own;
    query(&h, s, CX, y0, CZ); // the down ray alone; it anchors the contact at y0
    tx_hip_out o = query(&h, s, CX, D, CZ); // four 45-degree rays join
    assert_int_equal(o.contacts, 5);
    // the down ray meets the still skin where it first did: R = 0. Anchor: a joining ray's
    // P_in = A + t d, R = c - A = -(y0 - D) y; own: P_in = its hit now, R = 0
    double joined = own ? 0 : y0 - D;
    assert_true(fabs(o.f[1] - ALPHA / 5 * 4 * joined) < 1e-9);
  }
  drop(s);
}

static void test_dented_skin_pushes_straight_back(void** state) {
  (void)state;
  skin* s = flat();
  tx_hip h = make_hip(98);
  const double y = 2.4e-3, depth = 1e-3;
  tx_hip_out o = query(&h, s, CX, y, CZ);
  assert_int_equal(o.contacts, 1);
  // a wide dent centred under the HIP, the HIP following it down
  tx_skin_dent(s->x, N * N, (double[3]){CX, 0, CZ}, depth, 0.02);
  tx_tri_bvh_refit(&s->bvh, s->x);
  o = query(&h, s, CX, y - depth, CZ);
  assert_true(o.contacts >= 1);
  assert_true(fabs(o.f[0]) < 1e-3 * o.f[1] && fabs(o.f[2]) < 1e-3 * o.f[1]);
  assert_true(fabs(o.f[1] - ALPHA * depth) < 0.02 * o.f[1]); // from zero at first contact
  drop(s);
}

static void test_eq8_moves_first_contact_after_slide(void** state) {
  (void)state;
  skin* s = flat();
  tx_hip h = make_hip(26);
  const double y = 2.4e-3, up = 0; // the still skin: no push, P_in was set on it
  query(&h, s, CX, y, CZ);
  // 2 mm along x, below slide_max (3 mm): R = (2 mm, 0, 0)
  tx_hip_out o = query(&h, s, CX + 2e-3, y, CZ);
  assert_true(fabs(o.f[0] + ALPHA * 2e-3) < 1e-6 && fabs(o.f[1] - up) < 1e-6);
  assert_int_equal(h.resets, 0);
  // 4 mm: past slide_max, eq. 8 across the approach: P_in moves (1 - k) R_t, R_t becomes k R_t
  o = query(&h, s, CX + 4e-3, y, CZ);
  assert_int_equal(h.resets, 1);
  assert_true(fabs(o.f[0] + 0.3 * ALPHA * 4e-3) < 1e-6 && fabs(o.f[1] - up) < 1e-6);
  // 1 mm more: the new first point stays, R = (0.3 x 4 + 1 mm, 0, 0)
  o = query(&h, s, CX + 5e-3, y, CZ);
  assert_int_equal(h.resets, 1);
  assert_true(fabs(o.f[0] + ALPHA * (1.2e-3 + 1e-3)) < 1e-6 && fabs(o.f[1] - up) < 1e-6);
  drop(s);
}

// pushed straight in, a skin whose triangle under the HIP tilts (the side of
// a narrow dent) must not move P_in: eq. 8 is for sliding across the skin
static void test_eq8_not_for_a_straight_push_into_tilted_skin(void** state) {
  (void)state;
  skin* s = flat();
  tx_hip h = make_hip(26);
  const double y = 2.4e-3, depth = 8e-3;
  query(&h, s, CX, y, CZ);
  tx_skin_dent(s->x, N * N, (double[3]){CX + 1.5e-3, 0, CZ}, depth, 2e-3);
  tx_tri_bvh_refit(&s->bvh, s->x);
  tx_ray_hit hit;
  assert_true(tx_tri_bvh_ray(&s->bvh, s->x, (double[3]){CX, y - 5e-3, CZ}, (double[3]){0, -1, 0}, 0.02, &hit));
  assert_true(hit.n[1] < 0.8); // the triangle under the HIP leans over
  double skin_y = y - 5e-3 - hit.t;
  tx_hip_out o = query(&h, s, CX, y - 5e-3, CZ);
  assert_int_equal(h.resets, 0);
  // the straight-down ray's R = (0, skin_y - (y - r), 0) is over 5 mm long, and more than
  // slide_max of it lies along the leaning triangle: measured against the hit normal, eq. 8
  // would have fired; the force still points out of the skin
  assert_true(y - R - skin_y > 5e-3);
  assert_true(o.contacts > 1);
  // the skin 0.5 mm further down with the HIP: the force points out of the skin
  for (int i = 0; i < N * N; i++) s->x[3 * i + 1] -= 5e-4f;
  tx_tri_bvh_refit(&s->bvh, s->x);
  o = query(&h, s, CX, y - 5.5e-3, CZ);
  assert_int_equal(h.resets, 0);
  assert_true(o.contacts > 1 && o.f[1] > 0);
  drop(s);
}

static void test_pierced_gives_zero_until_contact_ends(void** state) {
  (void)state;
  skin* s = flat();
  tx_hip h = make_hip(98);
  tx_hip_out o = query(&h, s, 0, 2.4e-3, 0);
  assert_int_equal(o.contacts, 1);
  assert_false(o.pierced);
  // tear a hole of radius 1 mm around the axis and take the HIP through it
  uint32_t kept = 0;
  for (uint32_t t = 0; t < s->ntri; t++) {
    const int32_t* v = s->tri + 3 * t;
    double cx = (s->x[3 * v[0]] + s->x[3 * v[1]] + s->x[3 * v[2]]) / 3;
    double cz = (s->x[3 * v[0] + 2] + s->x[3 * v[1] + 2] + s->x[3 * v[2] + 2]) / 3;
    if (cx * cx + cz * cz > 1e-6) memmove(s->tri + 3 * kept++, v, 3 * sizeof *v);
  }
  assert_true(kept < s->ntri);
  assert_int_equal(tx_tri_bvh_build(&s->bvh, s->x, N * N, s->tri, kept), 0);
  const double c[3] = {0, -0.8e-3, 0};
  // the hole's rim is within reach of the shallow rays: the method alone would push
  tx_ray_hit hit;
  double d[3] = {2 / sqrt(5.0), 1 / sqrt(5.0), 0};
  assert_true(tx_tri_bvh_ray(&s->bvh, s->x, c, d, REACH, &hit));
  o = query(&h, s, c[0], c[1], c[2]);
  assert_true(o.pierced);
  assert_int_equal(o.contacts, 0);
  assert_true(o.f[0] == 0 && o.f[1] == 0 && o.f[2] == 0);
  for (int i = 0; i < 9; i++) assert_true(o.k[i] == 0);
  // out of reach of the skin and back (a torn flap swinging onto the HIP): still
  // pierced, no force, while within pierce_range (1 cm) of where it went through
  o = query(&h, s, 0, -5e-3, 0);
  assert_true(o.pierced);
  o = query(&h, s, 0, -1.5e-3, 0);
  assert_true(o.pierced);
  assert_true(o.f[0] == 0 && o.f[1] == 0 && o.f[2] == 0);
  // clear of the pierce (over 1 cm from it) the state resets: the next touch starts afresh
  o = query(&h, s, 0, -0.012, 0);
  assert_false(o.pierced);
  assert_false(h.touching);
  // and back on the side it came from too
  tx_hip h2 = make_hip(98);
  o = query(&h2, s, 0.004, 2.4e-3, 0.004);
  assert_int_equal(o.contacts, 1);
  h2.pierced = true; // as if it had gone through here
  memcpy(h2.pierce_at, (double[3]){0.004, 0, 0.004}, sizeof h2.pierce_at);
  o = query(&h2, s, 0.004, 2.6e-3 + 1e-4, 0.004); // above the pierce by more than r + h/2
  assert_false(o.pierced);
  drop(s);
}

// mechanics mode: the skin's reaction, carried from where the physics computed it
// along its normal with its tangent stiffness, at most r + h/2 deep, never a pull;
// no pierce without a tear, and zero force before the physics has seen the contact
static void test_reaction_carried_bounded_never_a_pull(void** state) {
  (void)state;
  skin* s = flat();
  tx_hip h = make_hip(26);
  const double y = 2.4e-3;
  tx_skin_contact r = {.f = {0, 0.1, 0}, .x = {CX, y, CZ}, .n = {0, 1, 0}, .k = 50, .depth = 1e-3, .touching = 1};
  tx_skin_contact none = {0};
  tx_hip_out o;
  tx_hip_query_reaction(&h, &s->bvh, s->x, H, (double[3]){CX, y, CZ}, &none, &o);
  assert_int_equal(o.contacts, 0); // the rays touch, the physics has not pushed yet: no force
  assert_true(o.f[1] == 0);
  tx_hip_query_reaction(&h, &s->bvh, s->x, H, (double[3]){CX, y, CZ}, &r, &o);
  assert_true(fabs(o.f[1] - 0.1) < 1e-12 && o.f[0] == 0 && o.f[2] == 0);
  assert_true(o.x0[1] == y);
  // 0.1 mm deeper: F = f + k 0.1 mm, K = -k n n^T
  tx_hip_query_reaction(&h, &s->bvh, s->x, H, (double[3]){CX, y - 1e-4, CZ}, &r, &o);
  assert_true(fabs(o.f[1] - (0.1 + 50 * 1e-4)) < 1e-12);
  for (int i = 0; i < 9; i++) assert_true(fabs(o.k[i] - (i == 4 ? -50.0 : 0)) < 1e-12);
  // 5 mm deeper, past the still skin's mid-plane: no tear, so no pierce; the force holds
  // at f + k (r + h/2) and K = 0 (past the trusted reach)
  tx_hip_query_reaction(&h, &s->bvh, s->x, H, (double[3]){CX, y - 5e-3, CZ}, &r, &o);
  assert_false(o.pierced);
  assert_true(fabs(o.f[1] - (0.1 + 50 * REACH)) < 1e-12);
  for (int i = 0; i < 9; i++) assert_true(o.k[i] == 0);
  // back out 3 mm above x: f - k 3 mm < 0, the skin does not pull
  tx_hip_query_reaction(&h, &s->bvh, s->x, H, (double[3]){CX, y + 3e-3, CZ}, &r, &o);
  assert_true(o.f[0] == 0 && o.f[1] == 0 && o.f[2] == 0);
  // a torn skin with nothing ahead along the approach: pierced, no force
  tx_hip h2 = make_hip(26);
  tx_hip_query_reaction(&h2, &s->bvh, s->x, H, (double[3]){CX, y, CZ}, &r, &o);
  assert_true(o.f[1] > 0);
  r.torn = 1;
  tx_hip_query_reaction(&h2, &s->bvh, s->x, H, (double[3]){CX, -5e-3, CZ}, &r, &o);
  assert_true(o.pierced);
  assert_true(o.f[0] == 0 && o.f[1] == 0 && o.f[2] == 0);
  drop(s);
}

// BVH nodes one 98-ray query visits on an n x n skin of the same spacing
static uint64_t query_nodes(uint32_t n) {
  float* x = malloc(sizeof(float) * 3 * n * n);
  int32_t* tri = malloc(sizeof(int32_t) * 6 * (n - 1) * (n - 1));
  assert_non_null(x);
  assert_non_null(tri);
  uint32_t m = tx_skin_grid((int)n, (int)n, SPACING, SPACING, (double[3]){0, 0, 0}, x, tri);
  tx_skin_dent(x, n * n, (double[3]){0, 0, 0}, 2e-3, 4e-3);
  tx_tri_bvh b;
  assert_int_equal(tx_tri_bvh_init(&b, m), 0);
  assert_int_equal(tx_tri_bvh_build(&b, x, n * n, tri, m), 0);
  tx_hip h = make_hip(98);
  tx_hip_out o;
  b.visited = 0;
  tx_hip_query(&h, &b, x, H, (double[3]){CX, -2e-3 + 0.6 * REACH, CZ}, &o);
  assert_true(o.contacts > 0);
  uint64_t v = b.visited;
  tx_tri_bvh_free(&b);
  free(x);
  free(tri);
  return v;
}

static void test_query_cost_independent_of_far_triangles(void** state) {
  (void)state;
  uint64_t small = query_nodes(41), large = query_nodes(401); // 3200 and 320000 triangles
  assert_true(large < 2 * small);
}

static void test_query_allocates_nothing(void** state) {
  (void)state;
  skin* s = flat();
  tx_hip h = make_hip(98);
  allocations = 0;
  counting = 1;
  for (int i = 0; i < 100; i++) query(&h, s, CX + i * 1e-5, 2.4e-3 - i * 1e-5, CZ);
  tx_tri_bvh_refit(&s->bvh, s->x);
  counting = 0;
  assert_int_equal(allocations, 0);
  drop(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_defaults_are_the_papers),
      cmocka_unit_test(test_contact_threshold_radius_plus_half_thickness),
      cmocka_unit_test(test_one_ray_force_and_push),
      cmocka_unit_test(test_26_and_98_rays_by_hand),
      cmocka_unit_test(test_joining_rays_anchor_or_own),
      cmocka_unit_test(test_dented_skin_pushes_straight_back),
      cmocka_unit_test(test_eq8_moves_first_contact_after_slide),
      cmocka_unit_test(test_eq8_not_for_a_straight_push_into_tilted_skin),
      cmocka_unit_test(test_pierced_gives_zero_until_contact_ends),
      cmocka_unit_test(test_reaction_carried_bounded_never_a_pull),
      cmocka_unit_test(test_query_cost_independent_of_far_triangles),
      cmocka_unit_test(test_query_allocates_nothing),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
