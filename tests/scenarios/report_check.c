// Checks a run's report.json for the tests, so that they need neither jq nor python.
//
//   report_check REPORT keys                 every documented key, with its JSON type
//   report_check REPORT steps NAME N [...]   controller NAME ran exactly N steps, none missed
//   report_check STUDY study                 haptic-stability.json: its keys, within 25% of
//                                            Colgate's bound and 5% of the exact boundary,
//                                            for each wall damping too
//
// Exit status 0 when the report passes, 1 with one line on stderr when it does not.
#include <jansson.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char* report_path;

static int bad(const char* what, const char* key) {
  fprintf(stderr, "report_check: %s: %s: %s\n", report_path, key, what);
  return 1;
}

static int need_number(const json_t* o, const char* key, const char* where) {
  char full[128];
  snprintf(full, sizeof full, "%s%s", where, key);
  return json_is_number(json_object_get(o, key)) ? 0 : bad("expected a number", full);
}

static int need_string(const json_t* o, const char* key, const char* where) {
  char full[128];
  snprintf(full, sizeof full, "%s%s", where, key);
  const json_t* v = json_object_get(o, key);
  return json_is_string(v) && *json_string_value(v) ? 0 : bad("expected a non-empty string", full);
}

// {p50, p99, max}, ordered as percentiles must be
static int need_percentiles(const json_t* c, const char* key, const char* where) {
  char full[128];
  snprintf(full, sizeof full, "%s%s", where, key);
  const json_t* p = json_object_get(c, key);
  if (!json_is_object(p)) return bad("expected an object", full);
  snprintf(full, sizeof full, "%s%s.", where, key);
  if (need_number(p, "p50", full) || need_number(p, "p99", full) || need_number(p, "max", full)) return 1;
  double p50 = json_number_value(json_object_get(p, "p50")), p99 = json_number_value(json_object_get(p, "p99")),
         max = json_number_value(json_object_get(p, "max"));
  if (!(0 <= p50 && p50 <= p99 && p99 <= max)) return bad("expected 0 <= p50 <= p99 <= max", full);
  return 0;
}

static int check_keys(const json_t* r) {
  if (need_string(r, "scenario", "") || need_string(r, "mode", "") || need_number(r, "duration_s", "")) return 1;
  const char* mode = json_string_value(json_object_get(r, "mode"));
  if (strcmp(mode, "lockstep") != 0 && strcmp(mode, "realtime") != 0) return bad("expected lockstep or realtime", "mode");
  if (!json_is_object(json_object_get(r, "warnings"))) return bad("expected an object", "warnings");
  const json_t* list = json_object_get(r, "controllers");
  if (!json_is_array(list) || json_array_size(list) == 0) return bad("expected a non-empty array", "controllers");
  size_t i;
  const json_t* c;
  json_array_foreach(list, i, c) {
    char where[64];
    snprintf(where, sizeof where, "controllers[%zu].", i);
    if (!json_is_object(c)) return bad("expected an object", where);
    if (need_string(c, "name", where) || need_string(c, "thread", where) || need_number(c, "target_hz", where) ||
        need_number(c, "achieved_hz", where) || need_number(c, "steps", where) || need_number(c, "missed", where) ||
        need_percentiles(c, "jitter_us", where) || need_percentiles(c, "step_us", where))
      return 1;
  }
  return 0;
}

static int check_steps(const json_t* r, int argc, char** argv) {
  if (argc < 2 || argc % 2) return fprintf(stderr, "report_check: steps: expected NAME N pairs\n"), 1;
  for (int a = 0; a < argc; a += 2) {
    const json_t* found = NULL;
    size_t i;
    const json_t* c;
    json_array_foreach(json_object_get(r, "controllers"), i, c) {
      const char* name = json_string_value(json_object_get(c, "name"));
      if (name && strcmp(name, argv[a]) == 0) found = c;
    }
    if (!found) return bad("no such controller in the report", argv[a]);
    long long want = strtoll(argv[a + 1], NULL, 10);
    long long steps = json_integer_value(json_object_get(found, "steps"));
    long long missed = json_integer_value(json_object_get(found, "missed"));
    if (steps != want || missed != 0) {
      fprintf(stderr, "report_check: %s: %s: %lld steps and %lld missed, expected %lld and 0\n", report_path, argv[a],
              steps, missed, want);
      return 1;
    }
  }
  return 0;
}

static int check_study(const json_t* r) {
  const json_t* cases = json_object_get(r, "cases");
  if (!json_is_array(cases) || json_array_size(cases) == 0) return bad("expected a non-empty array", "cases");
  size_t i;
  const json_t* c;
  json_array_foreach(cases, i, c) {
    char where[32];
    snprintf(where, sizeof where, "cases[%zu].", i);
    if (need_number(c, "period_s", where) || need_number(c, "k_max_theory", where) ||
        need_number(c, "k_max_exact", where) || need_number(c, "k_max_measured", where) ||
        need_number(c, "k_max_with_passivity_control", where) ||
        need_number(c, "k_max_with_port_passivity_control", where))
      return 1;
    double theory = json_number_value(json_object_get(c, "k_max_theory"));
    double exact = json_number_value(json_object_get(c, "k_max_exact"));
    double measured = json_number_value(json_object_get(c, "k_max_measured"));
    if (!(measured > 0.75 * theory && measured < 1.25 * theory)) return bad("measured not within 25% of theory", where);
    if (!(measured > 0.95 * exact && measured < 1.05 * exact)) return bad("measured not within 5% of exact", where);
    const json_t* walls = json_object_get(c, "wall_damping");
    if (!json_is_array(walls) || json_array_size(walls) < 2) return bad("expected an array of 2 or more", where);
    size_t j;
    const json_t* w;
    json_array_foreach(walls, j, w) {
      char at[96];
      snprintf(at, sizeof at, "%swall_damping[%zu].", where, j);
      if (need_number(w, "wall_damping_n_s_m", at) || need_number(w, "k_max_theory", at) ||
          need_number(w, "k_max_exact", at) || need_number(w, "k_max_measured", at))
        return 1;
      double we = json_number_value(json_object_get(w, "k_max_exact"));
      double wm = json_number_value(json_object_get(w, "k_max_measured"));
      if (!(wm > 0.95 * we && wm < 1.05 * we)) return bad("measured not within 5% of exact", at);
    }
  }
  return 0;
}

int main(int argc, char** argv) {
  if (argc < 3) return fprintf(stderr, "usage: report_check REPORT keys | REPORT steps NAME N [NAME N ...]\n"), 2;
  report_path = argv[1];
  json_error_t e;
  json_t* r = json_load_file(report_path, JSON_REJECT_DUPLICATES, &e);
  if (!r) return fprintf(stderr, "report_check: %s:%d:%d: %s\n", report_path, e.line, e.column, e.text), 1;
  int rc;
  if (!json_is_object(r)) rc = bad("expected an object", "(top)");
  else if (strcmp(argv[2], "keys") == 0) rc = check_keys(r);
  else if (strcmp(argv[2], "steps") == 0) rc = check_keys(r) || check_steps(r, argc - 3, argv + 3);
  else if (strcmp(argv[2], "study") == 0) rc = check_study(r);
  else {
    fprintf(stderr, "report_check: unknown check '%s'\n", argv[2]);
    rc = 2;
  }
  json_decref(r);
  return rc;
}
