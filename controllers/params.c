// Configure-time API: parameters, declared ports and warnings of one instance.
// Errors are sticky: the first one is kept and later calls return defaults.
#include "system_internal.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char* tx_setup_name(const tx_setup* s) { return s->in->name; }
double tx_setup_rate(const tx_setup* s) { return s->in->rate_hz; }

static int vfail(tx_setup* s, const char* key, const char* fmt, va_list ap) {
  instance* in = s->in;
  if (in->failed) return -1;
  in->failed = true;
  snprintf(in->fault.key, sizeof in->fault.key, "%s%s", key ? "params." : "", key ? key : "");
  vsnprintf(in->fault.message, sizeof in->fault.message, fmt, ap);
  return -1;
}

int tx_setup_fail(tx_setup* s, const char* key, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vfail(s, key, fmt, ap);
  va_end(ap);
  return -1;
}

double tx_setup_rate_in(tx_setup* s, double lo, double hi) {
  double rate = s->in->rate_hz;
  if (rate >= lo && rate <= hi) return rate;
  tx_setup_fail(s, NULL, "%s runs at %g to %g Hz, not %g", s->in->cls->type, lo, hi, rate);
  return 0;
}

// the value of params.KEY, marked as used; NULL when absent or after an error
static json_t* param(tx_setup* s, const char* key) {
  if (s->in->failed || !key) return NULL;
  json_object_set_new(s->in->used, key, json_true());
  return s->in->params ? json_object_get(s->in->params, key) : NULL;
}

const tx_param_def* tx_param_find(const tx_controller_class* cls, const char* key) {
  for (int i = 0; cls && cls->params && key && i < cls->nparams; i++)
    if (strcmp(cls->params[i].key, key) == 0) return &cls->params[i];
  return NULL;
}

static const char* kind_name(tx_param_kind k) {
  static const char* const names[] = {"?", "a number", "an integer", "a boolean", "a string", "a list of strings", "JSON"};
  return k >= TX_PARAM_NUM && k <= TX_PARAM_JSON ? names[k] : names[0];
}

// In a class with a table: the entry for key, which must be of this kind.
// NULL without a table, or after an error (a table that lacks the key is a
// programming error, so that the table cannot drift from configure).
static const tx_param_def* entry(tx_setup* s, const char* key, tx_param_kind kind) {
  const tx_controller_class* cls = s->in->cls;
  if (!cls->params || s->in->failed) return NULL;
  const tx_param_def* d = tx_param_find(cls, key);
  if (!d)
    return tx_setup_fail(s, key, "programming error: %s reads a parameter its table lacks", cls->type), NULL;
  if (d->kind != kind)
    return tx_setup_fail(s, key, "programming error: %s reads it as %s, its table says %s", cls->type, kind_name(kind),
                         kind_name(d->kind)), NULL;
  return d;
}

// a tx_table_* call in a class without a table
static bool no_table(tx_setup* s, const char* key) {
  if (s->in->cls->params) return false;
  tx_setup_fail(s, key, "programming error: %s has no parameter table, read it with tx_param_*", s->in->cls->type);
  return true;
}

// a tx_param_* call whose default or range differs from the class's table
static bool drifted(tx_setup* s, const char* key, bool same, const char* code, const char* table) {
  if (same) return false;
  tx_setup_fail(s, key, "programming error: %s reads it with %s, its table says %s", s->in->cls->type, code, table);
  return true;
}

static bool same_num(double a, double b) { return a == b || (isnan(a) && isnan(b)); }

json_t* tx_param_json(tx_setup* s, const char* key) {
  if (s->in->cls->params && !entry(s, key, TX_PARAM_JSON)) return NULL;
  return param(s, key);
}

int tx_param_point(tx_setup* s, const char* key, const double def[3], double out[3]) {
  json_t* j = tx_param_json(s, key);
  memcpy(out, def, 3 * sizeof(double));
  if (!j || json_is_null(j)) return 0;
  if (!json_is_array(j) || json_array_size(j) != 3) return tx_setup_fail(s, key, "expected [x, y, z] in m");
  for (int a = 0; a < 3; a++) {
    json_t* v = json_array_get(j, (size_t)a);
    if (!json_is_number(v) || !isfinite(json_number_value(v)) || fabs(json_number_value(v)) > 10)
      return tx_setup_fail(s, key, "element %d must be a number in [-10, 10]", a);
    out[a] = json_number_value(v);
  }
  return 0;
}

