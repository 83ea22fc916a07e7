// procedure.suture and view.scorecard through the loader, in lockstep, fed
// by a scripted stand-in for the instruments and the thread (test.suture_feed):
// four punctures (in and out of the near edge, in and out of the far edge),
// the thread pulled through all four to a 2 cm tail, wrapped 1.5 turns around the
// holder's jaws, a knot, the knot fixed, a second knot, a cut, the hands let
// go. Every step is done in order at the scripted times; the step text, the
// step events, the measures (bites 4 and 2.5 mm, knots, peak tension, a
// hand's 10 cm path) and OUT/scorecard.json agree; bad parameters are named.
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "scenarios/loader.h"
#include "tests/scenario_support.h"
#include "tests/controllers/procedure/suture_feed.h"
#include "controllers/procedure/suture_steps.h"

#include <tactus/components.h>
#include <tactus/events.h>

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

// the step events as they come
static tx_port heard_port;
static int heard[32][2]; // source, status
static int nheard;
static int listen_configure(tx_setup* s, void** self) {
  *self = NULL;
  heard_port = tx_setup_listen(s, "procedure.events");
  return 0;
}
static void listen_step(tx_ctx* c, void* self) {
  (void)self;
  for (tx_event e; tx_next_event(c, heard_port, &e);)
    if (e.kind == TX_EVENT_STEP && nheard < 32) heard[nheard][0] = (int)e.source, heard[nheard][1] = (int)e.value[0], nheard++;
}
static const tx_controller_class listen_class = {
    .type = "test.step_listener", .summary = "hears steps", .configure = listen_configure, .step = listen_step};

static tx_scenario* load_fed(const char* feed, const char* params) {
  if (!tx_find_controller(tx_test_suture_feed.type)) assert_int_equal(tx_register_controller(&tx_test_suture_feed), 0);
  if (!tx_find_controller(listen_class.type)) assert_int_equal(tx_register_controller(&listen_class), 0);
  char text[2048];
  snprintf(text, sizeof text,
           "{\"name\":\"t\",\"controllers\":["
           "{\"name\":\"feed\",\"type\":\"test.suture_feed\",\"rate_hz\":100,\"params\":{%s}},"
           "{\"name\":\"procedure\",\"type\":\"procedure.suture\",\"rate_hz\":100,\"params\":{%s}},"
           "{\"name\":\"hear\",\"type\":\"test.step_listener\",\"rate_hz\":100},"
           "{\"name\":\"scorecard\",\"type\":\"view.scorecard\",\"rate_hz\":30,\"params\":{\"scenario\":\"suturing\"}}]}",
           feed, params);
  nheard = 0;
  return tx_scenario_load_text("test", text, strlen(text), NULL);
}
static tx_scenario* load(const char* params) { return load_fed("", params); }

