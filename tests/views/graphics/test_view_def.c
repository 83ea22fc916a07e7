// A scenario's "view": what is accepted, the key paths of what is not, and
// the draw list made from the model's naming conventions.
#include "model/error.h"
#include "views/graphics/view_def.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

static int parse(const char* text, tx_view_def* d) {
  json_error_t e;
  json_t* j = json_loads(text, 0, &e);
  assert_non_null(j);
  *d = tx_view_def_default();
  int rc = tx_view_def_from_json(j, d);
  json_decref(j);
  return rc;
}

static void full_view(void** state) {
  (void)state;
  tx_view_def d;
  assert_int_equal(parse("{\"rate_hz\": 60, \"width\": 320, \"height\": 200, \"frame_every\": 3,"
                         "\"camera\": {\"eye\": [0, 0.1, 0.3], \"target\": [0, 0, 0], \"fov_deg\": 30, \"near_m\": 0.02, \"far_m\": 3},"
                         "\"stereo\": {\"interaxial_m\": 0.01, \"convergence_m\": 0.25},"
                         "\"background\": [0, 0, 0], \"light\": [0, -1, 0],"
                         "\"draw\": [{\"mesh\": \"skin\"}, {\"spheres\": \"tissue\", \"colour_by\": \"tissue.damage\", \"range\": [0, 2]},"
                         "{\"segments\": \"thread\", \"colour\": [1, 1, 0]}, {\"tool\": \"device0\", \"radius_m\": 0.003, \"show_force\": true},"
                         "{\"plane\": {\"point\": [0, -0.01, 0], \"normal\": [0, 2, 0], \"size_m\": 0.1}}]}",
                         &d),
                   0);
  assert_int_equal(d.width, 320);
  assert_int_equal(d.height, 200);
  assert_int_equal(d.frame_every, 3);
  assert_false(d.auto_camera);
  assert_true(fabs(d.camera.fov_y - 30 * M_PI / 180) < 1e-12);
  assert_true(fabs(d.camera.interaxial - 0.01) < 1e-12);
  assert_true(fabs(d.camera.convergence - 0.25) < 1e-12); // stereo.convergence_m wins over the target distance
  assert_true(fabsf(d.light_dir[1] + 1) < 1e-6f);
  assert_int_equal(d.nitems, 5);
  assert_int_equal(d.items[0].kind, TX_DRAW_MESH);
  assert_true(d.items[0].skin_texture); // a mesh without a colour wears the skin texture
  assert_string_equal(d.items[1].scalar, "tissue.damage");
  assert_true(d.items[1].range[1] == 2);
  assert_int_equal(d.items[3].kind, TX_DRAW_TOOL);
  assert_true(d.items[3].show_force);
  assert_true(fabsf(d.items[4].plane[4] - 1) < 1e-6f); // the normal is made unit
  assert_true(fabsf(d.items[4].plane[6] - 0.05f) < 1e-6f);
  char comps[3][TX_NAME_MAX];
  assert_int_equal(tx_draw_item_components(&d.items[0], comps), 2);
  assert_string_equal(comps[0], "skin.x");
  assert_string_equal(comps[1], "skin.tri");
  assert_int_equal(tx_draw_item_components(&d.items[1], comps), 2);
  assert_string_equal(comps[0], "tissue.spheres");
  assert_string_equal(comps[1], "tissue.damage");
  assert_int_equal(tx_draw_item_components(&d.items[3], comps), 2);
  assert_string_equal(comps[1], "device0.force");
  assert_int_equal(tx_draw_item_components(&d.items[4], comps), 0);
  assert_false(d.items[1].has_cut);
  // a mesh coloured by a scalar per vertex (an organ's temperature): its third component
  assert_int_equal(parse("{\"draw\": [{\"mesh\": \"liver\", \"colour_by\": \"liver.temperature\", \"range\": [310, 373]}]}", &d), 0);
  assert_int_equal(tx_draw_item_components(&d.items[0], comps), 3);
  assert_string_equal(comps[2], "liver.temperature");
  assert_true(d.items[0].range[0] == 310 && d.items[0].range[1] == 373);
  // a cutaway of spheres: a point and a direction made unit
  assert_int_equal(parse("{\"draw\": [{\"spheres\": \"t\", \"cut\": {\"point\": [0, 0.5, 0], \"normal\": [0, 0, 3]}}]}", &d),
                   0);
  assert_true(d.items[0].has_cut);
  assert_true(fabsf(d.items[0].cut[1] - 0.5f) < 1e-6f && fabsf(d.items[0].cut[5] - 1) < 1e-6f);
  // the camera's own target distance is the convergence when stereo does not say
  assert_int_equal(parse("{\"camera\": {\"eye\": [0, 0.3, 0.4], \"target\": [0, 0, 0]}}", &d), 0);
  assert_true(fabs(d.camera.convergence - 0.5) < 1e-12);
  assert_true(fabs(d.camera.interaxial - 0.5 / 30) < 1e-12); // the 1/30 rule unless stereo.interaxial_m says
  assert_false(d.interaxial_given);
}