const char* tx_json_kind(const json_t* v) {
  switch (json_typeof(v)) {
  case JSON_OBJECT: return "an object";
  case JSON_ARRAY: return "an array";
  case JSON_STRING: return "a string";
  case JSON_INTEGER: case JSON_REAL: return "a number";
  case JSON_TRUE: case JSON_FALSE: return "a boolean";
  case JSON_NULL: return "null";
  }
  return "?";
}

static double read_num(tx_setup* s, const char* key, double def, double min, double max) {
  json_t* v = param(s, key);
  if (!v) return def;
  if (!json_is_number(v)) return tx_setup_fail(s, key, "expected a number, got %s", tx_json_kind(v)), def;
  double x = json_number_value(v);
  if (!isfinite(x) || x < min || x > max)
    return tx_setup_fail(s, key, "%g is out of range [%g, %g]", x, min, max), def;
  return x;
}

static int64_t read_int(tx_setup* s, const char* key, int64_t def, int64_t min, int64_t max) {
  json_t* v = param(s, key);
  if (!v) return def;
  if (!json_is_integer(v)) return tx_setup_fail(s, key, "expected an integer, got %s", tx_json_kind(v)), def;
  int64_t x = json_integer_value(v);
  if (x < min || x > max)
    return tx_setup_fail(s, key, "%lld is out of range [%lld, %lld]", (long long)x, (long long)min, (long long)max), def;
  return x;
}

static bool read_bool(tx_setup* s, const char* key, bool def) {
  json_t* v = param(s, key);
  if (!v) return def;
  if (!json_is_boolean(v)) return tx_setup_fail(s, key, "expected true or false, got %s", tx_json_kind(v)), def;
  return json_is_true(v);
}

// keep a copy alive until fini, whatever happens to params
static const char* keep(tx_setup* s, const char* str) {
  json_t* copy = json_string(str);
  if (!copy || json_array_append_new(s->in->strings, copy)) return NULL;
  return json_string_value(copy);
}

static const char* read_str(tx_setup* s, const char* key, const char* def) {
  json_t* v = param(s, key);
  if (!v) return def;
  if (!json_is_string(v)) return tx_setup_fail(s, key, "expected a string, got %s", tx_json_kind(v)), def;
  return keep(s, json_string_value(v));
}

static int read_strs(tx_setup* s, const char* key, const char** out, int max) {
  json_t* v = param(s, key);
  if (!v) return 0;
  if (!json_is_array(v)) return tx_setup_fail(s, key, "expected an array of strings, got %s", tx_json_kind(v)), 0;
  if ((int)json_array_size(v) > max)
    return tx_setup_fail(s, key, "%zu entries, at most %d allowed", json_array_size(v), max), 0;
  size_t i;
  json_t* e;
  json_array_foreach(v, i, e) {
    if (!json_is_string(e)) return tx_setup_fail(s, key, "entry %zu: expected a string, got %s", i, tx_json_kind(e)), 0;
    out[i] = keep(s, json_string_value(e));
  }
  return (int)json_array_size(v);
}

double tx_table_num(tx_setup* s, const char* key) {
  if (no_table(s, key)) return NAN;
  const tx_param_def* d = entry(s, key, TX_PARAM_NUM);
  if (!d) return NAN;
  return read_num(s, key, d->def_str ? NAN : d->def_num, d->min, d->max);
}

int64_t tx_table_int(tx_setup* s, const char* key) {
  if (no_table(s, key)) return 0;
  const tx_param_def* d = entry(s, key, TX_PARAM_INT);
  if (!d) return 0;
  return read_int(s, key, (int64_t)d->def_num, (int64_t)d->min, (int64_t)d->max);
}

