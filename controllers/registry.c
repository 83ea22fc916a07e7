// The registry of controller classes: built-in ones and those plugins add.
#include "../model/error.h"

#include <tactus/controller.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#define CLASSES_MAX 256

static const tx_controller_class* classes[CLASSES_MAX];
static int class_count;

static bool valid_key(const char* k) {
  if (!k || !*k || strlen(k) >= 64) return false;
  for (; *k; k++)
    if (!((*k >= 'a' && *k <= 'z') || (*k >= '0' && *k <= '9') || *k == '_')) return false;
  return true;
}

static bool integral(double x) { return isfinite(x) && x == floor(x) && fabs(x) <= 9007199254740992.0; }

// a table that `tactus describe` and configure can trust: 0, or -1 with the
// reason it is not, naming the entry, in tx_error()
static int table_check(const tx_controller_class* cls) {
  if (!cls->params) return cls->nparams ? (tx_set_error("nparams is %d but params is NULL", cls->nparams), -1) : 0;
  if (cls->nparams < 0 || cls->nparams > 1000) return tx_set_error("nparams %d is out of range [0, 1000]", cls->nparams), -1;
  for (int i = 0; i < cls->nparams; i++) {
    const tx_param_def* d = &cls->params[i];
    const char* k = d->key ? d->key : "";
    if (!valid_key(d->key)) return tx_set_error("params[%d]: key '%s' must be 1-63 characters of a-z 0-9 _", i, k), -1;
    for (int j = 0; j < i; j++)
      if (strcmp(cls->params[j].key, k) == 0) return tx_set_error("params[%d]: key '%s' appears twice", i, k), -1;
    if (!d->meaning || !*d->meaning) return tx_set_error("params[%d] %s: no meaning given", i, k), -1;
    // one line each, and a cell of the docs' Markdown tables
    const char* texts[3] = {d->meaning, d->units, d->def_str};
    for (int t = 0; t < 3; t++)
      if (texts[t] && strpbrk(texts[t], "|\n\r"))
        return tx_set_error("params[%d] %s: meaning, units and default hold no '|' or line break", i, k), -1;
    switch (d->kind) {
    case TX_PARAM_NUM:
    case TX_PARAM_INT:
      if (!d->units || !*d->units) return tx_set_error("params[%d] %s: a number needs units (\"1\" for none)", i, k), -1;
      if (!isfinite(d->min) || !isfinite(d->max) || d->min > d->max)
        return tx_set_error("params[%d] %s: range [%g, %g] is not finite and ordered", i, k, d->min, d->max), -1;
      if (d->kind == TX_PARAM_INT && !(integral(d->min) && integral(d->max) && integral(d->def_num)))
        return tx_set_error("params[%d] %s: an integer needs whole default and range", i, k), -1;
      if (d->kind == TX_PARAM_INT && d->def_str)
        return tx_set_error("params[%d] %s: an integer takes no computed default", i, k), -1;
      if (!d->def_str && !(d->def_num >= d->min && d->def_num <= d->max))
        return tx_set_error("params[%d] %s: default %g is outside [%g, %g]", i, k, d->def_num, d->min, d->max), -1;
      break;
    case TX_PARAM_BOOL:
      if (d->def_num != 0 && d->def_num != 1) return tx_set_error("params[%d] %s: a boolean's default is 0 or 1", i, k), -1;
      break;
    case TX_PARAM_STRS:
      if (!integral(d->max) || d->max < 1 || d->max > 65536)
        return tx_set_error("params[%d] %s: a list needs max in [1, 65536] entries", i, k), -1;
      break;
    case TX_PARAM_STR:
    case TX_PARAM_JSON: break;
    default: return tx_set_error("params[%d] %s: unknown kind %d", i, k, (int)d->kind), -1;
    }
  }
  return 0;
}

// each live key is a number, an integer or a boolean of the table, and the class can tune it
static int live_check(const tx_controller_class* cls) {
  for (int i = 0; cls->live && cls->live[i]; i++) {
    const tx_param_def* d = tx_param_find(cls, cls->live[i]);
    if (!d) return tx_set_error("'%s' is not in the parameter table", cls->live[i]), -1;
    if (!(d->kind == TX_PARAM_NUM || d->kind == TX_PARAM_INT || d->kind == TX_PARAM_BOOL))
      return tx_set_error("%s: only a number, an integer or a boolean can be live", d->key), -1;
    if (!cls->tune) return tx_set_error("%s: live, but the class has no tune", d->key), -1;
  }
  return 0;
}

int tx_register_controller(const tx_controller_class* cls) {
  if (!cls || !cls->type || !*cls->type || !cls->configure || !cls->step)
    return tx_set_error("a controller class needs a type, configure and step"), -1;
  if (table_check(cls)) return tx_error_prefix("%s: parameter table", cls->type), -1;
  if (live_check(cls)) return tx_error_prefix("%s: live parameters", cls->type), -1;
  if (tx_find_controller(cls->type)) return tx_set_error("controller type '%s' is already registered", cls->type), -1;
  if (class_count == CLASSES_MAX) return tx_set_error("more than %d controller types", CLASSES_MAX), -1;
  classes[class_count++] = cls;
  return 0;
}

const tx_controller_class* tx_find_controller(const char* type) {
  for (int i = 0; type && i < class_count; i++)
    if (strcmp(classes[i]->type, type) == 0) return classes[i];
  return NULL;
}

const tx_controller_class* tx_controller_class_at(int i) { return i >= 0 && i < class_count ? classes[i] : NULL; }
