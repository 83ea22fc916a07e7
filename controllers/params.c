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

// the value of params.KEY, marked as used; NULL when absent or after an error
static json_t* param(tx_setup* s, const char* key) {
  if (s->in->failed || !key) return NULL;
  json_object_set_new(s->in->used, key, json_true());
  return s->in->params ? json_object_get(s->in->params, key) : NULL;
}

json_t* tx_param_json(tx_setup* s, const char* key) { return param(s, key); }

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

double tx_param_num(tx_setup* s, const char* key, double def, double min, double max) {
  json_t* v = param(s, key);
  if (!v) return def;
  if (!json_is_number(v)) return tx_setup_fail(s, key, "expected a number, got %s", tx_json_kind(v)), def;
  double x = json_number_value(v);
  if (!isfinite(x) || x < min || x > max)
    return tx_setup_fail(s, key, "%g is out of range [%g, %g]", x, min, max), def;
  return x;
}

int64_t tx_param_int(tx_setup* s, const char* key, int64_t def, int64_t min, int64_t max) {
  json_t* v = param(s, key);
  if (!v) return def;
  if (!json_is_integer(v)) return tx_setup_fail(s, key, "expected an integer, got %s", tx_json_kind(v)), def;
  int64_t x = json_integer_value(v);
  if (x < min || x > max)
    return tx_setup_fail(s, key, "%lld is out of range [%lld, %lld]", (long long)x, (long long)min, (long long)max), def;
  return x;
}

bool tx_param_bool(tx_setup* s, const char* key, bool def) {
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

const char* tx_param_str(tx_setup* s, const char* key, const char* def) {
  json_t* v = param(s, key);
  if (!v) return def;
  if (!json_is_string(v)) return tx_setup_fail(s, key, "expected a string, got %s", tx_json_kind(v)), def;
  return keep(s, json_string_value(v));
}

int tx_param_strs(tx_setup* s, const char* key, const char** out, int max) {
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