bool tx_table_bool(tx_setup* s, const char* key) {
  if (no_table(s, key)) return false;
  const tx_param_def* d = entry(s, key, TX_PARAM_BOOL);
  if (!d) return false;
  return read_bool(s, key, d->def_num != 0);
}

const char* tx_table_str(tx_setup* s, const char* key) {
  if (no_table(s, key)) return NULL;
  const tx_param_def* d = entry(s, key, TX_PARAM_STR);
  if (!d) return NULL;
  return read_str(s, key, d->def_str);
}

int tx_table_strs(tx_setup* s, const char* key, const char** out, int max) {
  if (no_table(s, key)) return 0;
  const tx_param_def* d = entry(s, key, TX_PARAM_STRS);
  if (!d) return 0;
  if (d->max > max)
    return tx_setup_fail(s, key, "programming error: %s keeps %d entries, its table allows %g", s->in->cls->type, max,
                         d->max), 0;
  return read_strs(s, key, out, (int)d->max);
}

double tx_param_num(tx_setup* s, const char* key, double def, double min, double max) {
  const tx_param_def* d = entry(s, key, TX_PARAM_NUM);
  char code[96], table[96];
  if (d) {
    snprintf(code, sizeof code, "default %g in [%g, %g]", def, min, max);
    snprintf(table, sizeof table, "default %g in [%g, %g]", d->def_str ? NAN : d->def_num, d->min, d->max);
    if (drifted(s, key, same_num(def, d->def_str ? NAN : d->def_num) && min == d->min && max == d->max, code, table))
      return def;
  }
  return read_num(s, key, def, min, max);
}

int64_t tx_param_int(tx_setup* s, const char* key, int64_t def, int64_t min, int64_t max) {
  const tx_param_def* d = entry(s, key, TX_PARAM_INT);
  char code[96], table[96];
  if (d) {
    snprintf(code, sizeof code, "default %lld in [%lld, %lld]", (long long)def, (long long)min, (long long)max);
    snprintf(table, sizeof table, "default %g in [%g, %g]", d->def_num, d->min, d->max);
    if (drifted(s, key, (double)def == d->def_num && (double)min == d->min && (double)max == d->max, code, table))
      return def;
  }
  return read_int(s, key, def, min, max);
}

bool tx_param_bool(tx_setup* s, const char* key, bool def) {
  const tx_param_def* d = entry(s, key, TX_PARAM_BOOL);
  if (d && drifted(s, key, def == (d->def_num != 0), def ? "default true" : "default false",
                   d->def_num != 0 ? "default true" : "default false"))
    return def;
  return read_bool(s, key, def);
}

const char* tx_param_str(tx_setup* s, const char* key, const char* def) {
  const tx_param_def* d = entry(s, key, TX_PARAM_STR);
  char code[128], table[128];
  if (d) {
    snprintf(code, sizeof code, "default \"%s\"", def ? def : "(none)");
    snprintf(table, sizeof table, "default \"%s\"", d->def_str ? d->def_str : "(none)");
    if (drifted(s, key, (!def && !d->def_str) || (def && d->def_str && strcmp(def, d->def_str) == 0), code, table))
      return def;
  }
  return read_str(s, key, def);
}

int tx_param_strs(tx_setup* s, const char* key, const char** out, int max) {
  const tx_param_def* d = entry(s, key, TX_PARAM_STRS);
  char code[64], table[64];
  if (d) {
    snprintf(code, sizeof code, "at most %d entries", max);
    snprintf(table, sizeof table, "at most %g entries", d->max);
    if (drifted(s, key, (double)max == d->max, code, table)) return 0;
  }
  return read_strs(s, key, out, max);
}

const char* tx_param_json_text(tx_setup* s, const char* key) {
  json_t* v = param(s, key);
  if (!v) return NULL;
  // 17 digits: every double comes back exactly when the text is parsed again
  char* text = json_dumps(v, JSON_COMPACT | JSON_ENCODE_ANY | JSON_REAL_PRECISION(17));
  const char* kept = text ? keep(s, text) : NULL;
  free(text);
  if (!kept) tx_setup_fail(s, key, "out of memory");
  return kept;
}