static void expect_error(const char* text, const char* want_key, const char* want_msg) {
  tx_view_def d;
  assert_int_equal(parse(text, &d), -1);
  assert_string_equal(tx_error_key(), want_key);
  if (!strstr(tx_error(), want_msg)) fail_msg("%s: message '%s' lacks '%s'", text, tx_error(), want_msg);
  // the message starts with the key, for a caller that has no use for it apart
  if (*want_key && strncmp(tx_error(), want_key, strlen(want_key)) != 0) fail_msg("'%s' does not start with the key", tx_error());
}

static void errors_name_the_key(void** state) {
  (void)state;
  expect_error("{\"colour\": 1}", "colour", "unknown key");
  expect_error("{\"width\": 0}", "width", "integer in [16, 4096]");
  expect_error("{\"width\": 1.5}", "width", "integer");
  expect_error("{\"rate_hz\": -30}", "rate_hz", "(0, 1000]");
  expect_error("{\"frame_every\": 0}", "frame_every", "[1, ");
  expect_error("{\"camera\": {\"eye\": [0, 0], \"target\": [0, 0, 0]}}", "camera.eye", "3 numbers");
  expect_error("{\"camera\": {\"eye\": [0, 0, 0], \"target\": [0, 0, 0]}}", "camera", "differ");
  expect_error("{\"camera\": {\"fov_deg\": 180}}", "camera.fov_deg", "[1, 170]");
  expect_error("{\"camera\": {\"near_m\": 1, \"far_m\": 0.5}}", "camera", "near < far");
  expect_error("{\"camera\": {\"zoom\": 2}}", "camera.zoom", "unknown key");
  expect_error("{\"stereo\": {\"interaxial_m\": -0.01}}", "stereo.interaxial_m", "[0, 1]");
  expect_error("{\"stereo\": {\"convergence_m\": 0}}", "stereo.convergence_m", "(0, 10000]");
  expect_error("{\"stereo\": \"sbs\"}", "stereo", "an object");
  expect_error("{\"background\": [0, 0, 2]}", "background", "[0, 1]");
  expect_error("{\"light\": [0, 0, 0]}", "light", "non-zero");
  expect_error("{\"draw\": []}", "draw", "1 to 16");
  expect_error("{\"draw\": [3]}", "draw[0]", "an object");
  expect_error("{\"draw\": [{}]}", "draw[0]", "one of mesh");
  expect_error("{\"draw\": [{\"mesh\": \"a\", \"tool\": \"b\"}]}", "draw[0]", "exactly one");
  expect_error("{\"draw\": [{\"mesh\": \"Skin!\"}]}", "draw[0].mesh", "component prefix");
  expect_error("{\"draw\": [{\"mesh\": \"skin\", \"colur\": [1, 0, 0]}]}", "draw[0].colur", "unknown key");
  expect_error("{\"draw\": [{\"mesh\": \"skin\"}, {\"spheres\": \"t\", \"colour\": [1, 0]}]}", "draw[1].colour", "3 numbers");
  expect_error("{\"draw\": [{\"tool\": \"device0\", \"colour_by\": \"skin.t\"}]}", "draw[0].colour_by", "only meshes, spheres");
  expect_error("{\"draw\": [{\"mesh\": \"skin\", \"cut\": {}}]}", "draw[0].cut", "only spheres");
  expect_error("{\"draw\": [{\"spheres\": \"t\", \"cut\": {\"normal\": [0, 0, 0]}}]}", "draw[0].cut.normal", "non-zero");
  expect_error("{\"draw\": [{\"spheres\": \"t\", \"cut\": {\"side\": 1}}]}", "draw[0].cut.side", "unknown key");
  expect_error("{\"draw\": [{\"spheres\": \"t\", \"cut\": [0, 0, 1]}]}", "draw[0].cut", "an object");
  expect_error("{\"draw\": [{\"spheres\": \"t\", \"range\": [0, 1]}]}", "draw[0].range", "needs colour_by");
  expect_error("{\"draw\": [{\"spheres\": \"t\", \"colour_by\": \"t.d\", \"range\": [1, 1]}]}", "draw[0].range", "low < high");
  expect_error("{\"draw\": [{\"spheres\": \"t\", \"texture\": \"skin\"}]}", "draw[0].texture", "only meshes");
  expect_error("{\"draw\": [{\"mesh\": \"s\", \"texture\": \"wood\"}]}", "draw[0].texture", "\"tissue\" or \"none\"");
  expect_error("{\"draw\": [{\"tool\": \"device0\", \"radius_m\": 0}]}", "draw[0].radius_m", "(0, 1]");
  expect_error("{\"draw\": [{\"tool\": \"device0\", \"show_force\": 1}]}", "draw[0].show_force", "true or false");
  expect_error("{\"draw\": [{\"plane\": {\"normal\": [0, 0, 0]}}]}", "draw[0].plane.normal", "non-zero");
  expect_error("{\"draw\": [{\"plane\": {\"size\": 1}}]}", "draw[0].plane.size", "unknown key");
  expect_error("{\"draw\": [{\"instrument\": \"instrument0\"}]}", "draw[0].urdf", "needs its urdf");
  expect_error("{\"draw\": [{\"instrument\": \"instrument0\", \"urdf\": \"\"}]}", "draw[0].urdf", "the hand's instruments");
  expect_error("{\"draw\": [{\"instrument\": \"instrument0\", \"urdf\": 3}]}", "draw[0].urdf", "the hand's instruments");
  expect_error("{\"draw\": [{\"mesh\": \"skin\", \"urdf\": \"needle_holder\"}]}", "draw[0].urdf", "only instruments");
  expect_error("[1]", "", "an object");
}

