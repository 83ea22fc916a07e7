// The run report: per-controller rates, jitter and step times, and warnings.
#include "report.h"

#include "../model/error.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

static json_t* percentiles_us(tx_percentiles p) {
  return json_pack("{s:f,s:f,s:f}", "p50", p.p50 * 1e-3, "p99", p.p99 * 1e-3, "max", p.max * 1e-3);
}

json_t* tx_report_json(const tx_report* r) {
  tx_system* s = r->system;
  json_t* controllers = json_array();
  for (int i = 0; i < tx_system_count(s); i++) {
    tx_controller_stats st = tx_system_stats(s, i);
    char thread[16];
    int t = tx_system_thread(s, i);
    snprintf(thread, sizeof thread, "t%d", t);
    json_array_append_new(controllers,
                          json_pack("{s:s,s:s,s:s,s:f,s:f,s:I,s:I,s:o,s:o}", "name", tx_system_name(s, i), "type",
                                    tx_system_class(s, i)->type, "thread", thread, "target_hz", tx_system_rate(s, i),
                                    "achieved_hz", st.achieved_hz, "steps", (json_int_t)st.steps, "missed",
                                    (json_int_t)st.missed, "jitter_us", percentiles_us(st.jitter_ns), "step_us",
                                    percentiles_us(st.step_ns)));
    json_t* c = json_array_get(controllers, json_array_size(controllers) - 1);
    if (tx_system_thread_name(s, t)) json_object_set_new(c, "thread_name", json_string(tx_system_thread_name(s, t)));
    if (tx_system_thread_own(s, t)) json_object_set_new(c, "own_thread", json_true());
  }
  json_t* warnings = json_object();
  for (int w = 0; w < tx_system_warnings(s); w++)
    json_object_set_new(warnings, tx_system_warning_key(s, w), json_integer((json_int_t)tx_system_warning_count(s, w)));
  // a haptics controller that misses a deadline is a stall the hand feels: a
  // warning, not only a number in the table
  for (int i = 0; i < tx_system_count(s); i++) {
    tx_controller_stats st = tx_system_stats(s, i);
    if (strncmp(tx_system_class(s, i)->type, "haptics", 7) != 0 || st.missed == 0) continue;
    char key[TX_WARNING_KEY_MAX + 32];
    snprintf(key, sizeof key, "%s.missed_deadlines", tx_system_name(s, i));
    json_object_set_new(warnings, key, json_integer((json_int_t)st.missed));
  }
  // event streams: what was sent, and any loss, which is a warning
  json_t* streams = json_object();
  for (int k = 0; k < tx_system_streams(s); k++) {
    tx_stream_info st = tx_system_stream(s, k);
    json_t* lost = json_object();
    char key[TX_WARNING_KEY_MAX + 64];
    for (int rd = 0; rd < st.nreaders; rd++) {
      json_object_set_new(lost, st.readers[rd], json_integer((json_int_t)st.lost[rd]));
      snprintf(key, sizeof key, "%s.lost_by.%s", st.name, st.readers[rd]);
      if (st.lost[rd]) json_object_set_new(warnings, key, json_integer((json_int_t)st.lost[rd]));
    }
    snprintf(key, sizeof key, "%s.overflows", st.name);
    if (st.overflows) json_object_set_new(warnings, key, json_integer((json_int_t)st.overflows));
    json_object_set_new(streams, st.name,
                        json_pack("{s:s,s:I,s:I,s:I,s:o}", "writer", st.writer, "capacity", (json_int_t)st.capacity,
                                  "sent", (json_int_t)st.sent, "overflows", (json_int_t)st.overflows, "lost", lost));
  }
  if (!r->lockstep && !r->result->fifo) json_object_set_new(warnings, "scheduler.no_sched_fifo", json_integer(1));
  if (!r->lockstep && !r->result->pinned) json_object_set_new(warnings, "scheduler.not_pinned", json_integer(1));

  json_t* results = json_object();
  for (int k = 0; k < tx_system_results(s); k++) {
    double v = tx_system_result(s, k); // a result never set is null, not a number
    json_object_set_new(results, tx_system_result_key(s, k), isfinite(v) ? json_real(v) : json_null());
  }
  json_t* report = json_pack("{s:s,s:s,s:f,s:o,s:o,s:o,s:s}", "scenario", r->scenario, "mode",
                             r->lockstep ? "lockstep" : "realtime", "duration_s", r->result->duration_s,
                             "controllers", controllers, "warnings", warnings, "results", results, "scheduler",
                             r->result->scheduler);
  if (tx_system_streams(s)) json_object_set_new(report, "streams", streams);
  else json_decref(streams);
  if (!r->lockstep) json_object_set_new(report, "host_steal_s", json_real(r->result->steal_s));
  if (r->lockstep) {
    char hash[17];
    snprintf(hash, sizeof hash, "%016llx", (unsigned long long)r->result->trace_hash);
    json_object_set_new(report, "trace_hash", json_string(hash));
  }
  if (r->result->stopped_early) json_object_set_new(report, "stopped_early", json_true());
  if (tx_system_tunes(s)) { // parameters changed during the run (the trainer's window), in order
    json_t* tuned = json_array();
    for (int k = 0; k < tx_system_tunes(s); k++) {
      tx_tune_info t = tx_system_tune_at(s, k);
      json_array_append_new(tuned, json_pack("{s:f,s:s,s:s,s:f}", "t_s", t.t_s, "controller", t.controller, "key",
                                             t.key, "value", t.value));
    }
    json_object_set_new(report, "tuned", tuned);
  }
  return report;
}