// the model's rule for component names (model/model.c)
static bool valid_component_name(const char* s) {
  if (!s || !*s || strlen(s) >= TX_NAME_MAX) return false;
  for (; *s; s++)
    if (!((*s >= 'a' && *s <= 'z') || (*s >= '0' && *s <= '9') || *s == '_' || *s == '.')) return false;
  return true;
}

// the parameter that gave this component name (a string, or a string in a
// list), so that the error names it and the --set behind it; NULL if none
static const char* param_naming(const instance* in, const char* name) {
  const char* key;
  json_t* v;
  if (name && in->params) json_object_foreach(in->params, key, v) {
    if (json_is_string(v) && strcmp(json_string_value(v), name) == 0) return key;
    size_t i;
    json_t* e;
    if (json_is_array(v)) json_array_foreach(v, i, e)
      if (json_is_string(e) && strcmp(json_string_value(e), name) == 0) return key;
  }
  return NULL;
}

static port* new_port(tx_setup* s, const char* name, bool write) {
  instance* in = s->in;
  if (in->failed) return NULL;
  if (!valid_component_name(name))
    return tx_setup_fail(s, param_naming(in, name), "bad component name '%s': expected 1-%d characters of a-z 0-9 _ .",
                         name ? name : "", TX_NAME_MAX - 1), NULL;
  for (int i = 0; i < in->nports; i++)
    if (strcmp(in->ports[i].name, name) == 0)
      return tx_setup_fail(s, NULL, "component '%s' is declared twice by this controller", name), NULL;
  if (in->nports == TX_PORTS_MAX) return tx_setup_fail(s, NULL, "more than %d reads and writes", TX_PORTS_MAX), NULL;
  port* p = &in->ports[in->nports++];
  *p = (port){.write = write};
  strcpy(p->name, name);
  return p;
}

tx_port tx_setup_write(tx_setup* s, const tx_component_def* def) {
  if (!def) return tx_setup_fail(s, NULL, "write without a component definition"), (tx_port){0};
  port* p = new_port(s, def->name, true);
  if (!p) return (tx_port){0};
  const char* units = def->units ? def->units : "1";
  if (strlen(units) >= TX_UNITS_MAX) return tx_setup_fail(s, NULL, "%s: units '%s' too long", def->name, units), (tx_port){0};
  strcpy(p->units, units);
  p->def = *def;
  p->def.name = p->name;
  p->def.units = p->units;
  return (tx_port){(uint16_t)s->in->nports};
}

tx_port tx_setup_read(tx_setup* s, const char* component) { return tx_setup_read_as(s, component, (tx_type)0, 0); }

tx_port tx_setup_read_as(tx_setup* s, const char* component, tx_type type, uint32_t cols) {
  return tx_setup_read_expect(s, component, type, cols, NULL);
}

tx_port tx_setup_read_expect(tx_setup* s, const char* component, tx_type type, uint32_t cols, const char* units) {
  if (units && strlen(units) >= TX_UNITS_MAX)
    return tx_setup_fail(s, NULL, "%s: units '%s' too long", component ? component : "", units), (tx_port){0};
  port* p = new_port(s, component, false);
  if (!p) return (tx_port){0};
  p->want_type = type;
  p->want_cols = cols;
  if (units) strcpy(p->want_units, units);
  return (tx_port){(uint16_t)s->in->nports};
}

tx_port tx_setup_emit(tx_setup* s, const char* stream, uint32_t capacity) {
  if (capacity < 2 || capacity > TX_STREAM_CAPACITY_MAX || (capacity & (capacity - 1)))
    return tx_setup_fail(s, NULL, "event stream '%s': capacity %u is not a power of two in [2, %u]", stream ? stream : "",
                         capacity, TX_STREAM_CAPACITY_MAX), (tx_port){0};
  port* p = new_port(s, stream, false);
  if (!p) return (tx_port){0};
  p->kind = PORT_EMIT;
  p->capacity = capacity;
  return (tx_port){(uint16_t)s->in->nports};
}

