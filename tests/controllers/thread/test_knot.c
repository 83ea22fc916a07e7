// Knots: the papers' rule on hand-made contact marks (blocks, gaps, counts);
// the Gauss-code classifier's Reidemeister moves on hand-written curves; and
// the reference set of thread shapes (knot_shapes.h), each with its answer,
// with the precision and recall of both the papers' rule and the classifier.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "knot_shapes.h"
#include "controllers/physics/skin_grid.h"
#include "controllers/thread/thread.h"
#include "model/error.h"

#include <stdio.h>
#include <string.h>

static void marks(uint8_t* m, int n, const char* pattern) {
  memset(m, 0, (size_t)n);
  for (int i = 0; pattern[i] && i < n; i++) m[i] = pattern[i] == '#';
}

static void test_papers_rule_blocks_and_gaps(void** state) {
  (void)state;
  tx_knot_rule r = tx_knot_rule_papers();
  tx_knot_papers k;
  uint8_t m[64];
  // two blocks of 5, 5 apart: 10 colliding, a knot over cylinders 0..14
  marks(m, 64, "#####.....#####");
  assert_true(tx_knot_papers_rule(m, 64, &r, &k));
  assert_int_equal(k.colliding, 10);
  assert_int_equal(k.blocks, 2);
  assert_int_equal(k.first, 0);
  assert_int_equal(k.last, 14);
  // 4 apart: too close
  marks(m, 64, "#####....#####");
  assert_false(tx_knot_papers_rule(m, 64, &r, &k));
  // blocks of 4 and 6: a knot; of 3 and 7: one block only
  marks(m, 64, "####.....######");
  assert_true(tx_knot_papers_rule(m, 64, &r, &k));
  marks(m, 64, "###.....#######");
  assert_false(tx_knot_papers_rule(m, 64, &r, &k));
  assert_int_equal(k.blocks, 1);
  // 9 colliding in two blocks: too few
  marks(m, 64, "####.....#####");
  assert_false(tx_knot_papers_rule(m, 64, &r, &k));
  // short runs do not count as blocks but do count as colliding
  marks(m, 64, "####.....####...##");
  assert_true(tx_knot_papers_rule(m, 64, &r, &k));
  assert_int_equal(k.colliding, 10);
  assert_int_equal(k.last, 12);
  marks(m, 64, "");
  assert_false(tx_knot_papers_rule(m, 64, &r, &k));
  assert_int_equal(k.first, -1);
}

// a curve given by corners, resampled finely
static int curve(const double (*c)[3], int m, double* x) {
  static polyline l;
  l.n = 0;
  for (int i = 0; i < m; i++) pl_add(&l, c[i][0], c[i][1], c[i][2]);
  return resample(&l, x);
}

static void test_classifier_moves(void** state) {
  (void)state;
  tx_knot_work* w = tx_knot_work_create(SHAPE_MAX);
  assert_non_null(w);
  double* x = malloc(sizeof(double) * 3 * SHAPE_MAX);
  assert_non_null(x);
  tx_knot_diagram d;
  // straight: nothing to cross
  int n = curve((const double[][3]){{0, 0, 0}, {0.01, 0, 0}}, 2, x);
  assert_int_equal(tx_knot_classify(w, x, n, &d), 0);
  assert_int_equal(d.raw, 0);
  assert_int_equal(d.cls, TX_KNOT_UNKNOT);
  // one crossing (a curl): move I removes it
  n = curve((const double[][3]){{0, 0, 0}, {0.01, 0, 0}, {0.01, 0.01, 0.001}, {0.005, -0.005, 0.001}}, 4, x);
  assert_int_equal(tx_knot_classify(w, x, n, &d), 0);
  assert_int_equal(d.crossings, 0);
  assert_int_equal(d.cls, TX_KNOT_UNKNOT);
  // too many nodes for the work area
  assert_int_equal(tx_knot_classify(w, x, SHAPE_MAX + 1, &d), -1);
  assert_non_null(strstr(tx_error(), "nodes"));
  free(x);
  tx_knot_work_destroy(w);
}