// an instrument entry: its components (links, held), its list of URDFs, steel by default
static void instrument_entry(void** state) {
  (void)state;
  tx_view_def d;
  assert_int_equal(parse("{\"draw\": [{\"instrument\": \"instrument1\", \"urdf\": \"needle_holder metzenbaum_scissors\"}]}", &d), 0);
  assert_int_equal(d.items[0].kind, TX_DRAW_INSTRUMENT);
  assert_string_equal(d.items[0].urdf, "needle_holder metzenbaum_scissors");
  char comps[3][TX_NAME_MAX];
  assert_int_equal(tx_draw_item_components(&d.items[0], comps), 2);
  assert_string_equal(comps[0], "instrument1.links");
  assert_string_equal(comps[1], "instrument1.held");
  assert_true(d.items[0].colour[0] > 0.7f && d.items[0].colour[2] > d.items[0].colour[0]);
}

// a value of the wrong type is named in the words of the parameter readers (tx_json_kind)
static void wrong_types_named_as_parameters_name_them(void** state) {
  (void)state;
  expect_error("{\"stereo\": \"sbs\"}", "stereo", "got a string");
  expect_error("{\"draw\": [3]}", "draw[0]", "got a number");
  expect_error("{\"camera\": null}", "camera", "got null");
  expect_error("{\"camera\": [1]}", "camera", "got an array");
  expect_error("{\"draw\": [{\"tool\": \"device0\", \"show_force\": 1}]}", "draw[0].show_force", "got a number");
  expect_error("{\"camera\": {\"eye\": {}, \"target\": [0, 0, 0]}}", "camera.eye", "got an object");
  expect_error("{\"draw\": [{\"mesh\": \"skin\", \"colour\": true}]}", "draw[0].colour", "got a boolean");
}

