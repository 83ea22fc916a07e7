// Test controllers shared by the controller tests: a counter that writes its
// step count and a recorder that logs the order of steps.
#ifndef TX_TESTS_CONTROLLERS_SUPPORT_H
#define TX_TESTS_CONTROLLERS_SUPPORT_H

#include <tactus/controller.h>

#include <stdlib.h>
#include <string.h>

typedef struct counter {
  tx_port out, in;
  double gain;
  double seen; // last value read from "in"
  int64_t stop_at; // step index at which to stop the run (tx_stop_run), -1: never
} counter;

static const tx_param_def counter_params[] = {
    {"gain", TX_PARAM_NUM, "1", -1e6, 1e6, 1, NULL, "value written per step"},
    {"stop_at", TX_PARAM_INT, "1", -1, 1000000000, -1, NULL, "step index at which to stop the run; -1: never"},
    {"write", TX_PARAM_STR, NULL, 0, 0, 0, NULL, "the component written (f64 1 x 2); none by default"},
    {"read", TX_PARAM_STR, NULL, 0, 0, 0, NULL, "a component read; none by default"},
};

static int counter_configure(tx_setup* s, void** self) {
  counter* c = calloc(1, sizeof *c);
  *self = c;
  c->gain = tx_table_num(s, "gain");
  c->stop_at = tx_table_int(s, "stop_at");
  const char* out = tx_table_str(s, "write");
  const char* in = tx_table_str(s, "read");
  if (out) c->out = tx_setup_write(s, &(tx_component_def){out, TX_F64, 1, 2, "1"});
  if (in) c->in = tx_setup_read(s, in);
  return 0;
}

static void counter_step(tx_ctx* x, void* self) {
  counter* c = self;
  if (c->stop_at >= 0 && tx_step_index(x) == (uint64_t)c->stop_at) tx_stop_run(x, "disk full");
  if (c->in.id) {
    tx_snapshot s = tx_read(x, c->in);
    c->seen = ((const double*)s.data)[0];
  }
  if (c->out.id) {
    double* v = tx_write(x, c->out);
    v[0] = c->gain * (double)(tx_step_index(x) + 1) + 0.5 * c->seen;
    v[1] = (double)tx_sim_ns(x) * 1e-9;
  }
}

static void counter_fini(void* self) { free(self); }

static const tx_controller_class test_counter = {.type = "test.counter", .summary = "counts steps",
                                                 .configure = counter_configure, .step = counter_step,
                                                 .fini = counter_fini, .params = counter_params,
                                                 .nparams = TX_PARAMS_COUNT(counter_params)};

static inline void register_test_classes(void) {
  if (!tx_find_controller("test.counter")) tx_register_controller(&test_counter);
}

#endif
