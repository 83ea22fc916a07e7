// The scenario the physics.instruments cases share: device0's scripted hand
// (haptics at 1 kHz, rendering instrument0's force model) on a waypoint CSV
// in a temporary file, physics.instruments at 1 kHz with the case's
// parameters, and the case's other controllers before and after it.
// Included by test_instruments_controller.c after cmocka and tactus.
#ifndef TX_TESTS_INSTRUMENTS_FIXTURE_H
#define TX_TESTS_INSTRUMENTS_FIXTURE_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct instruments_fixture {
  char path[64]; // the hand's CSV, removed by fixture_free
  tx_scenario* s;
} instruments_fixture;

// a new temporary CSV for the hand, named after the case
static void fixture_path(instruments_fixture* f, const char* tag) {
  snprintf(f->path, sizeof f->path, "/tmp/tx-%s-XXXXXX.csv", tag);
  int fd = mkstemps(f->path, 4);
  assert_true(fd >= 0);
  close(fd);
  f->s = NULL;
}

// The scenario on the hand's CSV at path: before and after (JSON controller
// objects, each list ending, or starting, with a comma; "" for none),
// params (the physics.instruments parameters, JSON members); NULL with
// tx_error() when it does not load.
static tx_scenario* fixture_scenario(const char* path, const char* before, const char* params, const char* after) {
  char text[4096];
  int n = snprintf(text, sizeof text,
                   "{\"name\":\"t\",\"controllers\":["
                   "{\"name\":\"haptics\",\"type\":\"haptics\",\"rate_hz\":1000,\"params\":{\"device\":\"scripted:%s\","
                   "\"force_model\":\"instrument0.force_model\"}},%s"
                   "{\"name\":\"instruments\",\"type\":\"physics.instruments\",\"rate_hz\":1000,\"params\":{%s}}%s]}",
                   path, before, params, after);
  assert_true(n > 0 && n < (int)sizeof text);
  return tx_scenario_load_text("test", text, strlen(text), NULL);
}

// fixture_scenario on f's CSV, written from rows first (its text, header
// included; NULL: written already); fails the case when it does not load
static tx_scenario* fixture_load(instruments_fixture* f, const char* rows, const char* before, const char* params,
                                 const char* after) {
  if (rows) {
    FILE* out = fopen(f->path, "w");
    assert_non_null(out);
    fputs(rows, out);
    fclose(out);
  }
  f->s = fixture_scenario(f->path, before, params, after);
  if (!f->s) fail_msg("%s", tx_error());
  return f->s;
}

static void fixture_free(instruments_fixture* f) {
  unlink(f->path);
  tx_scenario_free(f->s);
  f->s = NULL;
}

#endif