static void every_step_in_order(void** state) {
  (void)state;
  tx_scenario* s = load("\"wound_a_m\":[-0.015,0,0],\"wound_b_m\":[0.015,0,0]");
  if (!s) fail_msg("%s", tx_error());
  char dir[] = "/tmp/tx-suture-XXXXXX";
  assert_non_null(mkdtemp(dir));
  tx_run_options o = {.duration_s = 9, .lockstep = true, .out_dir = dir};
  tx_run_result r;
  assert_int_equal(tx_system_run(s->system, &o, &r), 0);

  // the steps at the scripted times (each at its 100 Hz step)
  const tx_procedure_step_state* st = (const tx_procedure_step_state*)latest(s, "procedure.steps");
  const double ends[8] = {2.0, 3.0, 4.0, 5.0, 5.5, 6.5, 7.5, 8.5};
  for (int i = 0; i < 8; i++) {
    assert_int_equal((int)st[i].status, TX_STEP_DONE);
    assert_true(fabs(st[i].t_end_s - ends[i]) < 1e-6);
    assert_true(fabs(st[i].t_start_s - (i ? ends[i - 1] : 0)) < 1e-6);
  }
  assert_true(result(s, "procedure.steps_done") == 8);
  assert_true(result(s, "procedure.step_F") == TX_STEP_DONE);
  assert_true(result(s, "scorecard.steps_done") == 8);
  const tx_procedure_step* text = (const tx_procedure_step*)latest_snapshot(s, "procedure.step").data;
  assert_string_equal(text->text, "done: 8 of 8 steps");
  const tx_procedure_step* names = (const tx_procedure_step*)latest_snapshot(s, "procedure.step_names").data;
  assert_string_equal(names[2].text, "C wrap the thread around the needle holder");
  // each step began and ended once, in order
  assert_int_equal(nheard, 16);
  for (int i = 0; i < 8; i++) {
    assert_int_equal(heard[2 * i][0], i), assert_int_equal(heard[2 * i][1], TX_STEP_UNDER_WAY);
    assert_int_equal(heard[2 * i + 1][0], i), assert_int_equal(heard[2 * i + 1][1], TX_STEP_DONE);
  }
  const tx_suture_measures* m = (const tx_suture_measures*)latest(s, "procedure.suture");
  assert_true(fabs(m->bite_entry_m - 0.004) < 1e-12);
  assert_true(fabs(m->bite_exit_m - 0.0025) < 1e-12);
  assert_true(m->punctures == 4 && m->knots == 2 && m->knots_fixed == 1);
  assert_true(fabs(m->peak_tension_n - 2.5) < 0.01);
  assert_true(fabs(m->path_m[0] - 0.1) < 1e-9);
  assert_true(m->path_m[1] == 0);

  // the scorecard, as other tools read it
  char path[128];
  snprintf(path, sizeof path, "%s/scorecard.json", dir);
  json_error_t e;
  json_t* card = json_load_file(path, 0, &e);
  if (!card) fail_msg("%s: %s", path, e.text);
  assert_string_equal(json_string_value(json_object_get(card, "scenario")), "suturing");
  json_t* steps = json_object_get(card, "steps");
  assert_int_equal(json_array_size(steps), 8);
  json_t* g = json_array_get(steps, 6);
  assert_string_equal(json_string_value(json_object_get(g, "id")), "G");
  assert_string_equal(json_string_value(json_object_get(g, "name")), "cut the thread");
  assert_true(json_is_true(json_object_get(g, "done")));
  assert_true(fabs(json_number_value(json_object_get(g, "t_end_s")) - 7.5) < 1e-6);
  json_t* bite = json_object_get(card, "bite_asymmetry_m");
  assert_true(fabs(json_number_value(json_object_get(bite, "value")) - 0.0015) < 1e-9);
  assert_string_equal(json_string_value(json_object_get(bite, "unit")), "m");
  assert_true(strlen(json_string_value(json_object_get(bite, "rule"))) > 20);
  assert_true(json_is_false(json_object_get(card, "bite_symmetric"))); // 1.5 mm apart: over the 1 mm tolerance
  json_decref(card);
  remove(path);
  snprintf(path, sizeof path, "%s/scorecard.png", dir);
  remove(path);
  rmdir(dir);
  tx_scenario_free(s);
}

// the same script, but the thread misses the stitch's last puncture (the far
// edge's exit): its tail beyond the entry is as short from 3 s, yet the
// thread is not through the wound, so B is still under way at 4.5 s
static void a_short_tail_short_of_the_exit_is_not_b(void** state) {
  (void)state;
  tx_scenario* s = load_fed("\"through\":3", "\"wound_a_m\":[-0.015,0,0],\"wound_b_m\":[0.015,0,0]");
  if (!s) fail_msg("%s", tx_error());
  tx_run_options o = {.duration_s = 4.5, .lockstep = true};
  tx_run_result r;
  assert_int_equal(tx_system_run(s->system, &o, &r), 0);
  const tx_procedure_step_state* st = (const tx_procedure_step_state*)latest(s, "procedure.steps");
  assert_int_equal((int)st[TX_SUTURE_A].status, TX_STEP_DONE);
  assert_int_equal((int)st[TX_SUTURE_B].status, TX_STEP_UNDER_WAY);
  assert_true(result(s, "procedure.step_B") != TX_STEP_DONE);
  tx_scenario_free(s);
}

static void bad_parameters(void** state) {
  (void)state;
  const char* bad[][2] = {
      {"\"wound_a_m\":[0,0]", "test: controllers[1].params.wound_a_m: expected [x, y, z] in m"},
      {"\"wound_b_m\":[-0.015,0.01,0]", "test: controllers[1].params.wound_b_m: the wound line is under 0.1 mm long across the skin (x-z)"},
      {"\"tail_m\":0", "test: controllers[1].params.tail_m: 0 is out of range [0.001, 1]"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    tx_scenario* s = load(bad[i][0]);
    if (s) {
      tx_scenario_free(s);
      fail_msg("loaded %s", bad[i][0]);
    }
    if (strcmp(tx_error(), bad[i][1]) != 0) fail_msg("got '%s', expected '%s'", tx_error(), bad[i][1]);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(every_step_in_order),
      cmocka_unit_test(a_short_tail_short_of_the_exit_is_not_b),
      cmocka_unit_test(bad_parameters),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
