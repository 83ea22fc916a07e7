// Instruments drawn from their URDF visual meshes: the vertices placed at the
// link poses (a translation moves them by it, a quarter turn swaps the axes),
// the held instrument of a hand's list chosen by its index, bad input
// refused; and a headless render on OSMesa where the instrument's pixels lie
// where its pose puts them, and nowhere else.
#include "model/error.h"
#include "views/graphics/osmesa_target.h"
#include "views/graphics/renderer.h"
#include "views/graphics/stereo_frame.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

static void bounds(const float* x, uint32_t n, double lo[3], double hi[3]) {
  for (int c = 0; c < 3; c++) lo[c] = INFINITY, hi[c] = -INFINITY;
  for (uint32_t i = 0; i < n; i++)
    for (int c = 0; c < 3; c++) lo[c] = fmin(lo[c], x[3 * i + c]), hi[c] = fmax(hi[c], x[3 * i + c]);
}

// the thumb forceps closed, all links at the root frame (their joints at 0
// put them there: the blades' frames are 12 mm ahead, but the meshes are in
// each link's own frame); placed at (1, 2, 3) the box moves by it; turned a
// quarter about z, x runs along y
static void placed_at_the_link_poses(void** state) {
  (void)state;
  tx_instrument_mesh* m = tx_instrument_mesh_load("thumb_forceps");
  if (!m) fail_msg("%s", tx_error());
  tx_pose links[3] = {{.quat = {1, 0, 0, 0}}, {.quat = {1, 0, 0, 0}}, {.quat = {1, 0, 0, 0}}};
  const float* x;
  const int32_t* tri;
  uint32_t nv, nt;
  assert_true(tx_instrument_mesh_place(m, 0, links, 3, &x, &nv, &tri, &nt));
  assert_true(nv > 0 && nt > 0);
  for (uint32_t i = 0; i < 3 * nt; i++) assert_true(tri[i] >= 0 && (uint32_t)tri[i] < nv);
  double lo[3], hi[3], lo2[3], hi2[3];
  bounds(x, nv, lo, hi);
  print_message("  at the origin: x [%.4f, %.4f], y [%.4f, %.4f], z [%.4f, %.4f] m, %u vertices\n", lo[0], hi[0], lo[1],
                hi[1], lo[2], hi[2], nv);
  assert_true(hi[0] - lo[0] > 0.1); // 118 mm blades behind a 12 mm heel
  for (int l = 0; l < 3; l++) links[l].pos[0] = 1, links[l].pos[1] = 2, links[l].pos[2] = 3;
  assert_true(tx_instrument_mesh_place(m, 0, links, 3, &x, &nv, &tri, &nt));
  bounds(x, nv, lo2, hi2);
  for (int c = 0; c < 3; c++) assert_true(fabs(lo2[c] - lo[c] - (c + 1)) < 1e-5 && fabs(hi2[c] - hi[c] - (c + 1)) < 1e-5);
  double s = sqrt(0.5);
  for (int l = 0; l < 3; l++) links[l] = (tx_pose){.quat = {s, 0, 0, s}};
  assert_true(tx_instrument_mesh_place(m, 0, links, 3, &x, &nv, &tri, &nt));
  bounds(x, nv, lo2, hi2);
  assert_true(fabs(lo2[1] - lo[0]) < 1e-5 && fabs(hi2[1] - hi[0]) < 1e-5); // x -> y
  assert_true(fabs(lo2[0] + hi[1]) < 1e-5 && fabs(hi2[0] + lo[1]) < 1e-5); // y -> -x
  // no such index, too few links, a link that is not finite: nothing placed
  assert_false(tx_instrument_mesh_place(m, 1, links, 3, &x, &nv, &tri, &nt));
  assert_false(tx_instrument_mesh_place(m, NAN, links, 3, &x, &nv, &tri, &nt));
  assert_false(tx_instrument_mesh_place(m, 0, links, 2, &x, &nv, &tri, &nt));
  links[2].pos[0] = NAN;
  assert_false(tx_instrument_mesh_place(m, 0, links, 3, &x, &nv, &tri, &nt));
  tx_instrument_mesh_free(m);
  // a hand's list: the index picks the held one (the scissors have other meshes)
  m = tx_instrument_mesh_load("thumb_forceps metzenbaum_scissors");
  if (!m) fail_msg("%s", tx_error());
  for (int l = 0; l < 3; l++) links[l] = (tx_pose){.quat = {1, 0, 0, 0}};
  uint32_t nv0, nv1;
  assert_true(tx_instrument_mesh_place(m, 0, links, 3, &x, &nv0, &tri, &nt));
  assert_true(tx_instrument_mesh_place(m, 1, links, 3, &x, &nv1, &tri, &nt));
  assert_true(nv0 == nv && nv1 != nv0);
  tx_instrument_mesh_free(m);
  // bad input: one line naming the file
  assert_null(tx_instrument_mesh_load("no_such_instrument"));
  print_message("  %s\n", tx_error());
  assert_non_null(strstr(tx_error(), "no_such_instrument.urdf"));
  assert_null(tx_instrument_mesh_load("   "));
}

