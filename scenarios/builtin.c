// The controller classes that ship with tactus.
#include "loader.h"
#include "rates/rates_worker.h"

#include <pthread.h>

static void register_all(void) { tx_register_controller(&tx_rates_worker); }

void tx_register_builtin(void) {
  static pthread_once_t once = PTHREAD_ONCE_INIT;
  pthread_once(&once, register_all);
}
