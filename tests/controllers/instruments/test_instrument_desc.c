// Instrument descriptions: the six shipped URDFs read through urdfdom and
// their meshes through assimp agree with the closed forms they were built
// from; each kind of bad input is refused with one line naming the file and
// the element.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "controllers/instruments/instrument_desc.h"
#include "tactus/model.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char* names[] = {"thumb_forceps", "needle_holder", "metzenbaum_scissors",
                              "lap_grasper", "lap_scissors", "hook_cautery"};

static char* asset(const char* name) {
  static char path[1024];
  snprintf(path, sizeof path, "%s/%s.urdf", TX_INSTRUMENT_DIR, name);
  return path;
}

static char* slurp(const char* path) {
  FILE* f = fopen(path, "rb");
  assert_non_null(f);
  static char buf[1 << 16];
  size_t n = fread(buf, 1, sizeof buf - 1, f);
  fclose(f);
  buf[n] = 0;
  return strdup(buf);
}

// a copy of NAME's URDF in a fresh folder, with FROM replaced by TO (once),
// beside a link to the shipped meshes unless without_meshes
static char dir[64], urdf_path[128];
static char* replace(char* text, const char* from, const char* to) {
  char* at = strstr(text, from);
  assert_non_null(at);
  size_t n = strlen(text) - strlen(from) + strlen(to) + 1;
  char* out = malloc(n);
  snprintf(out, n, "%.*s%s%s", (int)(at - text), text, to, at + strlen(from));
  free(text);
  return out;
}
static const char* mutated2(const char* name, const char* from, const char* to, const char* from2, const char* to2,
                            bool without_meshes) {
  snprintf(dir, sizeof dir, "/tmp/tx-instr-XXXXXX");
  assert_non_null(mkdtemp(dir));
  char* text = replace(slurp(asset(name)), from, to);
  if (from2) text = replace(text, from2, to2);
  snprintf(urdf_path, sizeof urdf_path, "%s/%s.urdf", dir, name);
  FILE* f = fopen(urdf_path, "w");
  assert_non_null(f);
  fputs(text, f);
  fclose(f);
  free(text);
  if (!without_meshes) {
    char link[128];
    snprintf(link, sizeof link, "%s/meshes", dir);
    assert_int_equal(symlink(TX_INSTRUMENT_DIR "/meshes", link), 0);
  }
  return urdf_path;
}
static const char* mutated(const char* name, const char* from, const char* to, bool without_meshes) {
  return mutated2(name, from, to, NULL, NULL, without_meshes);
}

static void cleanup(void) {
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  assert_int_equal(system(cmd), 0);
}

// refused, with one line holding every fragment
static void expect_refused(const char* path, const char* f1, const char* f2) {
  tx_instrument_desc* d = tx_instrument_desc_load(path);
  if (d) tx_instrument_desc_free(d);
  assert_null(d);
  const char* e = tx_error();
  if (!strstr(e, path) || !strstr(e, f1) || (f2 && !strstr(e, f2)) || strchr(e, '\n'))
    fail_msg("error line '%s' should name %s, '%s'%s%s", e, path, f1, f2 ? " and " : "", f2 ? f2 : "");
}

static void test_all_six_load(void** state) {
  (void)state;
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
    tx_instrument_desc* d = tx_instrument_desc_load(asset(names[i]));
    if (!d) fail_msg("%s: %s", names[i], tx_error());
    bool hook = strcmp(names[i], "hook_cautery") == 0;
    assert_int_equal(d->urdf->nlinks, hook ? 1 : 3);
    assert_int_equal(tx_instrument_desc_jaws(d), hook ? 0 : 2);
    assert_string_equal(d->urdf->links[0].name, "root");
    for (int j = 0; j < d->urdf->njoints; j++) {
      const tx_urdf_joint* jt = &d->urdf->joints[j];
      assert_int_equal(jt->parent, 0);
      assert_true(jt->lower == 0 && jt->upper > 0.05 && jt->upper < 0.6); // 0 = closed
      assert_true(fabs(fabs(jt->axis[1]) - 1) < 1e-12); // jaws open about y
    }
    double m = tx_instrument_desc_mass(d);
    assert_true(m > 0.010 && m < 0.060); // catalogue instruments weigh tens of grams
    for (int l = 0; l < d->urdf->nlinks; l++) assert_true(d->meshes[l].ntriangles > 0);
    tx_instrument_desc_free(d);
  }
}

// the thumb forceps' heel is one box: its URDF mass and inertia are the box's
// closed forms, and its mesh's volume is the box's
static void test_box_link_matches_closed_form(void** state) {
  (void)state;
  tx_instrument_desc* d = tx_instrument_desc_load(asset("thumb_forceps"));
  assert_non_null(d);
  const tx_urdf_link* root = &d->urdf->links[0];
  double a = 0.012, b = 0.009, c = 0.003, m = 7900 * a * b * c;
  assert_true(fabs(root->mass - m) < 1e-6 * m);
  assert_true(fabs(root->inertia[0] - m * (b * b + c * c) / 12) < 1e-5 * root->inertia[0]);
  assert_true(fabs(root->inertia[3] - m * (a * a + c * c) / 12) < 1e-5 * root->inertia[3]);
  assert_true(fabs(root->inertia[5] - m * (a * a + b * b) / 12) < 1e-5 * root->inertia[5]);
  assert_true(fabs(tx_mesh_volume(&d->meshes[0]) - a * b * c) < 1e-6 * a * b * c);
  assert_int_equal(root->nshapes, 1);
  assert_int_equal(root->shapes[0].kind, TX_URDF_BOX);
  tx_instrument_desc_free(d);
}