static void automatic_draw_list(void** state) {
  (void)state;
  const char* written[] = {"tool0.force_model", "skin.x", "device0.pose", "skin.tri", "tissue.spheres", "tissue.damage",
                           "lonely.x", "thread.segments", "device0.force", "probe.pose", "skin.thickness"};
  tx_view_def d = tx_view_def_default();
  assert_int_equal(tx_view_def_auto_draw(&d, written, 11), 4); // probe.pose is no device
  assert_int_equal(d.items[0].kind, TX_DRAW_MESH); // skin.x with skin.tri; lonely.x has no triangles
  assert_string_equal(d.items[0].name, "skin");
  assert_int_equal(d.items[1].kind, TX_DRAW_TOOL);
  assert_string_equal(d.items[1].name, "device0");
  assert_true(d.items[1].show_force);
  assert_string_equal(d.items[1].proxy, "tool0.force_model"); // device0's force model is tool0's
  char comps[3][TX_NAME_MAX];
  assert_int_equal(tx_draw_item_components(&d.items[1], comps), 3);
  assert_string_equal(comps[2], "tool0.force_model");
  assert_int_equal(d.items[2].kind, TX_DRAW_SPHERES);
  assert_string_equal(d.items[2].scalar, "tissue.damage");
  assert_int_equal(d.items[3].kind, TX_DRAW_SEGMENTS);
  const char* none[] = {"rates.mesh", "tool0.force_model"};
  assert_int_equal(tx_view_def_auto_draw(&d, none, 2), 0);
}

// the graphics view gets "view" as text (tx_param_json_text): the same rules, and text that is not JSON is an error
// a tool's proxy: a force model component, read after its pose (and force); on nothing but a tool
static void tool_proxy(void** state) {
  (void)state;
  tx_view_def d = tx_view_def_default();
  assert_int_equal(tx_view_def_from_text("{\"draw\": [{\"tool\": \"device1\", \"proxy\": \"tool1.force_model\"}]}", &d), 0);
  assert_string_equal(d.items[0].proxy, "tool1.force_model");
  char comps[3][TX_NAME_MAX];
  assert_int_equal(tx_draw_item_components(&d.items[0], comps), 2);
  assert_string_equal(comps[0], "device1.pose");
  assert_string_equal(comps[1], "tool1.force_model");
  expect_error("{\"draw\": [{\"mesh\": \"skin\", \"proxy\": \"tool0.force_model\"}]}", "draw[0].proxy", "only tools show a proxy");
  expect_error("{\"draw\": [{\"tool\": \"device0\", \"proxy\": \"tool0.pose\"}]}", "draw[0].proxy",
               "expected a force model component such as tool0.force_model");
  expect_error("{\"draw\": [{\"tool\": \"device0\", \"proxy\": 3}]}", "draw[0].proxy", "expected a force model");
}

