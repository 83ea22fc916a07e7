// The registry of controller classes: built-in ones and those plugins add.
#include "../model/error.h"

#include <tactus/controller.h>

#include <string.h>

#define CLASSES_MAX 256

static const tx_controller_class* classes[CLASSES_MAX];
static int class_count;

int tx_register_controller(const tx_controller_class* cls) {
  if (!cls || !cls->type || !*cls->type || !cls->configure || !cls->step)
    return tx_set_error("a controller class needs a type, configure and step"), -1;
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