// the needle holder's box lock is one cylinder across y: its mesh (24 sides)
// has the prism's volume n/2 r^2 sin(2 pi/n) L, within 1.2 % of pi r^2 L
static void test_cylinder_mesh_volume(void** state) {
  (void)state;
  tx_instrument_desc* d = tx_instrument_desc_load(asset("needle_holder"));
  assert_non_null(d);
  double r = 0.004, L = 0.006, n = 24;
  double prism = n / 2 * r * r * sin(2 * M_PI / n) * L;
  assert_true(fabs(tx_mesh_volume(&d->meshes[0]) - prism) < 1e-5 * prism);
  const tx_urdf_shape* s = &d->urdf->links[0].shapes[0];
  assert_int_equal(s->kind, TX_URDF_CYLINDER);
  assert_true(s->size[0] == r && s->size[1] == L);
  // the URDF cylinder's z is turned onto y: q = (cos 45, sin 45, 0, 0)
  assert_true(fabs(s->pose.q[0] - sqrt(0.5)) < 1e-9 && fabs(s->pose.q[1] - sqrt(0.5)) < 1e-9);
  tx_instrument_desc_free(d);
}

static void test_malformed(void** state) {
  (void)state;
  expect_refused(mutated("needle_holder", "</link>", "</lnk>", false), "line 22:", "end tag");
  cleanup();
  expect_refused(mutated2("needle_holder", "<robot", "<robbed", "</robot>", "</robbed>", false), "robot", NULL);
  cleanup();
  expect_refused("/nonexistent/x.urdf", "No such file", NULL);
}

static void test_missing_mesh(void** state) {
  (void)state;
  expect_refused(mutated("lap_grasper", "x", "x", true), "link 'root' <visual> <mesh>", "lap_grasper_root.obj");
  cleanup();
}

static void test_joint_without_limits(void** state) {
  (void)state;
  expect_refused(mutated("needle_holder", "<limit lower=\"0\" upper=\"0.26\" effort=\"0.5\" velocity=\"4\"/>", "", false),
                 "jaw_upper_joint", "limit");
  cleanup();
  expect_refused(mutated("needle_holder", "lower=\"0\" upper=\"0.26\"", "lower=\"0.3\" upper=\"0.26\"", false),
                 "joint 'jaw_upper_joint' <limit>", "lower");
  cleanup();
  expect_refused(mutated("needle_holder", "type=\"revolute\"", "type=\"prismatic\"", false),
                 "joint 'jaw_upper_joint'", "revolute");
  cleanup();
}

static void test_bad_inertia(void** state) {
  (void)state;
  expect_refused(mutated("thumb_forceps", "<mass value=\"", "<mass value=\"-", false), "link 'root' <mass>",
                 "positive");
  cleanup();
  expect_refused(mutated("thumb_forceps", "<mass value=\"", "<mass value=\"0\" was=\"", false), "link 'root' <mass>",
                 "positive");
  cleanup();
  expect_refused(mutated("thumb_forceps", "ixx=\"", "ixx=\"-", false), "link 'root' <inertia> ixx", "positive");
  cleanup();
  expect_refused(mutated("thumb_forceps", "iyy=\"", "iyy=\"0\" was=\"", false), "link 'root' <inertia> iyy", "positive");
  cleanup();
  expect_refused(mutated("thumb_forceps", "izz=\"", "izz=\"9", false), "link 'root' <inertia>", "sum");
  cleanup();
  expect_refused(mutated2("thumb_forceps", "<inertial>", "<!--", "</inertial>", "-->", false), "link 'root'", "<inertial>");
  cleanup();
}

static void test_mesh_without_faces(void** state) {
  (void)state;
  const char* path = mutated("hook_cautery", "meshes/hook_cautery_root.obj", "empty.obj", true);
  char mesh[128];
  snprintf(mesh, sizeof mesh, "%s/empty.obj", dir);
  FILE* f = fopen(mesh, "w");
  assert_non_null(f);
  fputs("# points only\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", f);
  fclose(f);
  expect_refused(path, "link 'root' <visual> <mesh>", "empty.obj: no faces");
  cleanup();
}

static void test_bad_collision_shape(void** state) {
  (void)state;
  expect_refused(mutated("thumb_forceps", "<box size=\"0.012", "<box size=\"-0.012", false),
                 "link 'root' <collision name='heel'>", "positive");
  cleanup();
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_all_six_load),       cmocka_unit_test(test_box_link_matches_closed_form),
      cmocka_unit_test(test_cylinder_mesh_volume), cmocka_unit_test(test_malformed),
      cmocka_unit_test(test_missing_mesh),       cmocka_unit_test(test_joint_without_limits),
      cmocka_unit_test(test_bad_inertia),        cmocka_unit_test(test_mesh_without_faces),
      cmocka_unit_test(test_bad_collision_shape),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
