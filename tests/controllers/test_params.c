// Parameter tables: configure reads through them, keys they lack are refused
// with the valid ones named, a table that drifts from the code or cannot be
// trusted is refused, and the built-in tables hold the libraries' defaults.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "controllers/collision/hip.h"
#include "controllers/voxel/needle.h"
#include "controllers/voxel/tissue.h"
#include "model/error.h"
#include "scenarios/loader.h"
#include "test_support.h"

#include <tactus/config.h>

#if TX_WITH_BULLET
#include "controllers/physics/bullet/cloth.h"
#endif

#include <math.h>

// what the probe class read in its last configure
static struct {
  int configured;
  double num;
  int64_t i;
  bool b;
  const char* str;
  int nstrs;
  const char* strs[4];
} seen;

static const tx_param_def probe_params[] = {
    {"num", TX_PARAM_NUM, "N/m", 0, 10, 2.5, NULL, "a number"},
    {"int", TX_PARAM_INT, "1", -3, 3, 1, NULL, "an integer"},
    {"flag", TX_PARAM_BOOL, NULL, 0, 0, 1, NULL, "a boolean"},
    {"name", TX_PARAM_STR, NULL, 0, 0, 0, "x.y", "a string"},
    {"names", TX_PARAM_STRS, NULL, 0, 4, 0, NULL, "strings"},
    {"computed", TX_PARAM_NUM, "s", 0, 1, 0, "from elsewhere", "a computed default"},
};

// "int" picks a misuse after the reads: -1 a key the table lacks, -2 the wrong
// kind, -3 tx_table_strs with too small an array; 2 tx_param_num with the
// table's default and range, 3 with another default
static int probe_configure(tx_setup* s, void** self) {
  *self = NULL;
  seen.configured++;
  seen.num = tx_table_num(s, "num");
  seen.i = tx_table_int(s, "int");
  seen.b = tx_table_bool(s, "flag");
  seen.str = tx_table_str(s, "name");
  seen.nstrs = tx_table_strs(s, "names", seen.strs, 4);
  double computed = tx_table_num(s, "computed");
  if (isnan(computed)) seen.num += 1000; // marks "not given"
  switch ((int)seen.i) {
  case -1: tx_table_num(s, "missing"); break;
  case -2: tx_table_int(s, "num"); break;
  case -3: {
    const char* few[2];
    tx_table_strs(s, "names", few, 2);
  } break;
  case 2: seen.num = tx_param_num(s, "num", 2.5, 0, 10); break;
  case 3: tx_param_num(s, "num", 3, 0, 10); break;
  }
  return 0;
}

static void probe_step(tx_ctx* c, void* self) { (void)c, (void)self; }

static const tx_controller_class probe = {.type = "test.probe", .configure = probe_configure, .step = probe_step,
                                          .params = probe_params, .nparams = TX_PARAMS_COUNT(probe_params)};

// a class without a table that calls tx_table_num
static int tableless_configure(tx_setup* s, void** self) {
  *self = NULL;
  tx_table_num(s, "x");
  return 0;
}
static const tx_controller_class tableless = {.type = "test.tableless", .configure = tableless_configure,
                                              .step = probe_step};

static int add(tx_system* sys, const char* type, const char* params) {
  json_t* p = params ? json_loads(params, 0, NULL) : NULL;
  assert_true(!params || p);
  memset(&seen, 0, sizeof seen);
  int rc = tx_system_add(sys, "c", type, 100, p);
  json_decref(p);
  return rc;
}

static int setup(void** state) {
  (void)state;
  if (!tx_find_controller("test.probe")) assert_int_equal(tx_register_controller(&probe), 0);
  if (!tx_find_controller("test.tableless")) assert_int_equal(tx_register_controller(&tableless), 0);
  return 0;
}