tx_port tx_setup_listen(tx_setup* s, const char* stream) {
  port* p = new_port(s, stream, false);
  if (!p) return (tx_port){0};
  p->kind = PORT_LISTEN;
  return (tx_port){(uint16_t)s->in->nports};
}

// "INSTANCE.key" in a run-wide table of keys (warnings or results): its id,
// the same for the same key, or 0 after a configure error
static uint16_t intern_key(tx_setup* s, char (*keys)[TX_WARNING_KEY_MAX], int* count, const char* key,
                           const char* what) {
  char full[TX_WARNING_KEY_MAX];
  if (!key || snprintf(full, sizeof full, "%s.%s", s->in->name, key) >= (int)sizeof full)
    return tx_setup_fail(s, NULL, "%s key is missing or too long", what), 0;
  for (int i = 0; i < *count; i++)
    if (strcmp(keys[i], full) == 0) return (uint16_t)(i + 1);
  if (*count == TX_WARNINGS_MAX) return tx_setup_fail(s, NULL, "more than %d %s keys", TX_WARNINGS_MAX, what), 0;
  strcpy(keys[*count], full);
  return (uint16_t)++*count;
}

tx_result tx_setup_result(tx_setup* s, const char* key) {
  tx_system* sys = s->sys;
  uint16_t id = intern_key(s, sys->result_keys, &sys->nresults, key, "result");
  if (id) sys->result_values[id - 1] = NAN;
  return (tx_result){id};
}

tx_warning tx_setup_warning(tx_setup* s, const char* key) {
  tx_system* sys = s->sys;
  int before = sys->nwarnings;
  uint16_t id = intern_key(s, sys->warning_keys, &sys->nwarnings, key, "warning");
  if (sys->nwarnings > before) atomic_init(&sys->warning_counts[id - 1], 0);
  return (tx_warning){id};
}

// --- parameters as text, for `tactus describe` and the trainer's panel -------

const char* tx_param_num_text(double x, char* buf, size_t n) {
  char raw[64];
  for (int digits = 6; digits <= 17; digits++) { // the shortest text that reads back as x
    snprintf(raw, sizeof raw, "%.*g", digits, x);
    if (strtod(raw, NULL) == x) break;
  }
  size_t o = 0;
  for (const char* p = raw; *p && o + 1 < n; p++) {
    buf[o++] = *p;
    if (*p == 'e') {
      if (p[1] == '+') p++;
      else if (p[1] == '-') buf[o++] = *++p;
      while (p[1] == '0' && p[2]) p++;
    }
  }
  buf[o] = 0;
  return buf;
}

const char* tx_param_default_text(const tx_param_def* d, bool md, char* buf, size_t n) {
  switch (d->kind) {
  case TX_PARAM_NUM: case TX_PARAM_INT:
    if (d->def_str) return snprintf(buf, n, "%s", d->def_str), buf;
    return tx_param_num_text(d->def_num, buf, n);
  case TX_PARAM_BOOL: return d->def_num != 0 ? "true" : "false";
  case TX_PARAM_STR:
    if (!d->def_str) return "none";
    return snprintf(buf, n, md ? "`%s`" : "\"%s\"", *d->def_str || !md ? d->def_str : "\"\""), buf;
  case TX_PARAM_STRS: return "[]";
  case TX_PARAM_JSON: return "none";
  }
  return "?";
}

const char* tx_param_value_text(const tx_param_def* d, json_t* given, int width, char* buf, size_t n) {
  json_t* v = given ? json_object_get(given, d->key) : NULL;
  if (v && json_is_number(v)) return tx_param_num_text(json_number_value(v), buf, n);
  if (v) {
    char* text = json_dumps(v, JSON_COMPACT | JSON_ENCODE_ANY);
    // a long value (the view object) is cut: the text shows, the scenario holds
    if (text && width > 3 && strlen(text) > (size_t)width) snprintf(buf, n, "%.*s...", width - 3, text);
    else snprintf(buf, n, "%s", text ? text : "?");
    free(text);
    return buf;
  }
  char def[128];
  snprintf(buf, n, "%s (default)", tx_param_default_text(d, false, def, sizeof def));
  return buf;
}