static void test_reference_shapes(void** state) {
  (void)state;
  shape s[16];
  int ns = knot_shapes(s);
  tx_knot_work* w = tx_knot_work_create(SHAPE_MAX);
  assert_non_null(w);
  uint8_t* col = malloc(SHAPE_MAX);
  assert_non_null(col);
  tx_knot_rule rule = tx_knot_rule_papers();
  int tp[2] = {0}, fp[2] = {0}, fn[2] = {0}, named = 0, knots = 0;
  print_message("%-28s %5s %6s | %-14s %9s | %-10s %9s %6s\n", "shape", "nodes", "answer", "papers' rule", "colliding",
                "classifier", "crossings", "writhe");
  for (int i = 0; i < ns; i++) {
    assert_non_null(s[i].x);
    tx_knot_contacts(s[i].x, s[i].n, SHAPE_RADIUS, rule.min_gap, col);
    tx_knot_papers p;
    bool papers = tx_knot_papers_rule(col, s[i].n - 1, &rule, &p);
    tx_knot_diagram d;
    assert_int_equal(tx_knot_classify(w, s[i].x, s[i].n, &d), 0);
    bool classed = d.cls != TX_KNOT_UNKNOT;
    print_message("%-28s %5d %6s | %-14s %9d | %-10s %4d of %-2d %6d\n", s[i].name, s[i].n, s[i].knot ? "knot" : "none",
                  papers ? "knot" : "none", p.colliding, tx_knot_class_name(d.cls), d.crossings, d.raw, d.writhe);
    bool said[2] = {papers, classed};
    for (int k = 0; k < 2; k++) {
      tp[k] += said[k] && s[i].knot;
      fp[k] += said[k] && !s[i].knot;
      fn[k] += !said[k] && s[i].knot;
    }
    knots += s[i].knot;
    named += d.cls == s[i].cls;
  }
  double prec[2], rec[2];
  for (int k = 0; k < 2; k++) {
    prec[k] = tp[k] + fp[k] ? (double)tp[k] / (tp[k] + fp[k]) : 1;
    rec[k] = (double)tp[k] / knots;
  }
  print_message("papers' rule: precision %.2f, recall %.2f; classifier: precision %.2f, recall %.2f, %d of %d named\n",
                prec[0], rec[0], prec[1], rec[1], named, ns);
  // the classifier names every shape: knot or not, and which knot
  assert_int_equal(named, ns);
  assert_true(prec[1] == 1 && rec[1] == 1);
  // the papers' rule sees contact: the strands lying side by side fool it,
  // and a loose knot, with no contact, escapes it
  assert_true(prec[0] < 1);
  assert_true(rec[0] < 1);
  free(col);
  free_shapes(s, ns);
  tx_knot_work_destroy(w);
}

// the tight overhand lying 0.5 mm over a skin patch: the papers' rule finds
// it, it is near the skin, so its cylinders are pinned where they are; the
// rest of the thread still falls. Far from the skin nothing is fixed.
static void test_knot_near_the_skin_is_fixed(void** state) {
  (void)state;
  shape s[16];
  int ns = knot_shapes(s);
  shape* k = &s[0];
  static float px[41 * 41 * 3];
  static int32_t tri[2 * 40 * 40 * 3];
  double ymin = 1;
  for (int i = 0; i < k->n; i++) ymin = fmin(ymin, k->x[3 * i + 1]);
  uint32_t ntri = tx_skin_grid(41, 41, 0.0005, 0.0005, (double[3]){0, ymin - 0.0005, 0}, px, tri);
  uint8_t col[SHAPE_MAX];
  tx_knot_rule rule = tx_knot_rule_papers();
  tx_knot_contacts(k->x, k->n, SHAPE_RADIUS, rule.min_gap, col);
  tx_knot_papers p;
  assert_true(tx_knot_papers_rule(col, k->n - 1, &rule, &p));
  for (int near = 1; near >= 0; near--) {
    tx_thread_def d = tx_thread_def_default();
    d.model = TX_THREAD_ROD;
    d.nodes = k->n;
    d.length = SHAPE_SPACING * (k->n - 1);
    d.radius = SHAPE_RADIUS;
    d.max_triangles = (int)ntri;
    d.self_collision = false;
    tx_thread* t = tx_thread_create(&d);
    assert_non_null(t);
    assert_int_equal(tx_thread_set_positions(t, k->x), TX_THREAD_OK);
    assert_int_equal(tx_thread_set_mesh(t, px, 41 * 41, tri, ntri, 0), TX_THREAD_OK);
    assert_int_equal(tx_thread_fix_near_mesh(t, p.first, p.last, near ? 0.001 : 0.0001), near);
    for (int step = 0; step < 50; step++) assert_int_equal(tx_thread_step(t, 1e-3), TX_THREAD_OK);
    double still = 0, tail = 0;
    for (int i = p.first; i <= p.last + 1; i++)
      for (int a = 0; a < 3; a++) still = fmax(still, fabs(tx_thread_position(t, i)[a] - k->x[3 * i + a]));
    for (int a = 0; a < 3; a++) tail = fmax(tail, fabs(tx_thread_position(t, k->n - 1)[a] - k->x[3 * (k->n - 1) + a]));
    print_message("%s: knot cylinders %d..%d moved %.3g mm, tail %.3g mm\n", near ? "near" : "far", p.first, p.last,
                  still * 1e3, tail * 1e3);
    if (near) assert_true(still == 0);
    else assert_true(still > 1e-5);
    assert_true(tail > 1e-4);
    assert_int_equal(tx_thread_fix_near_mesh(t, 5, 2, 0.001), -1);
    tx_thread_destroy(t);
  }
  free_shapes(s, ns);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_papers_rule_blocks_and_gaps),
      cmocka_unit_test(test_classifier_moves),
      cmocka_unit_test(test_reference_shapes),
      cmocka_unit_test(test_knot_near_the_skin_is_fixed),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