static void defaults_come_from_the_table(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  assert_int_equal(add(s, "test.probe", NULL), 0);
  assert_true(seen.num == 2.5 + 1000); // the computed default reads as NaN
  assert_int_equal(seen.i, 1);
  assert_true(seen.b);
  assert_string_equal(seen.str, "x.y");
  assert_int_equal(seen.nstrs, 0);
  tx_system_destroy(s);
}

static void values_are_read_and_range_checked(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  assert_int_equal(add(s, "test.probe", "{\"num\": 7, \"int\": 0, \"flag\": false, \"name\": \"a.b\", "
                                         "\"names\": [\"p\", \"q\"], \"computed\": 0.5}"), 0);
  assert_true(seen.num == 7);
  assert_int_equal(seen.i, 0);
  assert_false(seen.b);
  assert_string_equal(seen.str, "a.b");
  assert_int_equal(seen.nstrs, 2);
  assert_string_equal(seen.strs[1], "q");
  tx_system_destroy(s);

  const struct { const char* params; const char* key; const char* says; } bad[] = {
      {"{\"num\": 11}", "params.num", "out of range [0, 10]"},
      {"{\"num\": \"big\"}", "params.num", "expected a number"},
      {"{\"int\": 4}", "params.int", "out of range [-3, 3]"},
      {"{\"int\": 1.5}", "params.int", "expected an integer"},
      {"{\"flag\": 1}", "params.flag", "expected true or false"},
      {"{\"name\": 3}", "params.name", "expected a string"},
      {"{\"names\": [\"a\", \"b\", \"c\", \"d\", \"e\"]}", "params.names", "at most 4"},
      {"{\"computed\": 2}", "params.computed", "out of range [0, 1]"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    s = tx_system_create();
    assert_int_equal(add(s, "test.probe", bad[i].params), -1);
    assert_string_equal(tx_error_key(), bad[i].key);
    assert_non_null(strstr(tx_error(), bad[i].says));
    tx_system_destroy(s);
  }
}

static void unknown_keys_are_refused_before_configure_naming_the_valid_ones(void** state) {
  (void)state;
  tx_system* s = tx_system_create();
  assert_int_equal(add(s, "test.probe", "{\"num\": 1, \"nmu\": 2}"), -1);
  assert_string_equal(tx_error_key(), "params.nmu");
  assert_string_equal(tx_error(), "unknown parameter for test.probe (valid: num, int, flag, name, names, computed)");
  assert_int_equal(seen.configured, 0);
  tx_system_destroy(s);
}

static void misuse_of_the_table_is_a_programming_error(void** state) {
  (void)state;
  const struct { const char* params; const char* key; const char* says; } bad[] = {
      {"{\"int\": -1}", "params.missing", "programming error: test.probe reads a parameter its table lacks"},
      {"{\"int\": -2}", "params.num", "programming error: test.probe reads it as an integer, its table says a number"},
      {"{\"int\": -3}", "params.names", "programming error: test.probe keeps 2 entries, its table allows 4"},
      {"{\"int\": 3}", "params.num",
       "programming error: test.probe reads it with default 3 in [0, 10], its table says default 2.5 in [0, 10]"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    tx_system* s = tx_system_create();
    assert_int_equal(add(s, "test.probe", bad[i].params), -1);
    assert_string_equal(tx_error_key(), bad[i].key);
    assert_string_equal(tx_error(), bad[i].says);
    tx_system_destroy(s);
  }
  // tx_param_num with the table's own default and range reads as before
  tx_system* s = tx_system_create();
  assert_int_equal(add(s, "test.probe", "{\"int\": 2, \"num\": 4}"), 0);
  assert_true(seen.num == 4);
  tx_system_destroy(s);
  // tx_table_* needs a table
  s = tx_system_create();
  assert_int_equal(add(s, "test.tableless", NULL), -1);
  assert_string_equal(tx_error_key(), "params.x");
  assert_non_null(strstr(tx_error(), "test.tableless has no parameter table"));
  tx_system_destroy(s);
}

static void the_test_counter_names_its_valid_keys(void** state) {
  (void)state;
  register_test_classes(); // classes without a table: test_system's own
  tx_system* s = tx_system_create();
  assert_int_equal(add(s, "test.counter", "{\"gian\": 2}"), -1);
  assert_string_equal(tx_error_key(), "params.gian");
  assert_non_null(strstr(tx_error(), "(valid: gain, stop_at, write, read)"));
  tx_system_destroy(s);
}

static void untrustworthy_tables_are_refused_at_registration(void** state) {
  (void)state;
  const struct { tx_param_def def[2]; int n; const char* says; } bad[] = {
      {{{"a", TX_PARAM_NUM, "m", 0, 1, 2, NULL, "x"}}, 1, "params[0] a: default 2 is outside [0, 1]"},
      {{{"a", TX_PARAM_NUM, NULL, 0, 1, 0, NULL, "x"}}, 1, "params[0] a: a number needs units"},
      {{{"a", TX_PARAM_NUM, "m", 1, 0, 0, NULL, "x"}}, 1, "range [1, 0] is not finite and ordered"},
      {{{"a", TX_PARAM_NUM, "m", 0, INFINITY, 0, NULL, "x"}}, 1, "is not finite and ordered"},
      {{{"a", TX_PARAM_INT, "1", 0, 10, 0.5, NULL, "x"}}, 1, "an integer needs whole default and range"},
      {{{"a", TX_PARAM_INT, "1", 0, 10, 0, "text", "x"}}, 1, "an integer takes no computed default"},
      {{{"a", TX_PARAM_BOOL, NULL, 0, 0, 2, NULL, "x"}}, 1, "a boolean's default is 0 or 1"},
      {{{"a", TX_PARAM_STRS, NULL, 0, 0, 0, NULL, "x"}}, 1, "a list needs max in [1, 65536]"},
      {{{"a", (tx_param_kind)99, NULL, 0, 0, 0, NULL, "x"}}, 1, "unknown kind 99"},
      {{{"a", TX_PARAM_STR, NULL, 0, 0, 0, NULL, ""}}, 1, "params[0] a: no meaning given"},
      {{{"a", TX_PARAM_STR, NULL, 0, 0, 0, NULL, "x | y"}}, 1, "hold no '|' or line break"},
      {{{"a", TX_PARAM_STR, NULL, 0, 0, 0, "two\nlines", "x"}}, 1, "hold no '|' or line break"},
      {{{"Bad-Key", TX_PARAM_STR, NULL, 0, 0, 0, NULL, "x"}}, 1, "key 'Bad-Key' must be 1-63 characters"},
      {{{NULL, TX_PARAM_STR, NULL, 0, 0, 0, NULL, "x"}}, 1, "params[0]: key '' must be"},
      {{{"a", TX_PARAM_STR, NULL, 0, 0, 0, NULL, "x"}, {"a", TX_PARAM_BOOL, NULL, 0, 0, 0, NULL, "y"}}, 2,
       "params[1]: key 'a' appears twice"},
      {{{"a", TX_PARAM_STR, NULL, 0, 0, 0, NULL, "x"}}, -1, "nparams -1 is out of range"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    tx_controller_class cls = {.type = "test.bad_table", .configure = tableless_configure, .step = probe_step,
                               .params = bad[i].def, .nparams = bad[i].n};
    assert_int_equal(tx_register_controller(&cls), -1);
    assert_non_null(strstr(tx_error(), "test.bad_table: parameter table: "));
    if (!strstr(tx_error(), bad[i].says)) fail_msg("case %zu: '%s' lacks '%s'", i, tx_error(), bad[i].says);
  }
  tx_controller_class cls = {.type = "test.bad_table", .configure = tableless_configure, .step = probe_step,
                             .params = NULL, .nparams = 3};
  assert_int_equal(tx_register_controller(&cls), -1);
  assert_non_null(strstr(tx_error(), "nparams is 3 but params is NULL"));
  assert_null(tx_find_controller("test.bad_table"));
}

// the tables of the built-in classes keep the defaults of the libraries they configure
static const tx_param_def* def_of(const char* type, const char* key) {
  const tx_controller_class* cls = tx_find_controller(type);
  assert_non_null(cls);
  const tx_param_def* d = tx_param_find(cls, key);
  if (!d) fail_msg("%s has no parameter %s", type, key);
  return d;
}

static void builtin_tables_hold_the_library_defaults(void** state) {
  (void)state;
  tx_register_builtin();
  for (int i = 0; tx_controller_class_at(i); i++) // every built-in class has a table
    if (strncmp(tx_controller_class_at(i)->type, "test.", 5) != 0 && !tx_controller_class_at(i)->params)
      fail_msg("%s has no parameter table", tx_controller_class_at(i)->type);
  tx_hip_def h = tx_hip_def_default();
  assert_true(def_of("collision.hip", "radius_m")->def_num == h.radius);
  assert_true(def_of("collision.hip", "rays")->def_num == h.rays);
  assert_true(def_of("collision.hip", "alpha")->def_num == h.alpha);
  assert_true(def_of("collision.hip", "k")->def_num == h.k);
  assert_true(def_of("collision.hip", "slide_max_m")->def_num == h.slide_max);
  assert_true(def_of("collision.hip", "pierce_range_m")->def_num == h.pierce_range);
  assert_true(def_of("collision.hip", "hold_m")->def_num == h.hold);
  assert_string_equal(def_of("collision.hip", "join")->def_str, h.join_anchor ? "anchor" : "own");

  tx_voxel_tissue_def t = tx_voxel_tissue_def_default();
  const char* const sizes[3] = {"block_x_m", "block_y_m", "block_z_m"}, *const counts[3] = {"count_x", "count_y", "count_z"};
  for (int a = 0; a < 3; a++) {
    assert_true(def_of("voxel.needle", sizes[a])->def_num == t.block_size[a]);
    assert_true(def_of("voxel.needle", counts[a])->def_num == t.count[a]);
  }
  assert_true(def_of("voxel.needle", "mass_kg")->def_num == t.mass);
  assert_true(def_of("voxel.needle", "elasticity")->def_num == t.elasticity);
  assert_true(def_of("voxel.needle", "spring_n_m")->def_num == t.spring);
  assert_true(def_of("voxel.needle", "damper_n_s_m")->def_num == t.damper);
  assert_true(def_of("voxel.needle", "radius_m")->def_num == t.radius);
  assert_true(def_of("voxel.needle", "damage_shrink")->def_num == t.damage_shrink);
  assert_true(def_of("voxel.needle", "recovery_s")->def_num == t.recovery_time);
  assert_true(def_of("voxel.needle", "skin_m")->def_num == t.skin);
  tx_voxel_needle_def n = tx_voxel_needle_def_default();
  assert_true(def_of("voxel.needle", "gauge")->def_num == n.gauge);
  tx_needle_tip tip;
  assert_true(tx_needle_tip_parse(def_of("voxel.needle", "tip")->def_str, &tip) && tip == n.tip);
  assert_true(def_of("voxel.needle", "tip_angle_deg")->def_num == n.tip_angle_deg);
  assert_true(def_of("voxel.needle", "length_m")->def_num == n.length);
  assert_true(def_of("voxel.needle", "friction")->def_num == n.friction);
  assert_true(def_of("voxel.needle", "rupture_force_n")->def_num == n.rupture_force);
  assert_true(def_of("voxel.needle", "cutting_force_n")->def_num == n.cutting_force);
  assert_true(def_of("voxel.needle", "load_time_s")->def_num == n.load_time);
#if TX_WITH_BULLET
  tx_cloth_def c = tx_cloth_def_default();
  assert_true(def_of("physics.skin", "size_m")->def_num == c.size[0]);
  assert_true(fabs(def_of("physics.skin", "size_m")->def_num / def_of("physics.skin", "spacing_m")->def_num + 2 -
                   c.res[0]) < 1e-9); // size / spacing + 1 cells: res particles a side
  assert_true(def_of("physics.skin", "thickness_m")->def_num == c.thickness);
  assert_true(def_of("physics.skin", "mass_kg")->def_num == c.mass);
  assert_true(def_of("physics.skin", "stretch_stiffness")->def_num == c.stretch_stiffness);
  assert_true(def_of("physics.skin", "bend_stiffness")->def_num == c.bend_stiffness);
  assert_true(def_of("physics.skin", "damping")->def_num == c.damping);
  assert_true((def_of("physics.skin", "gravity")->def_num != 0) == (c.gravity != 0));
  assert_true((def_of("physics.skin", "fixed_border")->def_num != 0) == c.fixed_border);
  assert_true(def_of("physics.skin", "pretension_n_per_m")->def_num == c.pretension);
  assert_true(def_of("physics.skin", "rupture_tension_n_per_m")->def_num == c.rupture_tension);
  assert_true(def_of("physics.skin", "rupture_length_m")->def_num == c.rupture_length);
  assert_true(def_of("physics.skin", "iterations")->def_num == c.iterations);
  assert_true(def_of("physics.skin", "max_substep_s")->def_num == c.max_substep);
  assert_true(def_of("physics.skin", "max_speed")->def_num == c.max_speed);
#endif
}

// a parameter as `tactus describe` and the trainer's panel show it: a number
// in its shortest text that reads back, a given string or JSON value (cut
// to the width with "..."), and the table's default marked as such
static void parameters_as_text(void** state) {
  (void)state;
  static const tx_param_def num = {"gain", TX_PARAM_NUM, "N/m", 0, 1e9, 300, NULL, "a gain"};
  static const tx_param_def str = {"device", TX_PARAM_STR, NULL, 0, 0, 0, "scripted:pierce-down", "a device"};
  static const tx_param_def obj = {"view", TX_PARAM_JSON, NULL, 0, 0, 0, NULL, "a view"};
  char buf[96];
  assert_string_equal(tx_param_num_text(0.1, buf, sizeof buf), "0.1");
  assert_string_equal(tx_param_num_text(2e-05, buf, sizeof buf), "2e-5");
  assert_string_equal(tx_param_num_text(1e+100, buf, sizeof buf), "1e100");
  json_error_t e;
  json_t* given = json_loads("{\"gain\":1500.5,\"device\":\"sim\",\"view\":{\"camera\":[0,1,2],\"draw\":[\"skin\"]}}", 0, &e);
  assert_non_null(given);
  assert_string_equal(tx_param_value_text(&num, given, 30, buf, sizeof buf), "1500.5");
  assert_string_equal(tx_param_value_text(&str, given, 30, buf, sizeof buf), "\"sim\"");
  assert_string_equal(tx_param_value_text(&obj, given, 20, buf, sizeof buf), "{\"camera\":[0,1,2]...");
  assert_int_equal(strlen(buf), 20);
  assert_string_equal(tx_param_value_text(&num, NULL, 30, buf, sizeof buf), "300 (default)");
  assert_string_equal(tx_param_value_text(&str, NULL, 30, buf, sizeof buf), "\"scripted:pierce-down\" (default)");
  assert_string_equal(tx_param_default_text(&str, true, buf, sizeof buf), "`scripted:pierce-down`");
  json_decref(given);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(defaults_come_from_the_table),
      cmocka_unit_test(parameters_as_text),
      cmocka_unit_test(values_are_read_and_range_checked),
      cmocka_unit_test(unknown_keys_are_refused_before_configure_naming_the_valid_ones),
      cmocka_unit_test(misuse_of_the_table_is_a_programming_error),
      cmocka_unit_test(the_test_counter_names_its_valid_keys),
      cmocka_unit_test(untrustworthy_tables_are_refused_at_registration),
      cmocka_unit_test(builtin_tables_hold_the_library_defaults),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