// markers: a puncture list and the skin its rows index, read in that order; bad input names its key
static void markers_entry(void** state) {
  (void)state;
  tx_view_def d = tx_view_def_default();
  assert_int_equal(tx_view_def_from_text("{\"draw\": [{\"markers\": {\"punctures\": \"needle.punctures\", \"skin\": \"skin\"}}]}", &d), 0);
  assert_int_equal(d.items[0].kind, TX_DRAW_MARKERS);
  assert_true(d.items[0].radius == 0.0015f);
  assert_true(d.items[0].colour[0] > 2 * d.items[0].colour[1]); // magenta by default
  char comps[3][TX_NAME_MAX];
  assert_int_equal(tx_draw_item_components(&d.items[0], comps), 2);
  assert_string_equal(comps[0], "needle.punctures");
  assert_string_equal(comps[1], "skin.x");
  assert_int_equal(tx_view_def_from_text("{\"draw\": [{\"markers\": {\"punctures\": \"a.punctures\", \"skin\": \"s\"}, "
                                         "\"radius_m\": 0.003, \"colour\": [0, 1, 0]}]}", &d), 0);
  assert_true(d.items[0].radius == 0.003f && d.items[0].colour[1] == 1);
  expect_error("{\"draw\": [{\"markers\": \"needle.punctures\"}]}", "draw[0].markers", "expected an object");
  expect_error("{\"draw\": [{\"markers\": {\"skin\": \"skin\"}}]}", "draw[0].markers.punctures", "expected a puncture list");
  expect_error("{\"draw\": [{\"markers\": {\"punctures\": \"needle.pose\", \"skin\": \"skin\"}}]}", "draw[0].markers.punctures",
               "expected a puncture list");
  expect_error("{\"draw\": [{\"markers\": {\"punctures\": 7, \"skin\": \"skin\"}}]}", "draw[0].markers.punctures",
               "expected a puncture list");
  expect_error("{\"draw\": [{\"markers\": {\"punctures\": \"needle.punctures\"}}]}", "draw[0].markers.skin", "expected the skin");
  expect_error("{\"draw\": [{\"markers\": {\"punctures\": \"needle.punctures\", \"skin\": [1]}}]}", "draw[0].markers.skin",
               "expected the skin");
  expect_error("{\"draw\": [{\"markers\": {\"punctures\": \"needle.punctures\", \"skin\": \"skin\", \"grasps\": 1}}]}",
               "draw[0].markers.grasps", "unknown key");
  expect_error("{\"draw\": [{\"markers\": {\"punctures\": \"n.punctures\", \"skin\": \"skin\"}, \"radius_m\": -1}]}",
               "draw[0].radius_m", "expected a number");
  expect_error("{\"draw\": [{\"mesh\": \"skin\", \"radius_m\": 0.01}]}", "draw[0].radius_m", "only tools and markers take a radius");
  expect_error("{\"draw\": [{\"markers\": {\"punctures\": \"n.punctures\", \"skin\": \"skin\"}, \"mesh\": \"skin\"}]}", "draw[0]",
               "expected exactly one of");
}

// markers of grasps and knots: event streams, and the thread a knot's nodes are on
static void markers_events(void** state) {
  (void)state;
  tx_view_def d = tx_view_def_default();
  assert_int_equal(tx_view_def_from_text("{\"draw\": [{\"markers\": {\"events\": [\"instruments.events\", \"thread.events\"], "
                                         "\"thread\": \"thread\"}}]}", &d), 0);
  assert_int_equal(d.items[0].nevents, 2);
  assert_string_equal(d.items[0].events[1], "thread.events");
  char comps[3][TX_NAME_MAX];
  assert_int_equal(tx_draw_item_components(&d.items[0], comps), 1);
  assert_string_equal(comps[0], "thread.spheres");
  assert_int_equal(tx_view_def_from_text("{\"draw\": [{\"markers\": {\"punctures\": \"needle.punctures\", \"skin\": \"skin\", "
                                         "\"events\": [\"instruments.events\"], \"thread\": \"t\"}}]}", &d), 0);
  assert_int_equal(tx_draw_item_components(&d.items[0], comps), 3);
  assert_string_equal(comps[0], "needle.punctures");
  assert_string_equal(comps[1], "skin.x");
  assert_string_equal(comps[2], "t.spheres");
  expect_error("{\"draw\": [{\"markers\": {\"events\": []}}]}", "draw[0].markers.events", "expected an array of 1 to 4");
  expect_error("{\"draw\": [{\"markers\": {\"events\": \"instruments.events\"}}]}", "draw[0].markers.events", "expected an array");
  expect_error("{\"draw\": [{\"markers\": {\"events\": [\"a\", \"b\", \"c\", \"d\", \"e\"]}}]}", "draw[0].markers.events",
               "expected an array of 1 to 4");
  expect_error("{\"draw\": [{\"markers\": {\"events\": [\"Bad Name\"]}}]}", "draw[0].markers.events", "entry 0");
  expect_error("{\"draw\": [{\"markers\": {\"events\": [\"e\"], \"thread\": 3}}]}", "draw[0].markers.thread", "expected the thread");
  expect_error("{\"draw\": [{\"markers\": {\"thread\": \"thread\"}}]}", "draw[0].markers.punctures", "or events");
  expect_error("{\"draw\": [{\"markers\": {\"events\": [\"e\"], \"skin\": \"skin\"}}]}", "draw[0].markers.skin", "give punctures");
}