// room for a report of this system: a few hundred bytes per controller, key and value
static long report_bytes(tx_system* s) {
  int readers = 0;
  for (int k = 0; k < tx_system_streams(s); k++) readers += tx_system_stream(s, k).nreaders;
  return 8192 + 1024L * tx_system_count(s) + 160L * (tx_system_warnings(s) + tx_system_results(s)) +
         512L * tx_system_streams(s) + 256L * readers + 160L * TX_TUNES_MAX;
}

int tx_report_reserve(tx_system* s, const char* dir, const char* name) {
  char tmp[4200];
  snprintf(tmp, sizeof tmp, "%s/%s.tmp", dir, name);
  FILE* f = fopen(tmp, "w");
  int rc = f ? posix_fallocate(fileno(f), 0, report_bytes(s)) : errno;
  if (f && fclose(f) != 0 && !rc) rc = errno;
  if (rc == EOPNOTSUPP || rc == ENOSYS || rc == EINVAL) rc = 0; // a file system without it: no reservation, no fault
  if (rc) {
    tx_set_error("%s: %s", tmp, strerror(rc));
    remove(tmp);
    return -1;
  }
  return 0;
}

void tx_report_unreserve(const char* dir, const char* name) {
  char tmp[4200];
  snprintf(tmp, sizeof tmp, "%s/%s.tmp", dir, name);
  remove(tmp);
}

int tx_report_save(const json_t* json, const char* dir, const char* name) {
  char path[4096], tmp[4200];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  char* text = json_dumps(json, JSON_INDENT(2) | JSON_REAL_PRECISION(10));
  if (!text) return tx_set_error("%s: out of memory", path), -1;
  size_t len = strlen(text);
  // into the space tx_report_reserve set aside, if any: a full disk still takes the report
  FILE* f = fopen(tmp, "r+");
  if (!f) f = fopen(tmp, "w");
  errno = 0;
  bool ok = f && fwrite(text, 1, len, f) == len && fflush(f) == 0 && ftruncate(fileno(f), (off_t)len) == 0;
  int e = errno;
  if (f && fclose(f) != 0 && ok) ok = false, e = errno;
  free(text);
  if (!ok || rename(tmp, path) != 0) {
    if (ok) e = errno;
    tx_set_error("%s: %s", path, strerror(e ? e : EIO));
    remove(tmp);
    return -1;
  }
  return 0;
}

static double num(const json_t* o, const char* a, const char* b) {
  const json_t* v = json_object_get(o, a);
  if (b) v = json_object_get(v, b);
  return json_number_value(v);
}

void tx_report_print(FILE* f, const json_t* report) {
  fprintf(f, "%s: %s, %.2f s; %s\n", json_string_value(json_object_get(report, "scenario")),
          json_string_value(json_object_get(report, "mode")), num(report, "duration_s", NULL),
          json_string_value(json_object_get(report, "scheduler")));
  fprintf(f, "%-14s %-6s %10s %12s %9s %7s  %-26s %-26s\n", "controller", "thread", "target Hz", "achieved Hz",
          "steps", "missed", "jitter us p50/p99/max", "step us p50/p99/max");
  size_t i;
  json_t* c;
  json_array_foreach(json_object_get(report, "controllers"), i, c) {
    char jit[40], stp[40];
    snprintf(jit, sizeof jit, "%.1f/%.1f/%.1f", num(c, "jitter_us", "p50"), num(c, "jitter_us", "p99"),
             num(c, "jitter_us", "max"));
    snprintf(stp, sizeof stp, "%.1f/%.1f/%.1f", num(c, "step_us", "p50"), num(c, "step_us", "p99"),
             num(c, "step_us", "max"));
    fprintf(f, "%-14s %-6s %10.1f %12.3f %9.0f %7.0f  %-26s %-26s\n", json_string_value(json_object_get(c, "name")),
            json_string_value(json_object_get(c, "thread")), num(c, "target_hz", NULL), num(c, "achieved_hz", NULL),
            num(c, "steps", NULL), num(c, "missed", NULL), jit, stp);
  }
  const char* key;
  json_t* v;
  int shown = 0;
  json_object_foreach(json_object_get(report, "warnings"), key, v) {
    if (json_integer_value(v) == 0) continue;
    fprintf(f, "%s %s=%lld", shown++ ? "," : "warnings:", key, (long long)json_integer_value(v));
  }
  fprintf(f, "%s\n", shown ? "" : "warnings: none");
  shown = 0;
  json_object_foreach(json_object_get(report, "results"), key, v) {
    if (!json_is_number(v)) continue;
    fprintf(f, "%s %s=%.6g", shown++ ? "," : "results:", key, json_number_value(v));
  }
  if (shown) fprintf(f, "\n");
  double steal = json_number_value(json_object_get(report, "host_steal_s"));
  if (steal > 0)
    fprintf(f, "host steal: %.2f s of CPU time taken by the hypervisor during the run (%.1f%% of %ld CPUs)\n", steal,
            100 * steal / (num(report, "duration_s", NULL) * sysconf(_SC_NPROCESSORS_ONLN)), sysconf(_SC_NPROCESSORS_ONLN));
}
