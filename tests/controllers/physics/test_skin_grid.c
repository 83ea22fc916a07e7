// The skin's grid: counts, positions, +y normals, the alternating diagonal,
// and a closed mesh (every inner edge shared by exactly two triangles).
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/physics/skin_grid.h"

#include <math.h>
#include <stdlib.h>

enum { NX = 5, NZ = 4 };

static void counts_and_positions(void** state) {
  (void)state;
  float x[3 * NX * NZ];
  int32_t tri[6 * (NX - 1) * (NZ - 1)];
  assert_int_equal(tx_skin_grid(NX, NZ, 0.01, 0.02, (double[3]){1, 2, 3}, x, tri), 2 * (NX - 1) * (NZ - 1));
  // particle (ix, iz) at iz nx + ix, centred on the given point
  assert_float_equal(x[0], 1 - 0.02, 1e-6);
  assert_float_equal(x[1], 2, 1e-6);
  assert_float_equal(x[2], 3 - 0.03, 1e-6);
  const float* last = x + 3 * (NX * NZ - 1);
  assert_float_equal(last[0], 1 + 0.02, 1e-6);
  assert_float_equal(last[2], 3 + 0.03, 1e-6);
  assert_int_equal(tx_skin_grid(1, NZ, 0.01, 0.01, (double[3]){0, 0, 0}, x, tri), 0);
}

static void normals_up_and_diagonals_alternate(void** state) {
  (void)state;
  float x[3 * NX * NZ];
  int32_t tri[6 * (NX - 1) * (NZ - 1)];
  uint32_t m = tx_skin_grid(NX, NZ, 0.01, 0.01, (double[3]){0, 0, 0}, x, tri);
  for (uint32_t t = 0; t < m; t++) {
    const float *a = x + 3 * tri[3 * t], *b = x + 3 * tri[3 * t + 1], *c = x + 3 * tri[3 * t + 2];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double ny = u[2] * v[0] - u[0] * v[2];
    assert_true(ny > 0.5e-4 * 0.99); // area 0.5e-4 m^2, +y
  }
  // cell (0, 0) splits along (0,0)-(1,1), its neighbour (1, 0) along (2,0)-(1,1)
  int diag0 = 0, diag1 = 0;
  for (int k = 0; k < 6; k++) diag0 += tri[k] == 0 || tri[k] == NX + 1;
  for (int k = 6; k < 12; k++) diag1 += tri[k] == 2 || tri[k] == NX + 1;
  assert_int_equal(diag0, 4);
  assert_int_equal(diag1, 4);
}

static void inner_edges_have_two_triangles(void** state) {
  (void)state;
  int32_t tri[6 * (NX - 1) * (NZ - 1)];
  uint32_t m = tx_skin_grid(NX, NZ, 0.01, 0.01, (double[3]){0, 0, 0}, NULL, tri);
  int uses[NX * NZ][NX * NZ] = {{0}};
  for (uint32_t t = 0; t < m; t++)
    for (int k = 0; k < 3; k++) {
      int a = tri[3 * t + k], b = tri[3 * t + (k + 1) % 3];
      uses[a < b ? a : b][a < b ? b : a]++;
    }
  int boundary = 0, inner = 0;
  for (int a = 0; a < NX * NZ; a++)
    for (int b = a + 1; b < NX * NZ; b++) {
      assert_true(uses[a][b] <= 2);
      boundary += uses[a][b] == 1, inner += uses[a][b] == 2;
    }
  assert_int_equal(boundary, 2 * (NX - 1) + 2 * (NZ - 1));
  int edges = (NX - 1) * NZ + NX * (NZ - 1) + (NX - 1) * (NZ - 1); // along x, along z, one diagonal a cell
  assert_int_equal(inner, edges - boundary);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(counts_and_positions),
      cmocka_unit_test(normals_up_and_diagonals_alternate),
      cmocka_unit_test(inner_edges_have_two_triangles),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