// the live list: a grasp until its hand's release, knots kept, a full list counts what it refuses
static void marker_list(void** state) {
  (void)state;
  tx_marker_list l = {0};
  tx_event g = {.kind = TX_EVENT_GRASP, .source = 1};
  g.grasp.point[0] = 0.01, g.grasp.point[1] = 0.02, g.grasp.point[2] = 0.03;
  tx_marker_take(&l, &g);
  g.source = 0;
  tx_marker_take(&l, &g);
  tx_event k = {.kind = TX_EVENT_KNOT, .source = 0, .value = {3, 9, 0}};
  tx_marker_take(&l, &k);
  assert_int_equal(l.n, 3);
  assert_true(l.m[0].p[1] == 0.02f && l.m[0].source == 1);
  assert_int_equal(l.m[2].first, 3), assert_int_equal(l.m[2].last, 9);
  tx_marker_take(&l, &(tx_event){.kind = TX_EVENT_RELEASE, .source = 1}); // hand 1's grasp ends, hand 0's stays
  assert_int_equal(l.n, 2);
  assert_int_equal(l.m[0].kind, TX_EVENT_GRASP), assert_int_equal(l.m[0].source, 0);
  assert_int_equal(l.m[1].kind, TX_EVENT_KNOT);
  tx_marker_take(&l, &(tx_event){.kind = TX_EVENT_CUT}); // not a marker
  tx_marker_take(&l, &(tx_event){.kind = TX_EVENT_KNOT, .value = {5, 2, 0}}); // last before first: bad
  g.grasp.point[0] = NAN;
  tx_marker_take(&l, &g);
  assert_int_equal(l.n, 2);
  for (int i = 0; i < TX_MARKERS_MAX; i++) tx_marker_take(&l, &k);
  assert_int_equal(l.n, TX_MARKERS_MAX);
  assert_int_equal(l.dropped, 2);
}

static void from_text(void** state) {
  (void)state;
  tx_view_def d = tx_view_def_default();
  assert_int_equal(tx_view_def_from_text("{\"width\":320,\"camera\":{\"fov_deg\":30}}", &d), 0);
  assert_int_equal(d.width, 320);
  assert_true(fabs(d.camera.fov_y - 30 * M_PI / 180) < 1e-12);
  d = tx_view_def_default();
  assert_int_equal(tx_view_def_from_text("{\"width\":-1}", &d), -1);
  assert_string_equal(tx_error_key(), "width");
  assert_int_equal(tx_view_def_from_text("{\"width\":", &d), -1);
  assert_non_null(strstr(tx_error(), "not JSON"));
  assert_int_equal(tx_view_def_from_text("[1]", &d), -1);
  assert_non_null(strstr(tx_error(), "expected an object"));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(full_view),
      cmocka_unit_test(errors_name_the_key),
      cmocka_unit_test(wrong_types_named_as_parameters_name_them),
      cmocka_unit_test(automatic_draw_list),
      cmocka_unit_test(from_text),
      cmocka_unit_test(tool_proxy),
      cmocka_unit_test(markers_entry),
      cmocka_unit_test(markers_events),
      cmocka_unit_test(marker_list),
      cmocka_unit_test(instrument_entry),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
