// The asset pipeline's checks on shapes whose answers are known: a cube is
// closed, manifold and outward; the same cube with a hole, a flipped
// triangle, turned inside out, or joined to a second cube at one corner is
// not. A regular tetrahedron's dihedral angles are acos(1/3); a tetrahedron
// of the other orientation is inverted. The readers refuse bad files naming
// the line or the key, and the raw + JSON volume round-trips.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "tools/lagb/mesh.h"
#include "tools/lagb/volume.h"

#include <tactus/model.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tests/temp_file.h"

// a unit cube, 12 triangles counter-clockwise seen from outside
static const double cube_v[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                    {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
static const int cube_t[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                                  {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};

static double vbuf[16 * 3];
static int tbuf[24 * 3];

// one cube, or two sharing vertex 6 (the second is the first moved by (1,1,1))
static tx_trimesh cube(int copies) {
  for (int c = 0; c < copies; c++) {
    for (int i = 0; i < 8; i++)
      for (int k = 0; k < 3; k++) vbuf[3 * (8 * c + i) + k] = cube_v[i][k] + c;
    for (int i = 0; i < 12; i++)
      for (int k = 0; k < 3; k++) {
        int v = cube_t[i][k] + 8 * c;
        if (c == 1 && cube_t[i][k] == 0) v = 6;  // the second cube's corner 0 is the first's corner 6
        tbuf[3 * (12 * c + i) + k] = v;
      }
  }
  return (tx_trimesh){8 * copies, 12 * copies, vbuf, tbuf};
}

static void test_closed_cube(void** state) {
  (void)state;
  tx_trimesh m = cube(1);
  tx_trimesh_report r;
  assert_true(tx_trimesh_inspect(&m, &r));
  assert_true(tx_trimesh_report_ok(&r));
  assert_int_equal(r.components, 1);
  assert_int_equal(r.euler, 2);
  assert_true(fabs(r.volume - 1) < 1e-12);
  assert_true(fabs(r.area - 6) < 1e-12);
  // every point inside winds once, every point outside not at all
  assert_true(fabs(tx_trimesh_winding(&m, (double[]){0.5, 0.5, 0.5}) - 1) < 1e-9);
  assert_true(fabs(tx_trimesh_winding(&m, (double[]){0.9, 0.1, 0.2}) - 1) < 1e-9);
  assert_true(fabs(tx_trimesh_winding(&m, (double[]){1.5, 0.5, 0.5})) < 1e-9);
}

static void test_hole(void** state) {
  (void)state;
  tx_trimesh m = cube(1);
  m.nt = 11;  // the last triangle gone
  tx_trimesh_report r;
  assert_true(tx_trimesh_inspect(&m, &r));
  assert_int_equal(r.boundary_edges, 3);
  assert_false(tx_trimesh_report_ok(&r));
}

static void test_flipped_and_inside_out(void** state) {
  (void)state;
  tx_trimesh m = cube(1);
  int t = tbuf[1];
  tbuf[1] = tbuf[2], tbuf[2] = t;  // one triangle flipped
  tx_trimesh_report r;
  assert_true(tx_trimesh_inspect(&m, &r));
  assert_int_equal(r.misoriented_edges, 3);
  assert_false(tx_trimesh_report_ok(&r));
  // all flipped: consistent, but the normals point in
  m = cube(1);
  for (int i = 0; i < 12; i++) t = tbuf[3 * i + 1], tbuf[3 * i + 1] = tbuf[3 * i + 2], tbuf[3 * i + 2] = t;
  assert_true(tx_trimesh_inspect(&m, &r));
  assert_int_equal(r.misoriented_edges, 0);
  assert_true(fabs(r.volume + 1) < 1e-12);
  assert_false(tx_trimesh_report_ok(&r));
}

static void test_cubes_touching_at_a_corner(void** state) {
  (void)state;
  tx_trimesh m = cube(2);
  tx_trimesh_report r;
  assert_true(tx_trimesh_inspect(&m, &r));
  // every edge has two triangles, but the shared corner has two fans
  assert_int_equal(r.boundary_edges + r.nonmanifold_edges + r.misoriented_edges, 0);
  assert_int_equal(r.nonmanifold_verts, 1);
  assert_false(tx_trimesh_report_ok(&r));
}

static void test_degenerate(void** state) {
  (void)state;
  tx_trimesh m = cube(1);
  tbuf[2] = tbuf[1];  // a triangle with a repeated vertex
  tx_trimesh_report r;
  assert_true(tx_trimesh_inspect(&m, &r));
  assert_true(r.degenerate >= 1);
  assert_false(tx_trimesh_report_ok(&r));
}

static void test_dihedrals(void** state) {
  (void)state;
  // regular: every angle acos(1/3) = 70.5288 degrees
  double a[3] = {1, 1, 1}, b[3] = {1, -1, -1}, c[3] = {-1, 1, -1}, d[3] = {-1, -1, 1};
  double ang[6];
  tx_tet_dihedrals(a, b, c, d, ang);
  for (int i = 0; i < 6; i++) assert_true(fabs(ang[i] - acos(1.0 / 3.0) * 180 / M_PI) < 1e-9);
  // the corner of a cube: three right angles at the corner's edges, and
  // acos(1/sqrt(3)) = 54.7356 at the others
  double o[3] = {0, 0, 0}, x[3] = {1, 0, 0}, y[3] = {0, 1, 0}, z[3] = {0, 0, 1};
  tx_tet_dihedrals(o, x, y, z, ang);
  int right = 0, other = 0;
  for (int i = 0; i < 6; i++) {
    right += fabs(ang[i] - 90) < 1e-9;
    other += fabs(ang[i] - acos(1 / sqrt(3.0)) * 180 / M_PI) < 1e-9;
  }
  assert_int_equal(right, 3);
  assert_int_equal(other, 3);
}

static void test_tet_orientation(void** state) {
  (void)state;
  // (b-a).((c-a)x(d-a)) > 0: TetGen's orientation; the swap is inverted
  double v[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  int good[] = {0, 1, 2, 3}, bad_e[] = {0, 2, 1, 3};
  tx_tetmesh m = {4, 1, v, TX_TETGEN_ORIENTATION > 0 ? good : bad_e};
  tx_tetmesh_report r;
  tx_tetmesh_inspect(&m, &r);
  assert_int_equal(r.inverted, 0);
  assert_true(fabs(r.volume - 1.0 / 6) < 1e-12);
  assert_true(fabs(r.min_dihedral - acos(1 / sqrt(3.0)) * 180 / M_PI) < 1e-9);
  assert_true(fabs(r.max_dihedral - 90) < 1e-9);
  m.e = TX_TETGEN_ORIENTATION > 0 ? bad_e : good;
  tx_tetmesh_inspect(&m, &r);
  assert_int_equal(r.inverted, 1);
  double flat[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  m = (tx_tetmesh){4, 1, flat, good};
  tx_tetmesh_inspect(&m, &r);
  assert_int_equal(r.degenerate, 1);
}

static void expect_obj_error(const char* text, const char* fragment) {
  char* path = write_file(text);
  tx_trimesh m;
  assert_false(tx_trimesh_read_obj(path, &m));
  if (!strstr(tx_error(), fragment)) fail_msg("'%s' does not name '%s'", tx_error(), fragment);
  assert_non_null(strstr(tx_error(), path));
  unlink(path);
}

static void test_obj_read(void** state) {
  (void)state;
  char* path = write_file("# a quad and a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1 2/2 3/3 4/4\nf -1 -2 -3\n");
  tx_trimesh m;
  assert_true(tx_trimesh_read_obj(path, &m));
  unlink(path);
  assert_int_equal(m.nv, 4);
  assert_int_equal(m.nt, 3);
  int want[] = {0, 1, 2, 0, 2, 3, 3, 2, 1};
  assert_memory_equal(m.t, want, sizeof want);
  tx_trimesh_free(&m);
  expect_obj_error("v 0 0 0\nv 1 0 0\nf 1 2 3\n", ":3: face index '3'");
  expect_obj_error("v 0 0\n", ":1: a vertex needs three");
  expect_obj_error("v 0 0 nan\n", ":1: a vertex needs three");
  expect_obj_error("v 0 0 0\nv 1 0 0\nf 1 2\n", ":3: a face needs at least three");
  expect_obj_error("v 0 0 0\n", "no faces");
}

static void test_obj_round_trip(void** state) {
  (void)state;
  tx_trimesh m = cube(1), back;
  char path[] = "/tmp/tx-test-XXXXXX.obj";
  close(mkstemps(path, 4));
  assert_true(tx_trimesh_write_obj(&m, path, "a cube"));
  assert_true(tx_trimesh_read_obj(path, &back));
  assert_int_equal(back.nv, 8);
  assert_int_equal(back.nt, 12);
  assert_memory_equal(back.t, m.t, 12 * 3 * sizeof(int));
  for (int i = 0; i < 24; i++) assert_true(fabs(back.v[i] - m.v[i]) < 1e-6);
  tx_trimesh_free(&back);
  unlink(path);
  assert_false(tx_trimesh_write_obj(&m, "/nonexistent/dir/x.obj", ""));
  assert_non_null(strstr(tx_error(), "/nonexistent/dir/x.obj"));
}

static void test_tetgen_files(void** state) {
  (void)state;
  char node[] = "/tmp/tx-test-XXXXXX.node", ele[] = "/tmp/tx-test-XXXXXX.ele";
  close(mkstemps(node, 5));
  close(mkstemps(ele, 4));
  FILE* f = fopen(node, "w");
  fputs("# TetGen -z\n4 3 0 1\n0 0 0 0 1\n1 1 0 0 1\n2 0 1 0 1\n3 0 0 1 1\n", f);
  fclose(f);
  f = fopen(ele, "w");
  fputs("1 4 0\n0 0 1 2 3\n", f);
  fclose(f);
  tx_tetmesh m;
  assert_true(tx_tetmesh_read(node, ele, &m));
  assert_int_equal(m.nv, 4);
  assert_int_equal(m.ne, 1);
  tx_tetmesh_free(&m);
  // one-based numbering (tetgen without -z) is refused
  f = fopen(ele, "w");
  fputs("1 4 0\n1 1 2 3 4\n", f);
  fclose(f);
  assert_false(tx_tetmesh_read(node, ele, &m));
  assert_non_null(strstr(tx_error(), ele));
  f = fopen(node, "w");
  fputs("4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", f);
  fclose(f);
  assert_false(tx_tetmesh_read(node, ele, &m));
  assert_non_null(strstr(tx_error(), "zero-based"));
  unlink(node);
  unlink(ele);
}

// a 3 x 2 x 2 volume through raw + JSON and back
static void test_volume_json(void** state) {
  (void)state;
  uint16_t lab[12] = {0, 1, 1, 0, 2, 2, 0, 0, 3, 4, 4, 4};
  tx_lagb_volume v = {{3, 2, 2}, {1e-3, 2e-3, 3e-3}, {0.1, 0.2, 0.3}, lab};
  char path[] = "/tmp/tx-test-XXXXXX.json";
  close(mkstemps(path, 5));
  tx_lagb_label names[] = {{"liver", 1}, {"stomach", 2}};
  assert_true(tx_lagb_volume_write_json(&v, path, names, 2));
  tx_lagb_volume back;
  tx_lagb_label got[4];
  int n = 0;
  assert_true(tx_lagb_volume_read_json(path, &back, got, 4, &n));
  assert_int_equal(back.n[0], 3);
  assert_int_equal(back.n[2], 2);
  assert_true(fabs(back.spacing[1] - 2e-3) < 1e-15);
  assert_true(fabs(back.origin[2] - 0.3) < 1e-12);
  assert_memory_equal(back.label, lab, sizeof lab);
  assert_int_equal(n, 2);
  assert_string_equal(got[1].name, "stomach");
  assert_int_equal(got[1].value, 2);
  tx_lagb_volume_free(&back);
  char raw[64];
  snprintf(raw, sizeof raw, "%.*s.raw", (int)strlen(path) - 5, path);
  // the raw file one voxel short, then a header that is not one
  FILE* f = fopen(raw, "wb");
  fwrite(lab, 1, 11, f);
  fclose(f);
  assert_false(tx_lagb_volume_read_json(path, &back, NULL, 0, NULL));
  assert_non_null(strstr(tx_error(), "fewer than 12 voxels"));
  assert_non_null(strstr(tx_error(), path));
  f = fopen(path, "w");
  fputs("{\"size\": [3, 2], \"spacing\": [1e-3, 1e-3, 1e-3], \"type\": \"uint8\", \"data\": \"x.raw\"}", f);
  fclose(f);
  assert_false(tx_lagb_volume_read_json(path, &back, NULL, 0, NULL));
  assert_non_null(strstr(tx_error(), "\"size\""));
  f = fopen(path, "w");
  fputs("{\"size\": [3, 2, 2], \"spacing\": [1, 1, 1], \"type\": \"uint8\", \"data\": \"x.raw\"}", f);
  fclose(f);
  assert_false(tx_lagb_volume_read_json(path, &back, NULL, 0, NULL));
  assert_non_null(strstr(tx_error(), "metres"));
  f = fopen(path, "w");
  fputs("{\"size\": [3, 2, 2], \"spacing\": [1e-3, 1e-3, 1e-3], \"type\": \"float\", \"data\": \"x.raw\"}", f);
  fclose(f);
  assert_false(tx_lagb_volume_read_json(path, &back, NULL, 0, NULL));
  assert_non_null(strstr(tx_error(), "\"type\""));
  f = fopen(path, "w");
  fputs("{\"size\": [3, 2, 2],", f);
  fclose(f);
  assert_false(tx_lagb_volume_read_json(path, &back, NULL, 0, NULL));
  assert_non_null(strstr(tx_error(), path));
  unlink(path);
  unlink(raw);
}

// the phantom holds every organ, and at its centre the cavity
static void test_phantom(void** state) {
  (void)state;
  tx_lagb_phantom_def d = tx_lagb_phantom_def_default();
  d.voxel = 8e-3;
  tx_lagb_volume v;
  assert_true(tx_lagb_phantom(&d, &v));
  int64_t count[5] = {0};
  for (int64_t i = 0; i < tx_lagb_volume_count(&v); i++) count[v.label[i] < 5 ? v.label[i] : 0]++;
  for (int l = 1; l < 5; l++) assert_true(count[l] > 0);
  // organ volumes (m^3) near the sizes the README gives: liver about 1.8 l,
  // stomach about 0.9 l, spleen about 0.15 l
  double vox = d.voxel * d.voxel * d.voxel;
  assert_true(fabs(count[1] * vox - 1.8e-3) < 0.3e-3);
  assert_true(fabs(count[2] * vox - 0.9e-3) < 0.25e-3);
  assert_true(fabs(count[3] * vox - 0.15e-3) < 0.08e-3);
  tx_lagb_volume_free(&v);
  d.voxel = 0;
  assert_false(tx_lagb_phantom(&d, &v));
  assert_non_null(strstr(tx_error(), "voxel"));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_closed_cube),     cmocka_unit_test(test_hole),
      cmocka_unit_test(test_flipped_and_inside_out), cmocka_unit_test(test_cubes_touching_at_a_corner),
      cmocka_unit_test(test_degenerate),      cmocka_unit_test(test_dihedrals),
      cmocka_unit_test(test_tet_orientation), cmocka_unit_test(test_obj_read),
      cmocka_unit_test(test_obj_round_trip),  cmocka_unit_test(test_tetgen_files),
      cmocka_unit_test(test_volume_json),     cmocka_unit_test(test_phantom),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