#define W 320
#define H 240

// the forceps seen from 30 cm straight above their plane: along x at
// y = +2 cm, then turned a quarter to run along y at x = -2 cm; the lit
// pixels lie on the row (then column) the pose projects to, and the mirror
// row (column) is dark
static void drawn_where_the_pose_says(void** state) {
  (void)state;
  tx_view_def d = tx_view_def_default();
  d.width = W, d.height = H;
  d.camera.eye[0] = 0, d.camera.eye[1] = 0, d.camera.eye[2] = 0.3;
  d.camera.target[0] = d.camera.target[1] = d.camera.target[2] = 0;
  d.camera.fov_y = 40 * M_PI / 180;
  d.camera.near_m = 0.01, d.camera.far_m = 10, d.camera.convergence = 0.3, d.camera.interaxial = 0.01;
  d.background[0] = d.background[1] = d.background[2] = 0;
  d.light_dir[0] = 0, d.light_dir[1] = 0, d.light_dir[2] = -1;
  d.items[0] = (tx_draw_item){.kind = TX_DRAW_INSTRUMENT, .colour = {0.7f, 0.7f, 0.7f}};
  snprintf(d.items[0].urdf, sizeof d.items[0].urdf, "thumb_forceps");
  d.nitems = 1;
  double focal = 0.5 * H / tan(0.5 * d.camera.fov_y) / 0.3; // px per m in the plane z = 0
  tx_osmesa* osm = tx_osmesa_create(W, H);
  if (!osm) fail_msg("%s", tx_error());
  tx_renderer* r = tx_renderer_create(tx_osmesa_proc);
  if (!r) fail_msg("%s", tx_error());
  double s = sqrt(0.5);
  for (int turn = 0; turn < 2; turn++) {
    tx_pose links[3];
    for (int l = 0; l < 3; l++) { // the root 6.5 cm behind the centre, the blades' frames 12 mm ahead of it
      double ahead = l ? 0.012 : 0;
      links[l] = turn == 0 ? (tx_pose){.pos = {-0.065 + ahead, 0.02, 0}, .quat = {1, 0, 0, 0}}
                           : (tx_pose){.pos = {-0.02, -0.065 + ahead, 0}, .quat = {s, 0, 0, s}};
    }
    tx_instrument_held held = {0};
    tx_scene sc = {.count = 1};
    sc.items[0] = (tx_scene_item){&d.items[0], {links, &held}, {3, 1}};
    tx_renderer_upload(r, &sc);
    tx_stereo_draw(r, &d, &d.camera, TX_STEREO_MONO, 0, W, H);
    tx_renderer_gl(r)->Finish();
    const uint8_t* px = tx_osmesa_pixels(osm); // bottom row first
    int on = 0, off = 0, n = 0;
    for (int k = -40; k <= 40; k += 10, n++) { // 4 cm either side of the middle, along the jaws
      double u = 0.5 * W + focal * (turn == 0 ? k * 1e-3 : -0.02), v = 0.5 * H + focal * (turn == 0 ? 0.02 : k * 1e-3);
      double um = turn == 0 ? u : W - u, vm = turn == 0 ? H - v : v; // the mirror: across the image's middle
      const uint8_t* p = px + 4 * ((size_t)(int)v * W + (int)u);
      const uint8_t* q = px + 4 * ((size_t)(int)vm * W + (int)um);
      on += p[0] + p[1] + p[2] > 60;
      off += q[0] + q[1] + q[2] > 60;
    }
    print_message("  %s: %d of %d points on the jaws lit, %d of their mirror\n", turn ? "along y" : "along x", on, n, off);
    assert_int_equal(on, n);
    assert_int_equal(off, 0);
  }
  assert_int_equal(tx_renderer_skipped(r), 0);
  tx_renderer_destroy(r);
  tx_osmesa_destroy(osm);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(placed_at_the_link_poses),
      cmocka_unit_test(drawn_where_the_pose_says),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
