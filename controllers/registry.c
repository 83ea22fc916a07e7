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

// a table that `tactus describe` and configure can trust: the reason it is
// not, naming the entry, or NULL
static const char* table_error(const tx_controller_class* cls, char* why, size_t n) {
  if (!cls->params) return cls->nparams ? (snprintf(why, n, "nparams is %d but params is NULL", cls->nparams), why) : NULL;
  if (cls->nparams < 0 || cls->nparams > 1000) return snprintf(why, n, "nparams %d is out of range [0, 1000]", cls->nparams), why;
  for (int i = 0; i < cls->nparams; i++) {
    const tx_param_def* d = &cls->params[i];
    const char* k = d->key ? d->key : "";
    if (!valid_key(d->key)) return snprintf(why, n, "params[%d]: key '%s' must be 1-63 characters of a-z 0-9 _", i, k), why;
    for (int j = 0; j < i; j++)
      if (strcmp(cls->params[j].key, k) == 0) return snprintf(why, n, "params[%d]: key '%s' appears twice", i, k), why;
    if (!d->meaning || !*d->meaning) return snprintf(why, n, "params[%d] %s: no meaning given", i, k), why;
    // one line each, and a cell of the docs' Markdown tables
    const char* texts[3] = {d->meaning, d->units, d->def_str};
    for (int t = 0; t < 3; t++)
      if (texts[t] && strpbrk(texts[t], "|\n\r"))
        return snprintf(why, n, "params[%d] %s: meaning, units and default hold no '|' or line break", i, k), why;
    switch (d->kind) {
    case TX_PARAM_NUM:
    case TX_PARAM_INT:
      if (!d->units || !*d->units) return snprintf(why, n, "params[%d] %s: a number needs units (\"1\" for none)", i, k), why;
      if (!isfinite(d->min) || !isfinite(d->max) || d->min > d->max)
        return snprintf(why, n, "params[%d] %s: range [%g, %g] is not finite and ordered", i, k, d->min, d->max), why;
      if (d->kind == TX_PARAM_INT && !(integral(d->min) && integral(d->max) && integral(d->def_num)))
        return snprintf(why, n, "params[%d] %s: an integer needs whole default and range", i, k), why;
      if (d->kind == TX_PARAM_INT && d->def_str)
        return snprintf(why, n, "params[%d] %s: an integer takes no computed default", i, k), why;
      if (!d->def_str && !(d->def_num >= d->min && d->def_num <= d->max))
        return snprintf(why, n, "params[%d] %s: default %g is outside [%g, %g]", i, k, d->def_num, d->min, d->max), why;
      break;
    case TX_PARAM_BOOL:
      if (d->def_num != 0 && d->def_num != 1) return snprintf(why, n, "params[%d] %s: a boolean's default is 0 or 1", i, k), why;
      break;
    case TX_PARAM_STRS:
      if (!integral(d->max) || d->max < 1 || d->max > 65536)
        return snprintf(why, n, "params[%d] %s: a list needs max in [1, 65536] entries", i, k), why;
      break;
    case TX_PARAM_STR:
    case TX_PARAM_JSON: break;
    default: return snprintf(why, n, "params[%d] %s: unknown kind %d", i, k, (int)d->kind), why;
    }
  }
  return NULL;
}

int tx_register_controller(const tx_controller_class* cls) {
  if (!cls || !cls->type || !*cls->type || !cls->configure || !cls->step)
    return tx_set_error("a controller class needs a type, configure and step"), -1;
  char why[256];
  if (table_error(cls, why, sizeof why)) return tx_set_error("%s: parameter table: %s", cls->type, why), -1;
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
