// Checks the run of the plugin in docs/writing-a-controller.md: the
// demo.counter instance of SCENARIO ran rate x duration steps (report.json),
// published demo.count once per step, and its last publish holds steps x gain
// (trace.csv keeps a hash of every payload, so the value itself is checked).
//
//   check_demo_run SCENARIO.json OUT_DIR DURATION_S
#include <tactus/tactus.h>

#include <inttypes.h>
#include <jansson.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failed(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
static int failed(const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  fputs("check_demo_run: ", stderr);
  vfprintf(stderr, fmt, ap);
  fputc('\n', stderr);
  va_end(ap);
  return 1;
}

static json_t* load(const char* path) {
  json_error_t e;
  json_t* j = json_load_file(path, 0, &e);
  if (!j) failed("%s:%d:%d: %s", path, e.line, e.column, e.text);
  return j;
}

// the first object in array whose key holds the string value
static json_t* find(json_t* array, const char* key, const char* value) {
  size_t i;
  json_t* e;
  json_array_foreach(array, i, e) {
    const char* v = json_string_value(json_object_get(e, key));
    if (v && strcmp(v, value) == 0) return e;
  }
  return NULL;
}

int main(int argc, char** argv) {
  if (argc != 4) return failed("usage: check_demo_run SCENARIO.json OUT_DIR DURATION_S"), 2;
  const double duration = atof(argv[3]);
  char report_path[4096], trace_path[4096];
  snprintf(report_path, sizeof report_path, "%s/report.json", argv[2]);
  snprintf(trace_path, sizeof trace_path, "%s/trace.csv", argv[2]);
  json_t* scenario = load(argv[1]);
  json_t* report = load(report_path);
  if (!scenario || !report) return 1;

  // what the scenario asked for
  json_t* demo = find(json_object_get(scenario, "controllers"), "type", "demo.counter");
  if (!demo) return failed("%s: no controller of type demo.counter", argv[1]);
  const char* name = json_string_value(json_object_get(demo, "name"));
  const double rate = json_number_value(json_object_get(demo, "rate_hz"));
  json_t* g = json_object_get(json_object_get(demo, "params"), "gain");
  const double gain = g ? json_number_value(g) : 1.0; // the example's default
  const uint64_t expected = (uint64_t)llround(rate * duration);
  if (!name || expected == 0) return failed("%s: the demo.counter needs a name and a rate", argv[1]);

  // what the report says it did
  const char* mode = json_string_value(json_object_get(report, "mode"));
  if (!mode || strcmp(mode, "lockstep") != 0) return failed("%s: mode is not lockstep", report_path);
  json_t* entry = find(json_object_get(report, "controllers"), "name", name);
  if (!entry) return failed("%s: no controller '%s'", report_path, name);
  const uint64_t steps = (uint64_t)json_integer_value(json_object_get(entry, "steps"));
  if (steps != expected)
    return failed("%s: ran %" PRIu64 " steps, expected rate x duration = %" PRIu64, name, steps, expected);

  // what it published: one line per publish, the last one holding steps x gain
  FILE* f = fopen(trace_path, "r");
  if (!f) return failed("%s: cannot open", trace_path);
  char line[512], who[TX_NAME_MAX], comp[TX_NAME_MAX];
  uint64_t publishes = 0, seq = 0, last_seq = 0, hash = 0, last_hash = 0;
  int64_t sim_ns;
  unsigned rows;
  while (fgets(line, sizeof line, f)) {
    if (sscanf(line, "%" SCNd64 ",%63[^,],%63[^,],%" SCNu64 ",%u,%" SCNx64, &sim_ns, who, comp, &seq, &rows, &hash) != 6)
      continue; // the header line
    if (strcmp(who, name) != 0 || strcmp(comp, "demo.count") != 0) continue;
    publishes++;
    last_seq = seq;
    last_hash = hash;
  }
  fclose(f);
  if (publishes != expected || last_seq != expected)
    return failed("%s: demo.count published %" PRIu64 " times (last seq %" PRIu64 "), expected once per step", name,
                  publishes, last_seq);
  const double value = gain * (double)expected;
  const uint64_t want = tx_hash(TX_HASH_SEED, &value, sizeof value);
  if (last_hash != want)
    return failed("%s: the last demo.count is not steps x gain = %g (payload hash %016" PRIx64 ", expected %016" PRIx64 ")",
                  name, value, last_hash, want);

  printf("check_demo_run: %s ran %" PRIu64 " steps at %g Hz; demo.count ends at %g\n", name, steps, rate, value);
  json_decref(scenario);
  json_decref(report);
  return 0;
}
